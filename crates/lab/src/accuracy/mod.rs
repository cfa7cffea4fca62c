//! What accuracy costs in time: error-against-time sweeps of every accuracy knob, the estimator
//! included.
//!
//! [`run`] renders, for each scene, a *reference* image once at high effort (the scene as written,
//! effects analysis on, by an estimator that is unbiased on the scene: see
//! [`reference_integrator`]; cached on disk with the settings that made it), then sweeps the
//! number of paths (doubling from [`AccuracyOptions::start_beams`]) for each [`Configuration`]:
//!
//! | configuration | what changes |
//! |---|---|
//! | `baseline` | nothing: the light tracer on the scene as written, effects analysis `auto`, independent sampling |
//! | `equal_wavelengths` | every light draws its wavelengths uniformly with weights (`"wavelength_sampling": "equal_wavelengths"`) instead of by importance |
//! | `piecewise_constant_spd` | every `Tabulated` SPD of the lights (and every tabulated `CieIlluminant`) becomes the seed's "choppy" `Binned` SPD: bins centred on the table's nodes, the same values |
//! | `effects_off` | the effects analysis off (one wavelength per path, beams continue after diffuse hits) |
//! | `path`, `bdpt` | the estimator, with independent sampling: N paths are `ceil(N / pixels)` camera samples per pixel |
//! | `auto` | the estimator `auto` picks ([`IntegratorChoice::decide`]), with the default sampler |
//! | `observer_wavelengths` | every light draws its wavelengths from SPD x observer sensitivity with weights (`"wavelength_sampling": "observer"`), light tracer |
//! | `sobol` | Owen-scrambled Sobol points instead of independent uniforms (`settings.sampler: "sobol"`), light tracer |
//! | `path_sobol`, `bdpt_sobol` | the path tracer and BDPT with `settings.sampler: "sobol"` (compare with `path` and `bdpt`, which sample independently) |
//!
//! Which knobs act on which estimator ([`KNOBS_BY_ESTIMATOR`], also in the report): the sampler
//! and the SPD sampler act on all three (a piecewise-constant SPD is another spectrum, so every
//! estimator converges to another image); the lights' wavelength strategy acts on the light
//! tracer and on one-wavelength BDPT (whose light subpaths start with a light's beam), not on
//! the path tracer or hero-wavelength BDPT, whose camera paths draw their own wavelengths
//! (`settings.camera_wavelengths`); the effects
//! analysis sets the light tracer's wavelengths per path and whether its beams and the path
//! tracer's paths continue after a diffuse hit, and BDPT ignores it. The sweep applies each
//! non-estimator knob to the light tracer, where all of them act, and the sampler also to the
//! path tracer and BDPT.
//!
//! Code: this module runs the sweep; `configuration` names the knobs, `knobs` sets them on the
//! typed scene, `cache` keeps the references, `report` analyses and writes the Markdown, `gains`
//! states each variance-reduction knob's variance over its peer's (pixel and colour), `plot`
//! draws the SVG, and `tests` tests them.
//!
//! Each point records the wall time of the render alone and the relative RMSE of the XYZ image
//! against the reference, `sqrt(sum |xyz - ref|^2 / sum |ref|^2)` over all pixels. Monte Carlo
//! error falls as `time^(-1/2)`; the report fits the slope of log error against log time per
//! configuration and puts it beside -1/2 (a flatter slope means bias, as with a changed spectrum
//! or an estimator that misses some light, or fixed costs that do not scale with paths).
//!
//! Outputs: `accuracy.md` (a table per scene, the slopes, which configuration reaches a given
//! error fastest, and the seconds to 10% of each estimator with auto's time over the fastest's)
//! and `accuracy.svg` (log-log plot of error against time, one panel per scene, one line per
//! configuration, with a dashed line of slope -1/2), both in [`AccuracyOptions::out_dir`].
//!
//! Every configuration is the scene file loaded as the renderer's typed [`Scene`] with its knobs
//! set on typed fields ([`apply`]): `settings.sampler`, the effects mode and the estimator
//! directly, a light's wavelength sampling through
//! [`spectrace_lights::LightSource::set_wavelength_sampling`] and its SPD through [`spectrace_lights::LightSource::map_spd`] with
//! [`SpectralPowerDistribution::piecewise_constant`] (hooks whose defaults say "not supported",
//! so third-party lights and spectra keep compiling; such lights are left as written and counted
//! in the report). No scene JSON is edited.
//!
//! To keep the default run short, [`AccuracyOptions::max_width`] scales the camera resolution down
//! (a new camera from the same [`CameraRepr`] with a smaller `width`/`height`, keeping the aspect
//! ratio); the field of view is unchanged, so the image shows the same view with fewer pixels.

mod cache;
mod check;
mod configuration;
mod gains;
mod knobs;
mod plot;
mod relmse;
mod report;

use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::{Deserialize, Serialize};
use spectrace_lights::WavelengthSampling;
use spectrace_lights::sampling::{GOLDEN_GAMMA, mix64};
use spectrace_renderer::{Scene, choose_integrator, decide_effects, render_xyz};
use spectrace_spectrum::{SpectralPowerDistribution, Xyz};
use spectrace_tracer::{
    ByMeasure, CameraRepr, EffectsMode, ErrorMeasure, IntegratorChoice, PinholeCamera, SamplerKind,
    SceneFeatures, relative_error,
};

use cache::{cache_key, deep_reference, read_reference, write_reference};
pub use check::{
    CHECK_REFERENCE_FACTOR, CheckReference, ESTIMATE_CAP_SECONDS, ESTIMATE_MEASURE,
    ESTIMATE_TARGET, EstimateCheck, estimate_check,
};
pub use configuration::Configuration;
pub use knobs::apply;
use knobs::limit_resolution;
pub use plot::write_plot;
pub use report::markdown;

/// Settings of an accuracy run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AccuracyOptions {
    /// The scene files.
    pub scenes: Vec<PathBuf>,
    /// Where `accuracy.md` and `accuracy.svg` go (default `docs`).
    pub out_dir: PathBuf,
    /// Where reference images are cached (default `target/accuracy-cache`).
    pub cache_dir: PathBuf,
    /// Paths of the reference image (default 2^24, 16 times the largest default sweep point, so
    /// the reference's own noise adds at most ~3% to the errors of its own estimator; keep it at
    /// least 8 times the largest sweep point). Its noise still limits how small an error can be
    /// measured: see the "reference's noise" column of the report's summary.
    pub reference_beams: u64,
    /// Paths of the first sweep point (default 2^12: one sample per pixel at the default width).
    pub start_beams: u64,
    /// Sweep points per configuration: `start_beams * 2^k` for `k < steps` (default 8).
    pub steps: u32,
    /// Worker threads (0: one per core, the default).
    pub threads: usize,
    /// Seed of the reference; the sweep points use seeds derived from it (never equal to it).
    pub seed: u64,
    /// Scale the camera down to at most this many pixels wide, keeping the aspect ratio (default
    /// `Some(96)`; `None` renders at the scene's own resolution).
    pub max_width: Option<u32>,
    /// The configurations to sweep, in report order (default: [`Configuration::ALL`]).
    #[serde(default = "all_configurations")]
    pub configurations: Vec<Configuration>,
    /// Check the renderer's own error estimate and the pilot's prediction on every scene
    /// ([`estimate_check`]; default on).
    #[serde(default)]
    pub estimate_check: bool,
    /// The estimate check's target in `relmse` (default [`ESTIMATE_TARGET`]).
    #[serde(default = "default_estimate_target")]
    pub estimate_target: f64,
}

fn default_estimate_target() -> f64 {
    ESTIMATE_TARGET
}

fn all_configurations() -> Vec<Configuration> {
    Configuration::ALL.to_vec()
}

impl Default for AccuracyOptions {
    /// Settings measured to finish every shipped scene with every configuration in under 20
    /// minutes on 2 shared cores, references included (see the run time in `docs/accuracy.md`):
    /// the sweep stops at 2^20 paths, where the faster configurations pass 10% and a few pass 2%;
    /// the other times to 2% are extrapolated along the fitted slopes and marked so.
    fn default() -> Self {
        Self {
            scenes: default_scenes(),
            out_dir: PathBuf::from("docs"),
            cache_dir: PathBuf::from("target/accuracy-cache"),
            reference_beams: 1 << 24,
            start_beams: 1 << 12,
            steps: 9,
            threads: 0,
            seed: 0x5EED_ACC0,
            max_width: Some(96),
            configurations: all_configurations(),
            estimate_check: true,
            estimate_target: ESTIMATE_TARGET,
        }
    }
}

/// The scenes of the default report: every shipped scene, `scenes/*.json` relative to the working
/// directory, sorted by name (none if the folder cannot be read).
pub fn default_scenes() -> Vec<PathBuf> {
    let Ok(entries) = std::fs::read_dir("scenes") else { return Vec::new() };
    let mut scenes: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.is_file() && p.extension().is_some_and(|x| x == "json"))
        .collect();
    scenes.sort();
    scenes
}

/// One rendered sweep point.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AccuracyPoint {
    /// Beams traced.
    pub beams: u64,
    /// Seed of the render.
    pub seed: u64,
    /// Wall time of the render alone (s).
    pub seconds: f64,
    /// Relative RMSE of XYZ against the reference.
    pub relative_rmse: f64,
    /// Sum of Y over the image over the reference's: 1 for an unbiased estimator (up to noise);
    /// far from 1 when light is missing or added.
    #[serde(default)]
    pub mean_ratio: f64,
    /// The part of the relative RMSE that changes pixels' colours, not their brightness (see
    /// [`colour_relative_rmse`]); 0 in reports written before it was measured.
    #[serde(default)]
    pub colour_rmse: f64,
    /// The per-pixel relative error against the reference ([`ErrorMeasure::RelMse`], the
    /// renderer's default measure; the plot's); 0 in reports written before it was measured.
    #[serde(default)]
    pub relmse: f64,
}

/// The sweep of one configuration on one scene.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ConfigurationResult {
    /// Which configuration.
    pub configuration: Configuration,
    /// What the rewrite changed in this scene (e.g. "2 lights"), empty for none.
    pub changed: String,
    /// Why the configuration does not apply to this scene (then `points` is empty).
    pub not_applicable: Option<String>,
    /// Why the configuration converges to another image than the reference on this scene, when
    /// it is known from the scene's features alone (see [`known_bias`]); `None` for none known.
    #[serde(default)]
    pub known_bias: Option<String>,
    /// The sweep, by increasing beams.
    pub points: Vec<AccuracyPoint>,
    /// Least-squares slope of log error against log time (-1/2 for plain Monte Carlo).
    pub slope_vs_time: Option<f64>,
    /// Least-squares slope of log error against log beams (-1/2 for plain Monte Carlo).
    pub slope_vs_beams: Option<f64>,
}

/// The reference image of a scene.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ReferenceInfo {
    /// The estimator that rendered it (see [`reference_integrator`]).
    pub integrator: IntegratorChoice,
    /// Paths (beams for the light tracer, camera samples for the others).
    pub beams: u64,
    /// Seed.
    pub seed: u64,
    /// Wall time of its render (s), as recorded when it was made.
    pub seconds: f64,
    /// Whether it was read from the cache.
    pub cached: bool,
    /// The cache file.
    pub file: String,
}

/// The results of one scene.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SceneResult {
    /// The scene file, as given.
    pub scene: String,
    /// A short name (the file stem).
    pub name: String,
    /// Image width used (after [`AccuracyOptions::max_width`]).
    pub width: u32,
    /// Image height used.
    pub height: u32,
    /// The baseline's effects decision.
    pub effects_summary: String,
    /// The estimator `auto` picks for the scene.
    pub auto_picks: IntegratorChoice,
    /// Why, in words.
    pub auto_reason: String,
    /// The reference.
    pub reference: ReferenceInfo,
    /// One sweep per configuration.
    pub configurations: Vec<ConfigurationResult>,
    /// The renderer's error estimate and the pilot's prediction against the truth.
    #[serde(default)]
    pub estimate_check: Option<EstimateCheck>,
}

/// Everything an accuracy run measured.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AccuracyReport {
    /// Worker threads used.
    pub threads: usize,
    /// The options of the run.
    pub options: AccuracyOptions,
    /// One entry per scene.
    pub scenes: Vec<SceneResult>,
    /// Wall time of the whole run (s).
    pub total_seconds: f64,
    /// Files written.
    pub files: Vec<String>,
}

/// Which knobs act on which estimator, as the report states it (see the module documentation).
pub const KNOBS_BY_ESTIMATOR: &str = "the sampler (`sobol`, `path_sobol`, `bdpt_sobol`; `path` \
     and `bdpt` sample independently, `auto` as by default) and the SPD sampler \
     (`piecewise_constant_spd`, another spectrum) act on every estimator; the lights' wavelength \
     strategy (`equal_wavelengths`, `observer_wavelengths`) acts on the light tracer, and on \
     BDPT only with one wavelength per sample (`bdpt_beam`, and scenes that disperse, fluoresce \
     or have line spectra, whose light subpaths start with a light's beam), not on the path \
     tracer or hero-wavelength BDPT (`bdpt`), whose camera paths draw their own wavelengths \
     (`settings.camera_wavelengths`, swept as `path_uniform_wavelengths` against the visible \
     density of `path`); BDPT's wavelengths (`bdpt_beam` against `bdpt`) act on BDPT alone; \
     the effects analysis \
     (`effects_off`) sets the light tracer's wavelengths per path and whether light-tracer beams \
     and path-tracer paths continue after a diffuse hit, and BDPT ignores it. The sweep applies \
     each of these knobs to the light tracer, where all of them act, and the sampler also to the \
     path tracer and BDPT";

/// The Monte Carlo expectation for the slope of log error against log time.
pub const EXPECTED_SLOPE: f64 = -0.5;

/// A round error target the report also names the fastest configuration for (10%: reached within
/// the default sweep on the small scenes, so the answer is interpolated, not extrapolated).
pub const ROUND_TARGET: f64 = 0.10;

/// The finer error target: about (10/2)^2 = 25 times the effort of [`ROUND_TARGET`] for plain
/// Monte Carlo, so usually beyond the default sweep and extrapolated (and said so).
pub const FINE_TARGET: f64 = 0.02;

/// The error targets of the summary table: [`ROUND_TARGET`] and [`FINE_TARGET`].
pub const TARGETS: [f64; 2] = [ROUND_TARGET, FINE_TARGET];

/// Times within this factor of the fastest are reported as a tie: single timings on a shared
/// machine vary by about this much.
pub const TIE_FACTOR: f64 = 1.15;

/// `auto` counts as a good pick when its time to [`ROUND_TARGET`] is within this factor of the
/// fastest estimator's.
pub const AUTO_FACTOR: f64 = 1.3;

/// A slope of log error against log time over the last three points flatter than this means the
/// error levels off (bias); such a configuration's time to a target is never extrapolated.
pub const LEVELS_OFF_SLOPE: f64 = -0.25;

/// Runs the sweeps, writes `accuracy.md` and `accuracy.svg` into `options.out_dir`, and returns
/// the measurements. Progress goes to stderr.
///
/// # Errors
/// A message for invalid options, a scene that cannot be loaded or renders black, or a file
/// that cannot be written.
pub fn run(options: &AccuracyOptions) -> Result<AccuracyReport, String> {
    let started = Instant::now();
    if options.scenes.is_empty() {
        return Err("accuracy: no scenes given (and none of the default scenes exists)".to_owned());
    }
    if options.configurations.is_empty() {
        return Err("accuracy: configurations: none given (name at least one)".to_owned());
    }
    if options.start_beams == 0 || options.steps == 0 || options.reference_beams == 0 {
        return Err(
            "accuracy: reference_beams, start_beams and steps must be at least 1".to_owned()
        );
    }
    let largest = options
        .start_beams
        .checked_mul(1u64 << (options.steps - 1).min(62))
        .filter(|_| options.steps <= 63)
        .ok_or("accuracy: start_beams * 2^(steps - 1) overflows")?;
    if largest >= options.reference_beams {
        eprintln!(
            "accuracy: warning: the largest sweep point ({largest} beams) is not below the \
             reference ({} beams); errors will be dominated by the reference's own noise",
            options.reference_beams
        );
    }
    let threads = if options.threads == 0 {
        std::thread::available_parallelism().map_or(1, |n| n.get())
    } else {
        options.threads
    };
    let mut scenes = Vec::new();
    for path in &options.scenes {
        scenes.push(run_scene(path, options, threads)?);
    }
    std::fs::create_dir_all(&options.out_dir)
        .map_err(|e| format!("{}: {e}", options.out_dir.display()))?;
    let md_path = options.out_dir.join("accuracy.md");
    let svg_path = options.out_dir.join("accuracy.svg");
    let mut report = AccuracyReport {
        threads,
        options: options.clone(),
        scenes,
        total_seconds: 0.0,
        files: vec![md_path.display().to_string(), svg_path.display().to_string()],
    };
    write_plot(&report, &svg_path)?;
    report.total_seconds = started.elapsed().as_secs_f64();
    std::fs::write(&md_path, markdown(&report))
        .map_err(|e| format!("{}: {e}", md_path.display()))?;
    eprintln!(
        "accuracy: wrote {} and {} in {:.1} s",
        md_path.display(),
        svg_path.display(),
        report.total_seconds
    );
    Ok(report)
}

/// A configuration's scene, ready to render, or why it does not apply.
struct Prepared {
    configuration: Configuration,
    changed: String,
    scene: Result<Scene, String>,
}

fn run_scene(
    path: &Path,
    options: &AccuracyOptions,
    threads: usize,
) -> Result<SceneResult, String> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("{}: cannot read: {e}", path.display()))?;
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "scene".to_owned());
    let baseline = load(&text, path, options.max_width).map_err(|e| format!("accuracy: {e}"))?;
    let (width, height) = (baseline.camera.width(), baseline.camera.height());
    let effects_summary = decide_effects(&baseline, Some(EffectsMode::Auto)).summary();
    let (auto_picks, auto_reason) = choose_integrator(&baseline, Some(IntegratorChoice::Auto));
    let reference_integrator = reference_integrator(&baseline);
    let features = baseline.features();
    eprintln!(
        "accuracy: {name}: {width}x{height} pixels; {effects_summary}; auto picks {auto_reason}; \
         reference by {}",
        reference_integrator.name()
    );

    // Warm-up (page faults, thread start-up) so the first timed point is not penalised.
    for integrator in [IntegratorChoice::Light, reference_integrator] {
        let seed = options.seed ^ 0xFFFF;
        render_xyz(&baseline, integrator, EffectsMode::Auto, options.start_beams, seed, threads)?;
    }

    let key = cache_key(
        &text,
        reference_integrator,
        options.reference_beams,
        options.seed,
        width,
        height,
    );
    let cache_file = options.cache_dir.join(format!("{name}-{key:016x}.xyz"));
    let (reference, reference_seconds, cached) = match read_reference(&cache_file, width, height) {
        Some(cached) => {
            eprintln!(
                "accuracy: {name}: reference {} beams from the cache ({})",
                cached.paths,
                cache_file.display()
            );
            (cached.image, cached.seconds, true)
        }
        None => {
            eprintln!(
                "accuracy: {name}: rendering the reference, {} paths by {}...",
                options.reference_beams,
                reference_integrator.name()
            );
            // Independent sampling: its batches are independent, so the reference's own noise
            // (see `reference_noise`) is measured by the same estimator's sweep.
            let mut independent =
                load(&text, path, options.max_width).map_err(|e| format!("accuracy: {e}"))?;
            independent.settings.sampler = SamplerKind::Independent;
            let (image, seconds, _) = render_xyz(
                &independent,
                reference_integrator,
                EffectsMode::Auto,
                options.reference_beams,
                options.seed,
                threads,
            )?;
            eprintln!("accuracy: {name}: reference took {seconds:.1} s");
            write_reference(&cache_file, width, height, options.reference_beams, seconds, &image)?;
            (image, seconds, false)
        }
    };
    if reference.iter().all(|p| p.x == 0.0 && p.y == 0.0 && p.z == 0.0) {
        return Err(format!(
            "accuracy: {}: the reference image is black; no light reaches the camera",
            path.display()
        ));
    }

    let mut prepared = Vec::new();
    for &configuration in &options.configurations {
        let (changed, scene) = match load(&text, path, options.max_width)
            .and_then(|mut scene| apply(configuration, &mut scene).map(|changed| (changed, scene)))
        {
            Ok((changed, scene)) => (changed, Ok(scene)),
            Err(reason) => (String::new(), Err(reason)),
        };
        if let Err(reason) = &scene {
            eprintln!("accuracy: {name}: {} not applicable: {reason}", configuration.name());
        }
        prepared.push(Prepared { configuration, changed, scene });
    }

    // Beam counts in the outer loop, configurations inside: slow drifts of a shared machine's
    // speed then spread over every configuration instead of biasing one.
    let mut points: Vec<Vec<AccuracyPoint>> = vec![Vec::new(); prepared.len()];
    for k in 0..options.steps {
        let nominal = options.start_beams << k;
        for (c, p) in prepared.iter().enumerate() {
            let Ok(scene) = &p.scene else { continue };
            // Seeds by the configuration's place in `ALL`, so a subset sweeps with the same seeds.
            let index = Configuration::ALL.iter().position(|&k| k == p.configuration).unwrap_or(c);
            let seed = sweep_seed(options.seed, index as u64, u64::from(k));
            let integrator = p.configuration.integrator();
            let mode = p.configuration.effects_mode();
            let (xyz, seconds, beams) =
                render_xyz(scene, integrator, mode, nominal, seed, threads)?;
            let relative_rmse = relative_rmse(&xyz, &reference)?;
            let mean_ratio = mean_ratio(&xyz, &reference);
            let colour_rmse = colour_relative_rmse(&xyz, &reference)?;
            let relmse = relative_error(ErrorMeasure::RelMse, &xyz, &reference)?;
            eprintln!(
                "accuracy: {name}: {:<22} {beams:>10} paths {seconds:>8.3} s  error {:.3}%  \
                 relmse {:.3}%  mean Y {mean_ratio:.3}x the reference",
                p.configuration.name(),
                relative_rmse * 100.0,
                relmse * 100.0
            );
            points[c].push(AccuracyPoint {
                beams,
                seed,
                seconds,
                relative_rmse,
                mean_ratio,
                colour_rmse,
                relmse,
            });
        }
    }
    let configurations: Vec<ConfigurationResult> = prepared
        .into_iter()
        .zip(points)
        .map(|(p, points)| {
            let log = |f: fn(&AccuracyPoint) -> f64| -> Vec<(f64, f64)> {
                points.iter().map(|q| (f(q).ln(), q.relative_rmse.ln())).collect()
            };
            ConfigurationResult {
                configuration: p.configuration,
                changed: p.changed,
                not_applicable: p.scene.err(),
                known_bias: known_bias(p.configuration, auto_picks, &features).map(str::to_owned),
                slope_vs_time: fit_slope(&log(|q| q.seconds)),
                slope_vs_beams: fit_slope(&log(|q| q.beams as f64)),
                points,
            }
        })
        .collect();
    let estimate_check = if options.estimate_check {
        let mut independent =
            load(&text, path, options.max_width).map_err(|e| format!("accuracy: {e}"))?;
        independent.settings.sampler = SamplerKind::Independent;
        let sweep_reference = reference.clone();
        let sweep_error = report::sweep_reference_error(
            &configurations,
            reference_integrator,
            options.reference_beams,
        )
        .map(|(_, e)| e)
        .unwrap_or_default();
        let mut reference_for = |paths: u64| {
            if paths <= options.reference_beams {
                // The sweep's reference is deep enough; its own error is estimated from the
                // sweep of its estimator.
                return Ok(CheckReference {
                    image: sweep_reference.clone(),
                    own_error: sweep_error,
                    paths: options.reference_beams,
                });
            }
            deep_reference(
                &independent,
                &text,
                &name,
                reference_integrator,
                paths,
                options,
                threads,
            )
        };
        let check = estimate_check(
            &baseline,
            auto_picks,
            options.estimate_target,
            &mut reference_for,
            threads,
            options.seed,
        )?;
        eprintln!(
            "accuracy: {name}: estimate check: {} to {}% in {:.2} s (predicted {:?} s), estimated \
             error {:?}, true error {:.4} against {} reference paths (its own {:?})",
            auto_picks.name(),
            options.estimate_target * 100.0,
            check.measured_seconds,
            check.prediction().and_then(|p| p.predicted_seconds),
            check.estimated_error,
            check.true_error,
            check.reference_paths,
            check.reference_error.relmse,
        );
        Some(check)
    } else {
        None
    };
    Ok(SceneResult {
        scene: path.display().to_string(),
        name,
        width,
        height,
        effects_summary,
        auto_picks,
        auto_reason,
        reference: ReferenceInfo {
            integrator: reference_integrator,
            beams: options.reference_beams,
            seed: options.seed,
            seconds: reference_seconds,
            cached,
            file: cache_file.display().to_string(),
        },
        configurations,
        estimate_check,
    })
}

/// The scene of `text` (the file `path`) as the renderer's typed [`Scene`], its camera scaled
/// down to at most `max_width` pixels wide.
fn load(text: &str, path: &Path, max_width: Option<u32>) -> Result<Scene, String> {
    let mut scene = Scene::from_json(text, path).map_err(|e| e.to_string())?;
    if let Some(max_width) = max_width {
        limit_resolution(&mut scene, max_width)?;
    }
    Ok(scene)
}

/// Why `configuration` converges to another image than the reference on a scene with
/// `features`, when the features alone say so (`auto_picks`: what `auto` renders with): a
/// piecewise-constant SPD is another spectrum; the light tracer shows mirrors and glass that the
/// camera sees black (flagged wherever the scene has specular surfaces, seen or not); the path
/// tracer misses thin lasers, beam-only lights, spectral lines and the caustics of point, spot and
/// parallel lights. `None` when no bias is known (the report also flags a mean brightness off by
/// more than 2%, and errors that level off).
pub fn known_bias(
    configuration: Configuration,
    auto_picks: IntegratorChoice,
    features: &SceneFeatures,
) -> Option<&'static str> {
    if configuration == Configuration::PiecewiseConstantSpd {
        return Some("another spectrum (piecewise constant)");
    }
    let integrator = match configuration.integrator() {
        IntegratorChoice::Auto => auto_picks,
        other => other,
    };
    match integrator {
        IntegratorChoice::Light if features.specular => {
            Some("the light tracer shows mirrors and glass seen by the camera black")
        }
        IntegratorChoice::Path
            if features.beam_only_lights + features.unreachable_lights > 0
                || features.line_spectra
                || (features.delta_position_lights + features.delta_direction_lights > 0
                    && features.specular) =>
        {
            Some("the path tracer misses thin lasers, spectral lines or caustics of delta lights")
        }
        _ => None,
    }
}

/// The estimator of a scene's reference image: one that is unbiased on it. The path tracer where
/// `auto` picks it (every light can be reached from the camera), BDPT everywhere else (the light
/// tracer shows mirrors and glass black; the path tracer misses skies, lasers, spectral lines and
/// the caustics of point lights).
pub fn reference_integrator(scene: &Scene) -> IntegratorChoice {
    match choose_integrator(scene, Some(IntegratorChoice::Auto)).0 {
        IntegratorChoice::Path => IntegratorChoice::Path,
        _ => IntegratorChoice::Bdpt,
    }
}

/// Relative RMSE of an XYZ image against a reference:
/// `sqrt(sum |xyz - ref|^2 / sum |ref|^2)` over all pixels and the three channels.
///
/// # Errors
/// A message when the sizes differ or the reference is black.
pub fn relative_rmse(image: &[Xyz], reference: &[Xyz]) -> Result<f64, String> {
    if image.len() != reference.len() {
        return Err(format!(
            "image of {} pixels against a reference of {}",
            image.len(),
            reference.len()
        ));
    }
    let (mut diff, mut norm) = (0.0, 0.0);
    for (a, r) in image.iter().zip(reference) {
        diff += (a.x - r.x).powi(2) + (a.y - r.y).powi(2) + (a.z - r.z).powi(2);
        norm += r.x * r.x + r.y * r.y + r.z * r.z;
    }
    if !(norm > 0.0) {
        return Err("the reference image is black".to_owned());
    }
    Ok((diff / norm).sqrt())
}

/// The colour part of [`relative_rmse`]: each pixel's XYZ error minus its component along
/// the reference pixel's XYZ direction (which only changes brightness), so
/// `sqrt(sum |d - (d . r^) r^|^2 / sum |ref|^2)` with `d = xyz - ref` and `r^ = ref / |ref|`.
/// Where the reference pixel is black it has no colour to keep and the whole error counts. The
/// squares of the two parts add up to the square of [`relative_rmse`].
///
/// # Errors
/// As [`relative_rmse`].
pub fn colour_relative_rmse(image: &[Xyz], reference: &[Xyz]) -> Result<f64, String> {
    relative_rmse(image, reference)?;
    let (mut diff, mut norm) = (0.0, 0.0);
    for (a, r) in image.iter().zip(reference) {
        let d = [a.x - r.x, a.y - r.y, a.z - r.z];
        let rr = r.x * r.x + r.y * r.y + r.z * r.z;
        let along =
            if rr > 0.0 { (d[0] * r.x + d[1] * r.y + d[2] * r.z).powi(2) / rr } else { 0.0 };
        diff += (d[0] * d[0] + d[1] * d[1] + d[2] * d[2] - along).max(0.0);
        norm += rr;
    }
    Ok((diff / norm).sqrt())
}

/// Sum of Y over `image` over the sum over `reference` (NaN for a black reference).
fn mean_ratio(image: &[Xyz], reference: &[Xyz]) -> f64 {
    let sum = |img: &[Xyz]| img.iter().map(|p| p.y).sum::<f64>();
    sum(image) / sum(reference)
}

/// Least-squares slope of `y` against `x` (`None` for fewer than two distinct `x` or
/// non-finite values): the renderer's fit, also used by `spectrace estimate`.
pub(super) fn fit_slope(points: &[(f64, f64)]) -> Option<f64> {
    spectrace_renderer::pilot::fit_line(points).map(|f| f.slope)
}

/// The seed of sweep point `k` of configuration `c`: derived from the reference seed, never
/// equal to it.
fn sweep_seed(seed: u64, c: u64, k: u64) -> u64 {
    let s = mix64(seed ^ mix64(GOLDEN_GAMMA ^ (c << 32) ^ k));
    if s == seed { s ^ 1 } else { s }
}

#[cfg(test)]
mod tests;
