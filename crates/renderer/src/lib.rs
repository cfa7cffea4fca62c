//! Spectrace's renderer: a scene file goes in, a validated scene is assembled, the estimator the
//! effects analysis chooses (light tracer, path tracer or BDPT) renders it, and a linear EXR, an
//! sRGB PNG and a JSON sidecar come out.
//!
//! This crate is thin glue over the others (the data flow of `docs/ARCHITECTURE.md`): [`Scene`]
//! reads and validates the JSON (errors name the file, line, column and field path) and adds area
//! lights' surfaces and glowing objects to the scene, [`render_scene`] runs the effects analysis,
//! chooses the integrator ([`choose_integrator`]), checks that light can reach the camera, renders
//! on threads with a progress bar and writes the outputs normalised per estimator
//! ([`Normalisation`]), and [`merge_parts`] turns the partial films of a sharded render into the
//! same image a single machine would make, bit for bit. Every render also says how accurate it
//! is ([`AccuracyEstimate`] in the sidecar, from the tracer's per-chunk moments), can render to a
//! target error (`--target-error`), and [`pilot::estimate`] predicts the time to a target per
//! estimator before rendering. The key design decision: one render path for every estimator
//! ([`with_integrator`]), so sharding, time budgets, targets, probes and outputs work the same for
//! all. The `spectrace` binary exposes it; the xtask's `render` subcommand calls it.
//! The accuracy report is not here: it is an experiment harness with its own crate,
//! `spectrace-lab`, so programs that render do not link its plotting library; this crate keeps
//! the timed measurement both it and `spectrace bench` use ([`render_xyz`],
//! [`integrator_benchmark`]). Nothing but `spectrace-lab`, `xtask` and the tests depend on this
//! crate.

pub mod cli;
mod files;
mod output;
mod part;
pub mod pilot;
mod scene;
mod sensor_output;
mod sensors;

use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::{Deserialize, Serialize};
use spectrace_lights::LightSource;
use spectrace_tracer::{
    Bdpt, ChunkWork, Effects, EffectsMode, Film, FilmError, Integrator, IntegratorChoice,
    LightTracer, LightTracerScene, MemoryLimit, PathTracer, RenderOutput, RenderPlan, SamplerKind,
    TraceStats, image_scale, render, render_observed,
};

pub use files::{
    MAX_OUTPUT_NAME_BYTES, MAX_PART_BYTES, MAX_SCENE_BYTES, check_no_input_replaced,
    check_output_name, prepare_out_dir, read_bounded, same_file, write_atomically,
};
pub use output::{EncodedImage, OUTPUT_BYTES_PER_PIXEL, encode_image, write_exr, write_png};
pub use part::{PARTIAL_VERSION, PartialFilm};
pub use scene::{
    DEFAULT_SENSOR_SPP, DEFAULT_SPP, EffectsSettings, LoadOptions, Object, OutputSettings, Scene,
    SceneError, SceneFile, SensorIntegrator, Settings, check_target_error,
};
pub use sensor_output::{
    MAX_SENSOR_CELLS, SensorGrid, SensorSummary, sensor_colour, write_sensor_files,
};
pub use sensors::{
    SensorEstimate, SensorReport, SensorSource, check_sensor_names, planned_sensor_outputs,
    sensor_grid, sensor_pass, sensor_pass_path, sensor_plan, sensor_summary, write_sensors,
};

/// Command-line overrides of a scene's settings.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RenderOptions {
    /// Beams for the whole image (overrides `settings.beams`).
    pub beams: Option<u64>,
    /// Time budget in seconds (overrides `settings.time_seconds`).
    pub time: Option<f64>,
    /// Threads (overrides `settings.threads`; 0 = one per core).
    pub threads: Option<usize>,
    /// Seed (overrides `settings.seed`).
    pub seed: Option<u64>,
    /// Render only chunks `k` mod `n` and write a partial film.
    pub shard: Option<(u64, u64)>,
    /// Effects mode (overrides `effects.mode`).
    pub effects: Option<EffectsMode>,
    /// Where the outputs go.
    pub out_dir: PathBuf,
    /// Show a progress bar and print the effects decision.
    pub verbose: bool,
    /// Refuse files (OBJ meshes, luminaire files) outside the scene file's folder (see [`LoadOptions`]).
    pub restrict_paths: bool,
    /// The estimator (overrides `settings.integrator`).
    pub integrator: Option<IntegratorChoice>,
    /// Camera samples per pixel for `path` and `bdpt` (overrides `settings.spp`).
    pub spp: Option<u64>,
    /// Render until the estimated relative error reaches this (overrides
    /// `settings.target_error`).
    pub target_error: Option<f64>,
}

/// Why a render failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RenderError {
    /// The scene is invalid (or cannot produce light at the camera).
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// An option is invalid.
    #[error("{0}")]
    Options(String),
    /// Writing or reading a file failed.
    #[error("{path}: {message}")]
    File {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
}

/// What a render did: the JSON sidecar's contents.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RenderReport {
    /// The scene file.
    pub scene: String,
    /// Image size.
    pub width: u32,
    /// Image size.
    pub height: u32,
    /// The plan after overrides (beams, chunk size, seed, threads, shard, time budget).
    pub plan: RenderPlan,
    /// The effects analysis' decision.
    pub effects: Effects,
    /// The decision in words.
    pub effects_summary: String,
    /// The estimator that rendered the image ([`Integrator::name`]): `"light"`, `"path"` or
    /// `"bdpt"`.
    #[serde(default = "light_integrator")]
    pub integrator: String,
    /// Why that estimator: asked for, or the effects analysis' reason.
    #[serde(default)]
    pub integrator_reason: String,
    /// Where the random numbers came from (`settings.sampler`): `"independent"` or `"sobol"`.
    #[serde(default = "independent_sampler")]
    pub sampler: String,
    /// Beams traced.
    pub beams: u64,
    /// Wall time (s).
    pub wall_seconds: f64,
    /// Beams per second.
    pub beams_per_second: f64,
    /// Contributions rejected by the film as non-finite or out of range (0 on every shipped
    /// scene).
    pub rejected_contributions: u64,
    /// The EXR holds the image multiplied by `2^exr_scale_log2`: 0 unless the image lies beyond
    /// the range of 32-bit floats (see [`encode_image`]).
    pub exr_scale_log2: i32,
    /// Channel values that would have overflowed to infinity (or underflowed to zero) in the
    /// EXR without that scale.
    pub out_of_range_values: u64,
    /// Anything the user should know about the result (also printed).
    pub warnings: Vec<String>,
    /// How accurate the image is, estimated from the spread between its chunks (absent when
    /// the image was too large to keep the estimate's moments).
    #[serde(default)]
    pub error_estimate: Option<AccuracyEstimate>,
    /// Tracer counters.
    pub stats: TraceStats,
    /// Total power of the lights (W).
    pub light_power: f64,
    /// Files written.
    pub outputs: Vec<String>,
    /// The illuminance sensors' figures (empty for a scene without sensors).
    #[serde(default)]
    pub sensors: Vec<SensorReport>,
    /// Spectrace version.
    pub version: String,
}

/// The relative errors the sidecar predicts render times for (10%, 5%, 2%, 1%).
pub const PREDICTED_ERRORS: [f64; 4] = [0.10, 0.05, 0.02, 0.01];

/// How accurate a rendered image is and what more accuracy costs: the sidecar's
/// `error_estimate`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AccuracyEstimate {
    /// Estimated relative RMSE against the converged image (over all pixels and X, Y, Z: the
    /// accuracy report's measure); `null` with fewer than two batches or a black image.
    pub relative_rmse: Option<f64>,
    /// One-sigma relative uncertainty of that estimate itself.
    pub relative_uncertainty: f64,
    /// Independent batches (work chunks) it comes from.
    pub batches: u64,
    /// `true` with at least [`spectrace_tracer::MIN_BATCHES`] batches.
    pub trusted: bool,
    /// The target asked for (`--target-error`, `settings.target_error`), if any.
    pub target_error: Option<f64>,
    /// Whether the estimate reached the target (`null` without one).
    pub target_reached: Option<bool>,
    /// Predicted total render time (s, at this render's speed) to reach each relative error in
    /// [`PREDICTED_ERRORS`], with error falling as `1 / sqrt(work)`; `[error, seconds]` pairs,
    /// only for errors below the current one.
    pub predicted_seconds: Vec<[f64; 2]>,
    /// More render time (s) that would halve the error (three times this render's: four
    /// times the work).
    pub seconds_to_halve: f64,
    /// With a target the render did not reach (a time cap): the predicted total render time
    /// (s) to reach it; `null` otherwise.
    #[serde(default)]
    pub seconds_to_target: Option<f64>,
}

impl AccuracyEstimate {
    /// The sidecar's estimate of a render of `seconds` that ended with `estimate`.
    pub fn new(
        estimate: &spectrace_tracer::ErrorEstimate,
        target: Option<f64>,
        seconds: f64,
    ) -> Self {
        let e = estimate.relative_rmse;
        let predicted_seconds = match e {
            Some(e) if e > 0.0 => PREDICTED_ERRORS
                .iter()
                .filter(|&&t| t < e)
                .map(|&t| [t, seconds * (e / t).powi(2)])
                .collect(),
            _ => Vec::new(),
        };
        Self {
            relative_rmse: e,
            relative_uncertainty: estimate.relative_uncertainty(),
            batches: estimate.batches,
            trusted: estimate.is_trusted(),
            target_error: target,
            target_reached: target.map(|t| e.is_some_and(|e| e <= t) && estimate.is_trusted()),
            predicted_seconds,
            seconds_to_halve: 3.0 * seconds,
            seconds_to_target: match (e, target) {
                (Some(e), Some(t)) if e > t && t > 0.0 => Some(seconds * (e / t).powi(2)),
                _ => None,
            },
        }
    }

    /// One line for the terminal: `error 3.2% ±0.1% (64 batches); 2%: ~41 s`.
    pub fn summary(&self) -> String {
        let Some(e) = self.relative_rmse else {
            return format!(
                "error: no estimate ({} batches, need 2 and a lit image)",
                self.batches
            );
        };
        let mut line = format!(
            "estimated error {:.2}% ±{:.2}% ({} batches{})",
            e * 100.0,
            e * self.relative_uncertainty * 100.0,
            self.batches,
            if self.trusted { "" } else { ", too few to trust" }
        );
        if let (Some(t), Some(reached)) = (self.target_error, self.target_reached) {
            line.push_str(&format!(
                "; target {:.2}% {}",
                t * 100.0,
                if reached { "reached" } else { "not reached" }
            ));
        }
        if let Some([t, s]) = self.predicted_seconds.first() {
            line.push_str(&format!("; {:.0}% would take ~{} in all", t * 100.0, duration(*s)));
        }
        line
    }
}

/// Seconds in words: `850 ms`, `12.3 s`, `4.1 min`, `2.5 h`.
pub fn duration(seconds: f64) -> String {
    if !seconds.is_finite() {
        "forever".to_owned()
    } else if seconds < 1.0 {
        format!("{:.0} ms", seconds * 1e3)
    } else if seconds < 120.0 {
        format!("{seconds:.1} s")
    } else if seconds < 7200.0 {
        format!("{:.1} min", seconds / 60.0)
    } else {
        format!("{:.1} h", seconds / 3600.0)
    }
}

/// The integrator of sidecars written before the field existed: the light tracer.
fn light_integrator() -> String {
    LightTracer::NAME.to_owned()
}

/// The sampler of sidecars written before the field existed.
fn independent_sampler() -> String {
    SamplerKind::Independent.name().to_owned()
}

/// Most worker threads a render accepts.
pub const MAX_THREADS: usize = 256;

/// Beams traced to check that light can reach the camera before rendering.
pub const PROBE_BEAMS: u64 = 20_000;

/// The tracer's view of a scene.
pub fn tracer_scene(scene: &Scene) -> LightTracerScene<'_> {
    LightTracerScene::new(&scene.world, &scene.materials, &scene.lights, &scene.camera)
        .with_emitters(scene.emitters.clone(), scene.object_shapes)
        .with_sampler(scene.settings.sampler)
        .with_sensors(&scene.sensors)
}

/// The estimator for a scene (with an optional override) and the reason, in words.
pub fn choose_integrator(
    scene: &Scene,
    choice: Option<IntegratorChoice>,
) -> (IntegratorChoice, String) {
    let features = tracer_scene(scene).features(&scene.non_convex);
    choice.unwrap_or(scene.settings.integrator).decide(&features)
}

/// What turns a film's exact sums into the image: `light_power * factor / items`, where the
/// items are the work items done (see [`normalisation`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Normalisation {
    /// Total power of the lights (W): every integrator's film holds sums relative to it, so
    /// that lights of any power keep the film's fixed point in range.
    pub light_power: f64,
    /// 1 for the light tracer (items are beams, each carrying `light_power / beams`); the pixel
    /// count for camera integrators (items are camera samples: the image is the mean per pixel).
    pub factor: f64,
}

impl Normalisation {
    /// The factor for `items` work items (0 for none; may overflow to infinity, which
    /// [`encode_image`] handles).
    pub fn scale(&self, items: u64) -> f64 {
        image_scale(self.light_power, items) * self.factor
    }
}

/// The normalisation of a render by `integrator` of an image of `pixels` pixels.
pub fn normalisation(integrator: IntegratorChoice, light_power: f64, pixels: u64) -> Normalisation {
    let factor = match integrator {
        IntegratorChoice::Path | IntegratorChoice::Bdpt => pixels as f64,
        IntegratorChoice::Light | IntegratorChoice::Auto => 1.0,
    };
    Normalisation { light_power, factor }
}

/// The effects decision for a scene (with an optional override).
pub fn decide_effects(scene: &Scene, mode: Option<EffectsMode>) -> Effects {
    let features = tracer_scene(scene).features(&scene.non_convex);
    Effects::decide(features, mode.unwrap_or(scene.effects.mode))
}

/// The plan after command-line overrides.
///
/// # Errors
/// [`RenderError::Options`] for zero beams, a non-positive time, or an invalid shard.
pub fn plan_for(scene: &Scene, options: &RenderOptions) -> Result<RenderPlan, RenderError> {
    let (integrator, _) = choose_integrator(scene, options.integrator);
    plan_with(scene, options, integrator)
}

/// The plan for a given estimator. The light tracer's work items are beams (`--beams`,
/// `settings.beams`, in chunks of `settings.chunk_beams`). A camera integrator's are camera
/// samples in passes of one sample per pixel (a chunk is a pass): `--spp` / `settings.spp`
/// passes, or with only `--beams N` given, `N / pixels` passes rounded up (the same number of
/// paths).
///
/// # Errors
/// As [`plan_for`].
pub fn plan_with(
    scene: &Scene,
    options: &RenderOptions,
    integrator: IntegratorChoice,
) -> Result<RenderPlan, RenderError> {
    let mut plan = plan_light(scene, options)?;
    if matches!(integrator, IntegratorChoice::Path | IntegratorChoice::Bdpt) {
        let pixels = u64::from(scene.camera.width()) * u64::from(scene.camera.height());
        let pixels = pixels.max(1);
        let spp = match (options.spp, options.beams) {
            (Some(0), _) => {
                return Err(RenderError::Options("--spp must be at least 1".to_owned()));
            }
            (Some(n), _) => n,
            (None, Some(beams)) => beams.div_ceil(pixels),
            (None, None) => scene.settings.spp,
        };
        plan.chunk_beams = pixels;
        let open_ended = options.time.is_some() || plan.target_error.is_some();
        plan.beams = if open_ended && options.spp.is_none() && options.beams.is_none() {
            (u64::MAX / 2 / pixels) * pixels
        } else {
            spp.checked_mul(pixels).ok_or_else(|| {
                RenderError::Options(format!(
                    "settings.spp / --spp = {spp}: {spp} samples of {pixels} pixels overflow"
                ))
            })?
        };
    }
    Ok(plan)
}

/// The light tracer's plan after overrides.
fn plan_light(scene: &Scene, options: &RenderOptions) -> Result<RenderPlan, RenderError> {
    let mut plan = scene.plan();
    if let Some(b) = options.beams {
        plan.beams = b;
        plan.time_budget = None;
    }
    if let Some(t) = options.time {
        if !(t > 0.0 && t.is_finite()) {
            return Err(RenderError::Options(format!(
                "--time {t}: must be a positive number of seconds"
            )));
        }
        plan.time_budget = Some(t);
        if options.beams.is_none() {
            plan.beams = u64::MAX / 2;
        }
    }
    if let Some(e) = options.target_error {
        scene::check_target_error(e)
            .map_err(|m| RenderError::Options(format!("--target-error {m}")))?;
        plan.target_error = Some(e);
    }
    if plan.target_error.is_some() {
        // The target decides how much to render; --beams caps it.
        plan.error_estimate = true;
        if options.beams.is_none() {
            plan.beams = u64::MAX / 2;
        }
    }
    if plan.beams == 0 {
        return Err(RenderError::Options("--beams must be at least 1".to_owned()));
    }
    if let Some(s) = options.seed {
        plan.seed = s;
    }
    if let Some(t) = options.threads {
        plan.threads = t;
    }
    if plan.threads > MAX_THREADS {
        return Err(RenderError::Options(format!(
            "settings.threads / --threads = {}: at most {MAX_THREADS}",
            plan.threads
        )));
    }
    if plan.threads == 0 {
        plan.threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    }
    if let Some((k, n)) = options.shard {
        if n == 0 || k >= n {
            return Err(RenderError::Options(format!("--shard {k}/{n}: need 0 <= K < N")));
        }
        plan.shard = Some((k, n));
    }
    Ok(plan)
}

/// Longest the pre-render probe may run (s); with a time budget, at most a tenth of it.
pub const PROBE_SECONDS: f64 = 2.0;

/// What the pre-render probe found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProbeOutcome {
    /// Beams traced.
    pub beams: u64,
    /// `true`: a beam put visible light on the film; `false`: the probe ran out of time first
    /// (inconclusive: the render goes on).
    pub lit: bool,
    /// Wall time (s).
    pub seconds: f64,
}

/// A sink that only records whether visible light reached the film (no film is allocated).
struct VisibleLight {
    width: u32,
    height: u32,
    lit: bool,
}

impl spectrace_tracer::Splat for VisibleLight {
    fn splat(&mut self, x: u32, y: u32, xyz: spectrace_spectrum::Xyz) -> bool {
        // As the film would: in the frame, every component in range, and one that is positive
        // after rounding to the film's fixed point.
        let mut positive = false;
        for v in [xyz.x, xyz.y, xyz.z] {
            let mut sum = spectrace_tracer::ExactSum::default();
            if !sum.add(v) {
                return false;
            }
            positive |= sum.raw() > 0;
        }
        if x >= self.width || y >= self.height {
            return false;
        }
        self.lit |= positive;
        true
    }
}

/// Checks, before rendering, that the film fits (at most [`spectrace_tracer::MAX_PIXELS`] pixels
/// and within [`MemoryLimit::system`], see [`RenderPlan::check_memory`]; nothing is allocated)
/// and that some light reaches the camera: traces beams (on their own random
/// streams) until one puts visible light on the film, at most `min(PROBE_BEAMS, plan.beams)` of
/// them and for at most `min(PROBE_SECONDS, plan.time_budget / 10)`. Most scenes need a handful
/// of beams. A probe that runs out of time is inconclusive and lets the render go on.
///
/// # Errors
/// [`SceneError::Scene`] for a camera resolution that is not a valid film or does not fit in
/// memory, and, explaining that the image would be black, when none of the beams lit the film.
pub fn probe(
    scene: &Scene,
    effects: &Effects,
    plan: &RenderPlan,
) -> Result<ProbeOutcome, SceneError> {
    let tracer_scene = tracer_scene(scene);
    let tracer = LightTracer::new(&tracer_scene, scene.tracer_settings(), *effects);
    probe_with(scene, plan, &tracer)
}

/// [`probe`] with any estimator: its work items (beams, or camera samples spread over the
/// image) are traced one per chunk until one puts visible light on the film.
///
/// # Errors
/// As [`probe`].
pub fn probe_with(
    scene: &Scene,
    plan: &RenderPlan,
    tracer: &dyn Integrator,
) -> Result<ProbeOutcome, SceneError> {
    let (width, height) = (scene.camera.width(), scene.camera.height());
    let camera_error = |e: FilmError| SceneError::Scene {
        path: scene.path.clone(),
        field: "camera".to_owned(),
        message: e.to_string(),
    };
    if u64::from(width) * u64::from(height) > spectrace_tracer::MAX_PIXELS {
        return Err(camera_error(FilmError::InvalidSize(width, height)));
    }
    // The film stays allocated while the image is converted for writing: count that too.
    let system = MemoryLimit::system();
    let writing = OUTPUT_BYTES_PER_PIXEL * u64::from(width) * u64::from(height);
    let limit = MemoryLimit {
        bytes: system.bytes.saturating_sub(writing),
        source: format!(
            "{}, less {} to convert the image for writing",
            system.source,
            spectrace_geometry::human_bytes(writing)
        ),
    };
    plan.check_memory(width, height, &limit).map_err(camera_error)?;
    let started = Instant::now();
    let limit = plan.time_budget.map_or(PROBE_SECONDS, |t| (t / 10.0).min(PROBE_SECONDS));
    let deadline = std::time::Duration::try_from_secs_f64(limit.max(0.0))
        .ok()
        .and_then(|d| started.checked_add(d));
    let max_beams = PROBE_BEAMS.min(plan.beams).max(1);
    let mut sink = VisibleLight { width, height, lit: false };
    let mut stats = TraceStats::default();
    let mut timed_out = false;
    for beam in 0..max_beams {
        // One beam per chunk, so that the probe can stop after any beam.
        let work = ChunkWork { seed: u64::MAX, chunk: beam, items: 1, deadline: None };
        stats.merge(&tracer.render_chunk(work, &mut sink));
        if sink.lit {
            break;
        }
        if deadline.is_some_and(|d| Instant::now() >= d) {
            timed_out = true;
            break;
        }
    }
    scene.lights.reset_count();
    let outcome = ProbeOutcome {
        beams: stats.beams,
        lit: sink.lit,
        seconds: started.elapsed().as_secs_f64(),
    };
    if sink.lit || (timed_out && stats.beams < max_beams) {
        return Ok(outcome);
    }
    Err(SceneError::Scene {
        path: scene.path.clone(),
        field: "lights".to_owned(),
        message: format!(
            "no light can reach the camera: none of {} probe paths (beams or camera samples) lit a point the camera sees \
             with visible light ({} hit a surface, {} reached the film). Check that the lights face the \
             objects, that their spectra lie in 360-830 nm, that some surface is not a mirror or glass, and \
             that the camera looks at the lit objects.",
            stats.beams, stats.hits, stats.splats
        ),
    })
}

/// What a user should know about the chosen estimator: light a camera integrator cannot reach.
fn integrator_warnings(scene: &Scene, choice: IntegratorChoice) -> Vec<String> {
    let mut warnings = Vec::new();
    let features = tracer_scene(scene).features(&scene.non_convex);
    if choice == IntegratorChoice::Light && features.specular {
        warnings.push(
            "the light tracer cannot see into mirrors and glass: what they reflect or refract \
             toward the camera is missing from this image (use --integrator bdpt or auto)"
                .to_owned(),
        );
    }
    if choice == IntegratorChoice::Bdpt && features.fluorescent && features.specular {
        warnings.push(
            "BDPT re-emits fluorescent light on light paths only: a fluorescent surface seen \
             only through mirrors or glass is missing from this image (use --integrator path)"
                .to_owned(),
        );
    }
    if choice != IntegratorChoice::Path {
        return warnings;
    }
    if features.beam_only_lights + features.delta_direction_lights > 0 {
        warnings.push(
            "the path tracer cannot reach lasers, skies or lights that only generate beams: \
             their light is missing from this image (use --integrator light or auto)"
                .to_owned(),
        );
    }
    if features.line_spectra {
        warnings.push(
            "the path tracer draws wavelengths from a density and misses spectral lines: \
             their light is missing from this image (use --integrator light or auto)"
                .to_owned(),
        );
    }
    if features.delta_position_lights > 0 && features.specular {
        warnings.push(
            "the path tracer cannot see caustics of point or spot lights (their light through \
             mirrors and glass onto other surfaces is missing; use --integrator light or auto)"
                .to_owned(),
        );
    }
    warnings
}

/// Renders a scene file with overrides and writes its outputs (or, with a shard, its partial film).
///
/// # Errors
/// [`RenderError`] for an invalid scene or options, or a file that cannot be written.
pub fn render_file(path: &Path, options: &RenderOptions) -> Result<RenderReport, RenderError> {
    let scene = Scene::load_with(path, LoadOptions { restrict_paths: options.restrict_paths })?;
    render_scene(&scene, options)
}

/// The files a render will write, checked before any work starts: a valid base name, an output
/// folder that is a folder, and no output that would replace an input.
fn planned_outputs(
    out_dir: &Path,
    name: &str,
    settings: &OutputSettings,
    shard: Option<(u64, u64)>,
    inputs: &[PathBuf],
    sensor_outputs: Vec<PathBuf>,
) -> Result<(), RenderError> {
    check_output_name(name).map_err(|e| RenderError::Options(format!("output name: {e}")))?;
    prepare_out_dir(out_dir).map_err(RenderError::Options)?;
    let outputs = match shard {
        Some((k, n)) => vec![out_dir.join(format!("{name}.part-{k}-of-{n}.bin"))],
        None => {
            let mut v = Vec::new();
            if settings.exr {
                v.push(out_dir.join(format!("{name}.exr")));
            }
            if settings.png {
                v.push(out_dir.join(format!("{name}.png")));
            }
            if settings.error_image {
                v.push(out_dir.join(format!("{name}.error.exr")));
            }
            v.push(out_dir.join(format!("{name}.json")));
            v.extend(sensor_outputs);
            v
        }
    };
    check_no_input_replaced(&outputs, inputs).map_err(RenderError::Options)
}

/// Renders a loaded scene with overrides and writes its outputs.
///
/// # Errors
/// As [`render_file`].
pub fn render_scene(scene: &Scene, options: &RenderOptions) -> Result<RenderReport, RenderError> {
    let (choice, reason) = choose_integrator(scene, options.integrator);
    let plan = plan_with(scene, options, choice)?;
    let name = scene.output_name();
    check_sensor_names(scene, &name)?;
    planned_outputs(
        &options.out_dir,
        &name,
        &scene.output,
        plan.shard,
        &scene.inputs,
        planned_sensor_outputs(scene, &options.out_dir),
    )?;
    let (plan, estimate_warning) = fit_estimate(scene, plan)?;
    let effects = decide_effects(scene, options.effects);
    if options.verbose {
        eprintln!("{}", effects.summary());
        eprintln!("integrator: {reason}");
    }
    with_integrator_filling(scene, choice, effects, plan.shard.is_none(), |tracer| {
        let setup = Setup { choice, reason: &reason, effects, plan, name: &name };
        render_with(scene, options, &setup, estimate_warning.into_iter().collect(), tracer)
    })
}

/// The plan without the error estimate when its moments would not fit in memory but the
/// render would, or would make a shard's part file larger than a part may be (a very large
/// image), with a warning saying so; the plan unchanged otherwise.
///
/// # Errors
/// [`RenderError::Options`] when a target error needs the estimate that does not fit.
fn fit_estimate(
    scene: &Scene,
    plan: RenderPlan,
) -> Result<(RenderPlan, Option<String>), RenderError> {
    if !plan.keeps_estimate() {
        return Ok((plan, None));
    }
    let (w, h) = (scene.camera.width(), scene.camera.height());
    let limit = MemoryLimit::system();
    let without = RenderPlan { error_estimate: false, ..plan };
    let estimate_bytes = plan.memory_bytes(w, h).saturating_sub(without.memory_bytes(w, h));
    // A part file holds the film (up to 48 bytes per pixel) and the moments (72).
    let part_bytes = (u64::from(w) * u64::from(h)).saturating_mul(48 + 72);
    let why = if plan.shard.is_some() && part_bytes > MAX_PART_BYTES {
        format!(
            "a part file of a {w}x{h} image with its moments would exceed the {} part-file limit",
            spectrace_geometry::human_bytes(MAX_PART_BYTES)
        )
    } else if plan.check_memory(w, h, &limit).is_err() && without.check_memory(w, h, &limit).is_ok()
    {
        format!(
            "its moments for a {w}x{h} image ({} more) do not fit in the memory a render may \
             use ({})",
            spectrace_geometry::human_bytes(estimate_bytes),
            limit.source
        )
    } else {
        return Ok((plan, None));
    };
    // A target needs the estimate.
    if plan.target_error.is_some() {
        return Err(RenderError::Options(format!(
            "--target-error / settings.target_error needs the error estimate, but {why}"
        )));
    }
    Ok((without, Some(format!("no error estimate: {why}"))))
}

/// Runs `f` with the estimator `choice` for `scene`, following `effects`.
pub fn with_integrator<R>(
    scene: &Scene,
    choice: IntegratorChoice,
    effects: Effects,
    f: impl FnOnce(&dyn Integrator) -> R,
) -> R {
    with_integrator_filling(scene, choice, effects, true, f)
}

/// As [`with_integrator`]; with `sensors` false the light tracer leaves the scene's sensors
/// alone (a shard's part holds the image only).
pub fn with_integrator_filling<R>(
    scene: &Scene,
    choice: IntegratorChoice,
    effects: Effects,
    sensors: bool,
    f: impl FnOnce(&dyn Integrator) -> R,
) -> R {
    let none = spectrace_tracer::SensorSet::default();
    let tracer_scene =
        if sensors { tracer_scene(scene) } else { tracer_scene(scene).with_sensors(&none) };
    match choice {
        IntegratorChoice::Path => {
            f(&PathTracer::new(&tracer_scene, scene.path_settings(), effects))
        }
        IntegratorChoice::Bdpt => f(&Bdpt::new(&tracer_scene, scene.bdpt_settings(), effects)),
        IntegratorChoice::Light | IntegratorChoice::Auto => {
            f(&LightTracer::new(&tracer_scene, scene.tracer_settings(), effects))
        }
    }
}

/// A render kept in memory: the film, the image and the estimator that made it.
#[derive(Debug, Clone)]
pub struct InMemoryRender {
    /// The film and counters.
    pub output: RenderOutput,
    /// The image (XYZ per pixel, film units).
    pub image: Vec<spectrace_spectrum::Xyz>,
    /// The estimator.
    pub integrator: IntegratorChoice,
}

/// Renders a scene with overrides without writing anything (no probe, no progress bar): for
/// tests, benchmarks and the accuracy report.
///
/// # Errors
/// [`RenderError::Options`] for invalid options or a film that cannot be made.
pub fn render_in_memory(
    scene: &Scene,
    options: &RenderOptions,
) -> Result<InMemoryRender, RenderError> {
    let (choice, _) = choose_integrator(scene, options.integrator);
    let plan = plan_with(scene, options, choice)?;
    let effects = decide_effects(scene, options.effects);
    let output = with_integrator(scene, choice, effects, |tracer| render(tracer, &plan, &|_| {}))
        .map_err(|e| RenderError::Options(e.to_string()))?;
    scene.lights.reset_count();
    let pixels = u64::from(scene.camera.width()) * u64::from(scene.camera.height());
    let image = image(&output, normalisation(choice, scene.lights.power(), pixels));
    Ok(InMemoryRender { output, image, integrator: choice })
}

/// What [`render_scene`] decided before building the estimator.
struct Setup<'a> {
    choice: IntegratorChoice,
    reason: &'a str,
    effects: Effects,
    plan: RenderPlan,
    name: &'a str,
}

/// The rest of [`render_scene`], once the estimator is built; `warnings` are the ones found so
/// far.
fn render_with(
    scene: &Scene,
    options: &RenderOptions,
    setup: &Setup<'_>,
    mut warnings: Vec<String>,
    tracer: &dyn Integrator,
) -> Result<RenderReport, RenderError> {
    let Setup { choice, reason, effects, plan, name } = *setup;
    let name = name.to_owned();
    warnings.extend(integrator_warnings(scene, choice));
    let unreachable =
        |f: spectrace_tracer::SceneFeatures| f.delta_direction_lights + f.beam_only_lights > 0;
    if !scene.sensors.is_empty()
        && scene.settings.sensor_integrator == SensorIntegrator::Path
        && unreachable(tracer_scene(scene).features(&scene.non_convex))
    {
        warnings.push(
            "settings.sensor_integrator \"path\": lasers, skies and beam-only lights cannot be \
             sampled from a point, so the sensors miss their light; use \"light\" or \"auto\""
                .to_owned(),
        );
    }
    if !scene.sensors.is_empty() && plan.shard.is_some() {
        warnings.push(
            "sensors are written by unsharded renders only (merge-parts writes the image): \
             render without --shard for the sensors' files"
                .to_owned(),
        );
    }
    // The light tracer's probe checks that light can reach the camera (for camera integrators a
    // black image is reported after the render).
    let probed = probe_with(scene, &plan, tracer)?;
    if options.verbose && !probed.lit {
        eprintln!(
            "note: the pre-render probe ran out of time after {} paths without seeing light reach \
             the camera; rendering anyway",
            probed.beams
        );
    }
    let bar = progress_bar(&plan, options.verbose);
    let started = Instant::now();
    let target = plan.shard_target_error();
    let update = |p: &spectrace_tracer::Progress| {
        bar.set_position(p.items.min(bar.length().unwrap_or(u64::MAX)));
        if let Some(e) = &p.estimate {
            bar.set_message(progress_message(e, target, p.seconds));
        }
    };
    let output =
        render_observed(tracer, &plan, &update).map_err(|e| RenderError::Options(e.to_string()))?;
    let pixels = u64::from(scene.camera.width()) * u64::from(scene.camera.height());
    let numerator = normalisation(choice, scene.lights.power(), pixels);
    bar.finish_and_clear();
    let wall = started.elapsed().as_secs_f64();
    let make_report = |output: &RenderOutput, mut written: Written| {
        written.warnings.append(&mut warnings.clone());
        let mut r = report(
            scene.path.display().to_string(),
            (scene.camera.width(), scene.camera.height()),
            plan,
            effects,
            tracer.name(),
            output,
            wall,
            scene.lights.power(),
            written,
        );
        r.integrator_reason = reason.to_owned();
        r.sampler = scene.settings.sampler.name().to_owned();
        r
    };
    if let Some((k, n)) = plan.shard {
        let path = options.out_dir.join(format!("{name}.part-{k}-of-{n}.bin"));
        let shard_report = make_report(
            &output,
            Written { files: vec![path.display().to_string()], ..Written::default() },
        );
        // The film moves into the part (no copy of what may be 1.5 GiB).
        let part = PartialFilm {
            version: PARTIAL_VERSION,
            scene_fingerprint: scene.fingerprint(),
            scene_path: scene.path.display().to_string(),
            plan: RenderPlan { shard: None, threads: 0, ..plan },
            light_power: scene.lights.power(),
            integrator: choice,
            sampler: scene.settings.sampler,
            effects,
            output_settings: scene.output.clone(),
            name: name.clone(),
            output,
        };
        let bytes =
            part.encode().map_err(|message| RenderError::File { path: path.clone(), message })?;
        drop(part);
        write_atomically(&path, |p| std::fs::write(p, &bytes).map_err(|e| e.to_string()))
            .map_err(|message| RenderError::File { path: path.clone(), message })?;
        return Ok(shard_report);
    }
    let mut written = write_outputs(&options.out_dir, &name, &scene.output, numerator, &output)?;
    if !probed.lit && output.film.accepted() == 0 {
        written.warnings.push(format!(
            "no light reached the camera: the image is black (the pre-render probe ran out of \
             time after {} paths, and none of the {} paths rendered lit a point the camera sees)",
            probed.beams, output.beams
        ));
    }
    let sensors = if scene.sensors.is_empty() {
        Vec::new()
    } else if tracer.sensor_cells() > 0 {
        let source = SensorSource {
            film: &output.film,
            beams: output.beams,
            seconds: output.seconds,
            filled_by: "image beams (light tracer)",
        };
        write_sensors(scene, &options.out_dir, source)?
    } else if sensor_integrator(scene) == SensorIntegrator::Light {
        let (film, beams, seconds) =
            sensor_pass(scene, &sensor_plan(scene, plan.threads), effects)?;
        let source =
            SensorSource { film: &film, beams, seconds, filled_by: "sensor pass (light tracer)" };
        write_sensors(scene, &options.out_dir, source)?
    } else {
        let passes = scene.settings.sensor_spp.unwrap_or(DEFAULT_SENSOR_SPP);
        let (film, beams, seconds) = sensor_pass_path(scene, passes, plan.threads, effects)?;
        let source = SensorSource {
            film: &film,
            beams,
            seconds,
            filled_by: "points sampled on the sensor (path tracer)",
        };
        write_sensors(scene, &options.out_dir, source)?
    };
    for r in &sensors {
        written.files.extend(r.files.iter().cloned());
        if options.verbose {
            eprintln!("{}", sensor_summary(r));
        }
    }
    let mut report = make_report(&output, written);
    report.sensors = sensors;
    write_sidecar(&options.out_dir, &name, &report)?;
    Ok(report)
}

/// How a camera integrator's render fills the sensors: the setting, with `auto` resolved (the
/// path tracer when every light can be sampled from a point, else light paths).
pub fn sensor_integrator(scene: &Scene) -> SensorIntegrator {
    match scene.settings.sensor_integrator {
        SensorIntegrator::Auto => {
            let f = tracer_scene(scene).features(&scene.non_convex);
            if f.beam_only_lights == 0 && f.delta_direction_lights == 0 {
                SensorIntegrator::Path
            } else {
                SensorIntegrator::Light
            }
        }
        other => other,
    }
}

/// What [`write_outputs`] wrote.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Written {
    /// The files.
    pub files: Vec<String>,
    /// The EXR's scale exponent (see [`encode_image`]).
    pub exr_scale_log2: i32,
    /// Values beyond the range of 32-bit floats without that scale.
    pub out_of_range_values: u64,
    /// Warnings for the user.
    pub warnings: Vec<String>,
}

#[allow(clippy::too_many_arguments)]
fn report(
    scene: String,
    (width, height): (u32, u32),
    plan: RenderPlan,
    effects: Effects,
    integrator: &str,
    output: &RenderOutput,
    wall: f64,
    light_power: f64,
    written: Written,
) -> RenderReport {
    let mut warnings = written.warnings;
    if output.film.rejected() > 0 {
        warnings.push(rejected_warning(output.film.rejected()));
    }
    RenderReport {
        scene,
        width,
        height,
        plan,
        effects,
        effects_summary: effects.summary(),
        integrator: integrator.to_owned(),
        integrator_reason: String::new(),
        sampler: independent_sampler(),
        beams: output.beams,
        wall_seconds: wall,
        beams_per_second: if wall > 0.0 { output.beams as f64 / wall } else { 0.0 },
        rejected_contributions: output.film.rejected(),
        error_estimate: output
            .estimate()
            .map(|e| AccuracyEstimate::new(&e, plan.target_error, output.seconds)),
        stats: output.stats,
        light_power,
        outputs: written.files,
        exr_scale_log2: written.exr_scale_log2,
        out_of_range_values: written.out_of_range_values,
        warnings,
        sensors: Vec::new(),
        version: env!("CARGO_PKG_VERSION").to_owned(),
    }
}

fn rejected_warning(n: u64) -> String {
    format!(
        "{n} contributions were not finite or beyond the film's range and were left out: \
         the image is darker than it should be where they fell"
    )
}

fn progress_bar(plan: &RenderPlan, visible: bool) -> indicatif::ProgressBar {
    if !visible {
        return indicatif::ProgressBar::hidden();
    }
    let open_ended = plan.time_budget.is_some() || plan.target_error.is_some();
    let bar = indicatif::ProgressBar::new(plan.shard_beams());
    let template = if open_ended {
        "{spinner} {elapsed_precise} {pos} items ({per_sec}) {msg}"
    } else {
        "{bar:30} {percent:>3}% {pos}/{len} items, {per_sec}, ETA {eta} {msg}"
    };
    if let Ok(style) = indicatif::ProgressStyle::with_template(template) {
        bar.set_style(style);
    }
    bar
}

/// The progress bar's message for a live estimate: the error and, with a target, the time
/// still needed (error falling as `1 / sqrt(time)`).
fn progress_message(
    e: &spectrace_tracer::ErrorEstimate,
    target: Option<f64>,
    seconds: f64,
) -> String {
    let Some(r) = e.relative_rmse else {
        return format!("error: waiting for batches ({})", e.batches);
    };
    let mut m = format!("error {:.2}%", r * 100.0);
    if !e.is_trusted() {
        m.push_str(&format!(" ({} of {} batches)", e.batches, spectrace_tracer::MIN_BATCHES));
    }
    if let Some(t) = target {
        let left = (seconds * (r / t).powi(2) - seconds).max(0.0);
        m.push_str(&format!(" -> {:.2}%, ~{} to go", t * 100.0, duration(left)));
    }
    m
}

/// The final image of a render: XYZ per pixel in film units.
pub fn image(output: &RenderOutput, norm: Normalisation) -> Vec<spectrace_spectrum::Xyz> {
    output.film.to_xyz(norm.scale(output.beams))
}

/// Writes the EXR and PNG of a finished render (each to a temporary name, then renamed into
/// place); returns what was written.
///
/// # Errors
/// [`RenderError::File`] if a file cannot be written.
pub fn write_outputs(
    dir: &Path,
    name: &str,
    settings: &OutputSettings,
    numerator: Normalisation,
    output: &RenderOutput,
) -> Result<Written, RenderError> {
    let (w, h) = (output.film.width(), output.film.height());
    let image = encode_image(output, numerator);
    let mut written = Written {
        exr_scale_log2: image.scale_log2,
        out_of_range_values: image.out_of_range_values,
        ..Written::default()
    };
    if image.scale_log2 != 0 {
        written.warnings.push(format!(
            "the image lies beyond the range of 32-bit floats ({} values would be infinite or \
             zero): the EXR holds it multiplied by 2^{} (header attribute spectraceScaleLog2, \
             sidecar exr_scale_log2)",
            image.out_of_range_values, image.scale_log2
        ));
    }
    let file_error = |path: &Path| {
        let path = path.to_owned();
        move |message| RenderError::File { path, message }
    };
    if settings.exr {
        let path = dir.join(format!("{name}.exr"));
        write_atomically(&path, |p| write_exr(p, w, h, &image.rgb, image.scale_log2))
            .map_err(file_error(&path))?;
        written.files.push(path.display().to_string());
    }
    if settings.png {
        let path = dir.join(format!("{name}.png"));
        write_atomically(&path, |p| {
            write_png(p, w, h, &image.rgb, settings.exposure, image.scale_log2)
        })
        .map_err(file_error(&path))?;
        written.files.push(path.display().to_string());
    }
    if settings.error_image {
        match &output.moments {
            Some(moments) => {
                let path = dir.join(format!("{name}.error.exr"));
                // In the image's units and with the image's EXR scale, so the two compare
                // pixel by pixel.
                let factor = numerator.scale(output.beams) * 2f64.powi(image.scale_log2);
                let rgb: Vec<[f32; 3]> = moments
                    .standard_error_rgb(factor)
                    .into_iter()
                    .map(|p| p.map(|v| v.min(f64::from(f32::MAX)) as f32))
                    .collect();
                write_atomically(&path, |p| write_exr(p, w, h, &rgb, image.scale_log2))
                    .map_err(file_error(&path))?;
                written.files.push(path.display().to_string());
            }
            None => written.warnings.push(
                "output.error_image: no error image, the render kept no error estimate".to_owned(),
            ),
        }
    }
    Ok(written)
}

fn write_sidecar(dir: &Path, name: &str, report: &RenderReport) -> Result<(), RenderError> {
    let path = dir.join(format!("{name}.json"));
    let text = serde_json::to_string_pretty(report)
        .map_err(|e| RenderError::File { path: path.clone(), message: e.to_string() })?;
    write_atomically(&path, |p| std::fs::write(p, &text).map_err(|e| e.to_string()))
        .map_err(|message| RenderError::File { path, message })
}

/// Merges the partial films of a sharded render into the final outputs, bit-identical to a
/// one-machine render with the same seed.
///
/// Every part is read with a size limit and validated field by field ([`PartialFilm::decode`]);
/// parts must come from the same render, may not share a chunk, and (without a time budget) must
/// cover every chunk. Outputs go into `out_dir` under the parts' validated name and never replace
/// a part file.
///
/// # Errors
/// [`RenderError::File`] for an unreadable or invalid part (naming the file and the field);
/// [`RenderError::Options`] when the parts do not belong together, overlap, miss chunks, or their
/// counts overflow.
pub fn merge_parts(parts: &[PathBuf], out_dir: &Path) -> Result<RenderReport, RenderError> {
    let read = |path: &PathBuf| {
        PartialFilm::read(path).map_err(|message| RenderError::File { path: path.clone(), message })
    };
    let Some(first_path) = parts.first() else {
        return Err(RenderError::Options("merge needs at least one partial film".to_owned()));
    };
    // Parts are read one at a time: memory holds the merged film and one part, whatever their
    // number. The first part's film becomes the merged film.
    let mut first = read(first_path)?;
    let (w, h) = (first.output.film.width(), first.output.film.height());
    let limit = MemoryLimit::system();
    let needed = Film::bytes_for(w, h).saturating_mul(2);
    if needed > limit.bytes {
        return Err(RenderError::Options(format!(
            "merging {w}x{h} films needs {} (the merged film and one part), more than the {} \
             this machine may use ({})",
            spectrace_geometry::human_bytes(needed),
            spectrace_geometry::human_bytes(limit.bytes),
            limit.source
        )));
    }
    planned_outputs(out_dir, &first.name, &first.output_settings, None, parts, Vec::new())?;
    let placeholder = RenderOutput {
        film: Film::new(1, 1).map_err(|e| RenderError::Options(e.to_string()))?,
        stats: TraceStats::default(),
        chunks: Vec::new(),
        beams: 0,
        seconds: 0.0,
        moments: None,
    };
    let mut merged = std::mem::replace(&mut first.output, placeholder);
    // Which part holds each chunk: coverage is checked by chunk identity, not by count.
    let mut owner: std::collections::BTreeMap<u64, usize> =
        merged.chunks.iter().map(|&c| (c, 0)).collect();
    let mut seconds = vec![merged.seconds];
    for (index, path) in parts.iter().enumerate().skip(1) {
        let part = read(path)?;
        let different = if part.scene_fingerprint != first.scene_fingerprint {
            Some("scene")
        } else if part.plan != first.plan {
            Some("plan (beams, chunk size, seed or time budget)")
        } else if part.effects != first.effects {
            Some("effects decision")
        } else if part.name != first.name || part.output_settings != first.output_settings {
            Some("output settings")
        } else if part.integrator != first.integrator {
            Some("integrator")
        } else if part.sampler != first.sampler {
            Some("sampler")
        } else if part.light_power.to_bits() != first.light_power.to_bits() {
            Some("light power")
        } else if (part.output.film.width(), part.output.film.height()) != (w, h) {
            Some("image size")
        } else {
            None
        };
        if let Some(what) = different {
            return Err(RenderError::Options(format!(
                "{}: belongs to another render: its {what} differs from {}",
                path.display(),
                first_path.display()
            )));
        }
        for &c in &part.output.chunks {
            if let Some(&other) = owner.get(&c) {
                return Err(RenderError::Options(format!(
                    "{}: chunk {c} is also in {} (the same shard twice?)",
                    path.display(),
                    parts[other].display()
                )));
            }
            owner.insert(c, index);
        }
        add_counts(&merged, &part.output).map_err(|what| {
            RenderError::Options(format!(
                "{}: adding its {what} to the other parts' overflows: not parts of one render",
                path.display()
            ))
        })?;
        merged
            .merge(&part.output)
            .map_err(|e| RenderError::Options(format!("{}: {e}", path.display())))?;
        seconds.push(part.output.seconds);
    }
    // Time budgets and targets stop early: only they may leave chunks out.
    if first.plan.time_budget.is_none() && first.plan.target_error.is_none() {
        let expected = first.plan.chunks();
        if owner.len() as u64 != expected {
            let missing =
                (0..expected).filter(|c| !owner.contains_key(c)).take(10).collect::<Vec<_>>();
            return Err(RenderError::Options(format!(
                "the parts cover {} of {expected} chunks; missing e.g. {missing:?}",
                owner.len()
            )));
        }
    }
    let numerator = normalisation(first.integrator, first.light_power, u64::from(w) * u64::from(h));
    let written = write_outputs(out_dir, &first.name, &first.output_settings, numerator, &merged)?;
    let total_seconds: f64 = seconds.iter().sum();
    let mut report = report(
        first.scene_path.clone(),
        (w, h),
        first.plan,
        first.effects,
        first.integrator.name(),
        &merged,
        seconds.iter().copied().fold(0.0, f64::max),
        first.light_power,
        written,
    );
    report.beams_per_second =
        if total_seconds > 0.0 { merged.beams as f64 / total_seconds } else { 0.0 };
    report.sampler = first.sampler.name().to_owned();
    write_sidecar(out_dir, &first.name, &report)?;
    Ok(report)
}

/// Checks that adding `part`'s counters to `merged`'s cannot overflow (tampered parts could make
/// them wrap); names the counter that would.
fn add_counts(merged: &RenderOutput, part: &RenderOutput) -> Result<(), &'static str> {
    let fits = |a: u64, b: u64, what: &'static str| a.checked_add(b).map(|_| ()).ok_or(what);
    fits(merged.beams, part.beams, "beams")?;
    fits(merged.stats.beams, part.stats.beams, "beam count")?;
    fits(merged.stats.hits, part.stats.hits, "hit count")?;
    fits(merged.stats.splats, part.stats.splats, "splat count")?;
    fits(merged.stats.roulette_kills, part.stats.roulette_kills, "roulette count")?;
    fits(merged.stats.depth_limited, part.stats.depth_limited, "depth-limit count")?;
    fits(merged.stats.reemissions, part.stats.reemissions, "re-emission count")?;
    fits(merged.film.accepted(), part.film.accepted(), "accepted-contribution count")?;
    fits(merged.film.rejected(), part.film.rejected(), "rejected-contribution count")?;
    Ok(())
}

/// One row of the effects benchmark: the same scene and beams rendered with the effects
/// analysis' decision and with everything simulated the general way.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EffectsBenchmarkRow {
    /// The scene file.
    pub scene: String,
    /// The decision in words.
    pub effects: String,
    /// Beams per render.
    pub beams: u64,
    /// Wall time with the analysis' decision (s).
    pub auto_seconds: f64,
    /// Wall time with `effects: off` (s).
    pub off_seconds: f64,
    /// Wavelength samples that reached the film per second, with the decision.
    pub auto_spectral_samples_per_second: f64,
    /// The same with `effects: off`.
    pub off_spectral_samples_per_second: f64,
}

/// Renders `scene` twice with the same beams and seed, with the effects analysis' decision and
/// with `off`, and measures both (the effects benchmark behind `spectrace bench`).
///
/// # Errors
/// As [`render_scene`].
pub fn effects_benchmark(
    scene: &Scene,
    beams: u64,
    threads: usize,
) -> Result<EffectsBenchmarkRow, RenderError> {
    let options = RenderOptions {
        beams: Some(beams),
        threads: Some(threads),
        seed: Some(1),
        ..RenderOptions::default()
    };
    // The effects analysis' savings are measured on the light tracer, whose knobs they are.
    let plan = plan_with(scene, &options, IntegratorChoice::Light)?;
    let measure = |mode: EffectsMode| -> Result<(f64, f64, Effects), RenderError> {
        let effects = decide_effects(scene, Some(mode));
        let started = Instant::now();
        let tracer_scene = tracer_scene(scene);
        let tracer = LightTracer::new(&tracer_scene, scene.tracer_settings(), effects);
        let out =
            render(&tracer, &plan, &|_| {}).map_err(|e| RenderError::Options(e.to_string()))?;
        let seconds = started.elapsed().as_secs_f64();
        scene.lights.reset_count();
        // Every splat carries `wavelengths_per_path` spectral samples.
        let samples = out.stats.splats as f64 * effects.wavelengths_per_path as f64;
        Ok((seconds, samples / seconds.max(1e-9), effects))
    };
    let (auto_seconds, auto_rate, effects) = measure(EffectsMode::Auto)?;
    let (off_seconds, off_rate, _) = measure(EffectsMode::Off)?;
    Ok(EffectsBenchmarkRow {
        scene: scene.path.display().to_string(),
        effects: effects.summary(),
        beams,
        auto_seconds,
        off_seconds,
        auto_spectral_samples_per_second: auto_rate,
        off_spectral_samples_per_second: off_rate,
    })
}

// ---------------------------------------------------------------------------------------------
// The estimators side by side (`spectrace bench`).

/// Renders `paths` paths with `integrator` (for a camera integrator, `ceil(paths / pixels)`
/// samples per pixel) and returns the XYZ image, the wall time of the render alone and the paths
/// traced. The measurement of [`integrator_benchmark`] and of the accuracy report
/// (`spectrace-lab`).
///
/// # Errors
/// A message for an invalid plan (zero paths, too many threads) or a failed render.
pub fn render_xyz(
    scene: &Scene,
    integrator: IntegratorChoice,
    mode: EffectsMode,
    paths: u64,
    seed: u64,
    threads: usize,
) -> Result<(Vec<spectrace_spectrum::Xyz>, f64, u64), String> {
    let options = RenderOptions {
        beams: Some(paths),
        seed: Some(seed),
        threads: Some(threads),
        effects: Some(mode),
        ..RenderOptions::default()
    };
    let (choice, _) = choose_integrator(scene, Some(integrator));
    let mut plan = plan_with(scene, &options, choice).map_err(|e| e.to_string())?;
    if choice == IntegratorChoice::Light {
        // At least ~16 chunks per render, so small sweep points use every thread too; the chunk
        // size depends on the beams alone, so a cached reference stays valid whatever the thread
        // count. (A camera integrator's chunk is a pass of one sample per pixel.)
        plan.chunk_beams = (paths / 16).clamp(1, plan.chunk_beams.max(1024)).min(plan.chunk_beams);
    }
    let effects = decide_effects(scene, Some(mode));
    scene.lights.reset_count();
    let started = Instant::now();
    // The image by the estimator's own `image_scale` (its documented film units; the same as
    // the renderer's `normalisation`).
    let (output, scale) = with_integrator(scene, choice, effects, |tracer| {
        render(tracer, &plan, &|_| {}).map(|out| {
            let scale = tracer.image_scale(out.beams);
            (out, scale)
        })
    })
    .map_err(|e| e.to_string())?;
    let seconds = started.elapsed().as_secs_f64();
    scene.lights.reset_count();
    Ok((output.film.to_xyz(scale), seconds, output.beams))
}

/// One estimator's measurement in [`integrator_benchmark`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct IntegratorTiming {
    /// The estimator asked for (`auto` included).
    pub integrator: IntegratorChoice,
    /// Paths traced (beams for the light tracer; `ceil(paths / pixels)` samples per pixel for
    /// the camera integrators).
    pub paths: u64,
    /// Wall time of the render alone (s).
    pub seconds: f64,
}

impl IntegratorTiming {
    /// Paths per second.
    pub fn paths_per_second(&self) -> f64 {
        self.paths as f64 / self.seconds.max(1e-9)
    }
}

/// One scene of `spectrace bench`: paths per second of every estimator with the same paths.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct IntegratorBenchmarkRow {
    /// The scene file.
    pub scene: String,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// The estimator `auto` picks.
    pub auto_picks: IntegratorChoice,
    /// Why, in words.
    pub auto_reason: String,
    /// Light, path, bdpt and auto, in that order.
    pub timings: Vec<IntegratorTiming>,
}

/// Renders `scene` with light, path, bdpt and auto, each with `paths` paths (N beams for the
/// light tracer, `ceil(N / pixels)` samples per pixel for the camera integrators) and the same
/// seed, and measures each (the integrator columns of `spectrace bench`).
///
/// # Errors
/// A message naming the estimator for zero paths, too many threads or a failed render.
pub fn integrator_benchmark(
    scene: &Scene,
    paths: u64,
    threads: usize,
) -> Result<IntegratorBenchmarkRow, String> {
    let (auto_picks, auto_reason) = choose_integrator(scene, Some(IntegratorChoice::Auto));
    let mut timings = Vec::new();
    for integrator in [
        IntegratorChoice::Light,
        IntegratorChoice::Path,
        IntegratorChoice::Bdpt,
        IntegratorChoice::Auto,
    ] {
        let (_, seconds, traced) =
            render_xyz(scene, integrator, EffectsMode::Auto, paths, 1, threads)
                .map_err(|e| format!("{}: {}: {e}", scene.path.display(), integrator.name()))?;
        timings.push(IntegratorTiming { integrator, paths: traced, seconds });
    }
    Ok(IntegratorBenchmarkRow {
        scene: scene.path.display().to_string(),
        width: scene.camera.width(),
        height: scene.camera.height(),
        auto_picks,
        auto_reason,
        timings,
    })
}
