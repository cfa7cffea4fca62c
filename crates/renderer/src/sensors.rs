//! Illuminance sensors in a render: where their values come from, how accurate they are, and
//! the files and sidecar figures they become.
//!
//! When the light tracer renders the image, the image's own beams fill the sensors at no extra
//! tracing. When a camera integrator (path tracer, BDPT) renders it, a *sensor pass* follows:
//! by default `spectrace_tracer::SensorPathTracer`, the path tracer from points sampled on the
//! sensors (`settings.sensor_spp` per cell), or with `settings.sensor_integrator: "light"` the
//! light tracer again with `settings.sensor_beams` beams, connected to no camera. Either way the
//! sums become irradiance and illuminance per cell, with the relative standard error of the
//! sensor's average from the spread of the samples, and a prediction of the time a 1% average
//! would take.

use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::{Deserialize, Serialize};
use spectrace_lights::LightSource;
use spectrace_tracer::{
    Effects, Film, Integrator, IntegratorChoice, LightTracer, LightTracerScene, PathTracer,
    RenderOutput, RenderPlan, SensorPathTracer, SensorSet, SensorSums, render as render_plan,
};

use crate::integrators::sampler_of;
use crate::sensor_output::{SensorGrid, write_sensor_files};
use crate::{DEFAULT_SENSOR_SPP, RenderError, Scene, SensorIntegrator, tracer_scene};

/// One sensor's figures in the sidecar.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SensorReport {
    /// The sensor's name.
    pub name: String,
    /// `[nu, nv]`.
    pub cells: [u32; 2],
    /// Average illuminance over the cells (lux).
    pub average_lux: f64,
    /// Smallest cell's illuminance (lux).
    pub minimum_lux: f64,
    /// Largest cell's illuminance (lux).
    pub maximum_lux: f64,
    /// Uniformity `U0 = minimum / average` (EN 12464-1); 0 when the average is 0.
    pub uniformity: f64,
    /// Average irradiance (W/m^2).
    pub average_w_m2: f64,
    /// Average melanopic equivalent daylight illuminance (lux, CIE S 026).
    #[serde(default)]
    pub average_melanopic_edi_lux: f64,
    /// Melanopic daylight efficacy ratio: average m-EDI over average illuminance (1 for D65);
    /// 0 when no light arrived.
    #[serde(default)]
    pub melanopic_der: f64,
    /// Estimated relative standard error of `average_lux` (one sigma), from the spread of the
    /// beams' contributions; `null` when no light arrived.
    pub average_relative_error: Option<f64>,
    /// Median over the lit cells of each cell's estimated relative standard error.
    pub median_cell_relative_error: Option<f64>,
    /// Beams that filled the sensor.
    pub beams: u64,
    /// How: `"image beams (light tracer)"` or `"sensor pass (light tracer)"`.
    pub filled_by: String,
    /// Seconds of tracing that filled it (the whole render's for image beams).
    pub seconds: f64,
    /// Predicted tracing time (s) for a 1% `average_relative_error` at this speed (error falls
    /// as one over the square root of the beams).
    pub predicted_seconds_for_1_percent: Option<f64>,
    /// The largest relative standard error of a cell at or above `settings.sensor_floor_lux`
    /// (`null` when no cell is that bright).
    #[serde(default)]
    pub worst_cell_relative_error: Option<f64>,
    /// `settings.sensor_target_error`, when the sensor pass ran to it.
    #[serde(default)]
    pub target_error: Option<f64>,
    /// Whether every cell at or above the floor reached it (`null` without a target).
    #[serde(default)]
    pub target_reached: Option<bool>,
    /// Files written.
    pub files: Vec<String>,
}

/// The output files every sensor of `scene` will write into `dir`.
pub fn planned_sensor_outputs(scene: &Scene, dir: &Path) -> Vec<PathBuf> {
    scene
        .sensors
        .sensors()
        .iter()
        .flat_map(|s| ["csv", "exr", "png"].map(|e| dir.join(format!("{}.{e}", s.name()))))
        .collect()
}

/// Checks that no sensor's files would take the image's name.
///
/// # Errors
/// [`RenderError::Options`] naming the sensor.
pub fn check_sensor_names(scene: &Scene, image_name: &str) -> Result<(), RenderError> {
    for (i, s) in scene.sensors.sensors().iter().enumerate() {
        if s.name() == image_name {
            return Err(RenderError::Options(format!(
                "sensors[{i}].name \"{}\": the image's files have that name; give the sensor \
                 another",
                s.name()
            )));
        }
    }
    Ok(())
}

/// The scene of a light-tracer sensor pass: connected to no camera, drawing from the sampler the
/// light tracer's image would (`sampler_of`, no target error: Sobol points where beams stop
/// after a diffuse hit), so that a sensor pass and a light-tracer image of as many beams fill
/// a sensor alike.
fn sensor_tracer_scene<'s>(scene: &'s Scene, effects: &Effects) -> LightTracerScene<'s> {
    let sampler = sampler_of(scene.settings.sampler, IntegratorChoice::Light, false, effects);
    tracer_scene(scene).sensors_only().with_sampler(sampler)
}

/// Runs a sensor pass: the light tracer, connected to no camera, filling `scene`'s sensors with
/// `plan`'s beams. Returns the film (its sensor cells) and the seconds it took.
///
/// # Errors
/// [`RenderError::Options`] if the film cannot be made.
pub fn sensor_pass(
    scene: &Scene,
    plan: &RenderPlan,
    effects: Effects,
) -> Result<(Film, u64, f64), RenderError> {
    let started = Instant::now();
    let traced = sensor_tracer_scene(scene, &effects);
    let tracer = LightTracer::new(&traced, scene.tracer_settings(), effects);
    let plan = RenderPlan { error_estimate: false, target_error: None, ..*plan };
    let output =
        render_plan(&tracer, &plan, &|_| {}).map_err(|e| RenderError::Options(e.to_string()))?;
    scene.lights.reset_count();
    let seconds = started.elapsed().as_secs_f64();
    let beams = output.beams;
    Ok((output.film, beams, seconds))
}

/// Runs a sensor pass with the path tracer sampling points on the sensors: `passes` samples of
/// every cell. Returns the film (its sensor cells), the passes done (the `N` of
/// [`sensor_grid`]) and the seconds it took.
///
/// # Errors
/// [`RenderError::Options`] if the film cannot be made.
pub fn sensor_pass_path(
    scene: &Scene,
    passes: u64,
    threads: usize,
    effects: Effects,
) -> Result<(Film, u64, f64), RenderError> {
    sensor_pass_path_seeded(scene, passes, threads, effects, scene.settings.seed)
}

/// [`sensor_pass_path`] with its own seed (the rounds of a pass to a target).
fn sensor_pass_path_seeded(
    scene: &Scene,
    passes: u64,
    threads: usize,
    effects: Effects,
    seed: u64,
) -> Result<(Film, u64, f64), RenderError> {
    let cells = u64::from(scene.sensors.total_cells()).max(1);
    let plan = RenderPlan { seed, ..per_item_plan(passes, cells, scene, threads) };
    let started = Instant::now();
    let output = path_pass_output(scene, &plan, effects)?;
    Ok((output.film, output.beams / cells, started.elapsed().as_secs_f64()))
}

/// The plan of a pass of `passes` samples of each of `items` receivers (sensor cells, or
/// observers' quantities): a chunk is one sample of every item; the scene's seed, no shard.
pub(crate) fn per_item_plan(passes: u64, items: u64, scene: &Scene, threads: usize) -> RenderPlan {
    RenderPlan {
        beams: passes.saturating_mul(items),
        chunk_beams: items,
        seed: scene.settings.seed,
        threads,
        shard: None,
        time_budget: None,
        error_estimate: false,
        target_error: None,
        error_measure: Default::default(),
    }
}

/// The path tracer's sensor pass on `plan` (which may name a shard).
fn path_pass_output(
    scene: &Scene,
    plan: &RenderPlan,
    effects: Effects,
) -> Result<RenderOutput, RenderError> {
    let traced = tracer_scene(scene);
    let tracer = SensorPathTracer::new(
        PathTracer::new(&traced, scene.path_settings(), effects),
        &scene.sensors,
    );
    render_plan(&tracer, plan, &|_| {}).map_err(|e| RenderError::Options(e.to_string()))
}

/// A pass over receivers, or a shard's share of one: its whole plan (without the shard), what
/// was rendered, and the work items per independent sample (the receivers for a pass sampling
/// each of them once per chunk, 1 for light paths).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PassShare {
    /// The pass's plan, without its shard.
    pub plan: RenderPlan,
    /// What was rendered of it.
    pub output: RenderOutput,
    /// Work items per independent sample: `N = output.beams / items_per_sample`.
    pub items_per_sample: u64,
}

/// The fixed sensor pass after a camera integrator's image (`sensor_spp` samples per cell, or
/// `sensor_beams` light paths), on `shard`'s chunks of it (all of them for `None`), with how it
/// fills the sensors.
///
/// # Errors
/// [`RenderError::Options`] if the film cannot be made.
pub(crate) fn fixed_sensor_pass(
    scene: &Scene,
    threads: usize,
    effects: Effects,
    shard: Option<(u64, u64)>,
) -> Result<(PassShare, &'static str), RenderError> {
    let started = Instant::now();
    let (plan, mut output, items_per_sample, filled_by) =
        if sensor_integrator(scene) == SensorIntegrator::Light {
            let plan = sensor_plan(scene, threads);
            let traced = sensor_tracer_scene(scene, &effects);
            let tracer = LightTracer::new(&traced, scene.tracer_settings(), effects);
            let output = render_plan(&tracer, &RenderPlan { shard, ..plan }, &|_| {})
                .map_err(|e| RenderError::Options(e.to_string()))?;
            scene.lights.reset_count();
            (plan, output, 1, FILLED_BY_LIGHT_PASS)
        } else {
            let passes = scene.settings.sensor_spp.unwrap_or(DEFAULT_SENSOR_SPP);
            let cells = u64::from(scene.sensors.total_cells()).max(1);
            let plan = per_item_plan(passes, cells, scene, threads);
            let output = path_pass_output(scene, &RenderPlan { shard, ..plan }, effects)?;
            (plan, output, cells, FILLED_BY_PATH_PASS)
        };
    output.seconds = started.elapsed().as_secs_f64();
    let plan = RenderPlan { threads: 0, ..plan };
    Ok((PassShare { plan, output, items_per_sample }, filled_by))
}

/// `filled_by` of sensors filled by the light tracer's image beams.
pub const FILLED_BY_IMAGE: &str = "image beams (light tracer)";
/// `filled_by` of sensors filled by a light-tracer sensor pass.
pub const FILLED_BY_LIGHT_PASS: &str = "sensor pass (light tracer)";
/// `filled_by` of sensors filled by the path tracer from points sampled on them.
pub const FILLED_BY_PATH_PASS: &str = "points sampled on the sensor (path tracer)";

/// The plan of a sensor pass: `settings.sensor_beams` beams (default `settings.beams`), the
/// scene's seed, chunking and threads, no time budget.
pub fn sensor_plan(scene: &Scene, threads: usize) -> RenderPlan {
    let s = &scene.settings;
    RenderPlan {
        beams: s.sensor_beams.unwrap_or(s.beams),
        chunk_beams: s.chunk_beams,
        seed: s.seed,
        threads,
        shard: None,
        time_budget: None,
        error_estimate: false,
        target_error: None,
        error_measure: Default::default(),
    }
}

/// A sensor's values and how well they are known.
#[derive(Debug, Clone, PartialEq)]
pub struct SensorEstimate {
    /// Irradiance and illuminance per cell.
    pub grid: SensorGrid,
    /// One-sigma standard error of each cell's illuminance (lux), same indexing.
    pub illuminance_errors: Vec<f64>,
    /// Relative standard error of the average illuminance; `None` when no light arrived.
    pub average_relative_error: Option<f64>,
    /// Median over the lit cells of each cell's relative standard error.
    pub median_cell_relative_error: Option<f64>,
}

/// Sensor `index`'s grid and errors from the film's sums, given `n` independent samples (light
/// paths, or passes over the cells) and the light power: each cell's `radiant x P / n / area`
/// and `luminous x P / n / area`, and the variance of a sum of `n` independent samples,
/// `sum x^2 - (sum x)^2 / n`.
pub fn sensor_grid(
    set: &SensorSet,
    index: usize,
    sums: &[SensorSums],
    light_power: f64,
    n: u64,
) -> SensorEstimate {
    let sensor = &set.sensors()[index];
    let offset = set.offset(index) as usize;
    let cells = &sums[offset..offset + sensor.cell_count() as usize];
    let scale = if n > 0 { light_power / n as f64 / sensor.cell_area() } else { 0.0 };
    let variance = |sum: f64, squares: f64| (squares - sum * sum / n.max(1) as f64).max(0.0);
    let total: f64 = cells.iter().map(|c| c[1]).sum();
    let total_variance: f64 = cells.iter().map(|c| variance(c[1], c[2])).sum();
    let mut relative: Vec<f64> =
        cells.iter().filter(|c| c[1] > 0.0).map(|c| variance(c[1], c[2]).sqrt() / c[1]).collect();
    relative.sort_by(f64::total_cmp);
    SensorEstimate {
        grid: SensorGrid {
            name: sensor.name().to_owned(),
            corner: sensor.corner(),
            edge_u: sensor.edge_u(),
            edge_v: sensor.edge_v(),
            cells: sensor.cells(),
            irradiance: cells.iter().map(|c| c[0] * scale).collect(),
            illuminance: cells.iter().map(|c| c[1] * scale).collect(),
            melanopic_edi: cells.iter().map(|c| c[3] * scale).collect(),
        },
        illuminance_errors: cells.iter().map(|c| variance(c[1], c[2]).sqrt() * scale).collect(),
        average_relative_error: (total > 0.0).then(|| total_variance.sqrt() / total),
        median_cell_relative_error: relative.get(relative.len() / 2).copied(),
    }
}

/// How a sensor was filled, for [`write_sensors`].
#[derive(Debug, Clone, Copy)]
pub struct SensorSource<'a> {
    /// The film whose sensor cells hold the sums.
    pub film: &'a Film,
    /// Beams traced into it.
    pub beams: u64,
    /// Seconds of tracing.
    pub seconds: f64,
    /// `"image beams (light tracer)"` or `"sensor pass (light tracer)"`.
    pub filled_by: &'a str,
    /// The sensor target the pass ran to, if any.
    pub target: Option<f64>,
}

/// The largest relative standard error of a cell of `estimate` at or above `floor_lux` (`None`
/// when none is).
pub fn worst_cell_error(estimate: &SensorEstimate, floor_lux: f64) -> Option<f64> {
    let lit = estimate.grid.illuminance.iter().zip(&estimate.illuminance_errors);
    lit.filter(|(lux, _)| **lux >= floor_lux && **lux > 0.0)
        .map(|(lux, se)| se / lux)
        .max_by(f64::total_cmp)
}

/// Most work items a sensor pass to a target does: 2^20 samples per cell (path tracer) or
/// 2^40 beams (light tracer); a pass that stops there reports its target not reached.
const SENSOR_TARGET_CAP: [u64; 2] = [1 << 20, 1 << 40];

/// The sensor pass of `kind` run until every cell at or above `settings.sensor_floor_lux` has a
/// relative standard error of at most `target`: in rounds, each on its own seed (so the rounds'
/// samples are independent and their films add), the first of 16 samples per cell (or 16
/// chunks of beams), each next one sized by the worst cell's error (its square falls as one
/// over the work), at most eight times the work so far. Returns the summed film, the work items
/// (the `N` of [`sensor_grid`]) and the seconds.
///
/// # Errors
/// As [`sensor_pass`].
fn sensor_pass_to_target(
    scene: &Scene,
    light: bool,
    target: f64,
    threads: usize,
    effects: Effects,
) -> Result<(Film, u64, f64), RenderError> {
    let started = Instant::now();
    let first = if light { 16 * scene.settings.chunk_beams.max(1) } else { 16 };
    let cap = SENSOR_TARGET_CAP[usize::from(light)];
    let (mut film, mut done, mut round) = (None::<Film>, 0u64, 0u64);
    let mut next = first;
    loop {
        let seed = scene.settings.seed ^ round.wrapping_mul(0x9E37_79B9_7F4A_7C15);
        let (part, items, _) = if light {
            let plan = RenderPlan { beams: next, seed, ..sensor_plan(scene, threads) };
            sensor_pass(scene, &plan, effects)?
        } else {
            sensor_pass_path_seeded(scene, next, threads, effects, seed)?
        };
        match film.as_mut() {
            None => film = Some(part),
            Some(f) => f.merge(&part).map_err(|e| RenderError::Options(e.to_string()))?,
        }
        done += items;
        round += 1;
        let sums = film.as_ref().map(|f| f.sensor_sums(1.0)).unwrap_or_default();
        let worst = (0..scene.sensors.sensors().len())
            .filter_map(|i| {
                let estimate = sensor_grid(&scene.sensors, i, &sums, scene.lights.power(), done);
                worst_cell_error(&estimate, scene.settings.sensor_floor_lux)
            })
            .max_by(f64::total_cmp);
        let Some(worst) = worst.filter(|&w| w > target && done < cap) else { break };
        // Error squared falls as one over the work: the total the target needs, with 10% to
        // spare, but at most eight times the work so far (a noisy first estimate).
        let needed = (done as f64 * (worst / target).powi(2) * 1.1).min(done as f64 * 9.0);
        next = (needed as u64).saturating_sub(done).clamp(first, cap.saturating_sub(done).max(1));
    }
    let film =
        film.ok_or_else(|| RenderError::Options("the sensor pass rendered nothing".to_owned()))?;
    Ok((film, done, started.elapsed().as_secs_f64()))
}

/// Writes every sensor's files into `dir` and returns their sidecar figures.
///
/// # Errors
/// [`RenderError::File`] when a file cannot be written (or would replace an input).
pub fn write_sensors(
    scene: &Scene,
    dir: &Path,
    source: SensorSource<'_>,
) -> Result<Vec<SensorReport>, RenderError> {
    let lit = LitSensors {
        sensors: &scene.sensors,
        light_power: scene.lights.power(),
        floor_lux: scene.settings.sensor_floor_lux,
        inputs: &scene.inputs,
    };
    write_lit_sensors(&lit, dir, source)
}

/// What writing sensors needs of a scene (a merge has the parts, not the scene).
#[derive(Debug, Clone, Copy)]
pub(crate) struct LitSensors<'a> {
    /// The sensors.
    pub sensors: &'a SensorSet,
    /// The lights' total power (W).
    pub light_power: f64,
    /// `settings.sensor_floor_lux`.
    pub floor_lux: f64,
    /// Files no output may replace.
    pub inputs: &'a [PathBuf],
}

/// [`write_sensors`] from what it needs.
pub(crate) fn write_lit_sensors(
    lit: &LitSensors<'_>,
    dir: &Path,
    source: SensorSource<'_>,
) -> Result<Vec<SensorReport>, RenderError> {
    let sums = source.film.sensor_sums(1.0);
    let mut reports = Vec::new();
    for index in 0..lit.sensors.sensors().len() {
        let estimate = sensor_grid(lit.sensors, index, &sums, lit.light_power, source.beams);
        let worst = worst_cell_error(&estimate, lit.floor_lux);
        let SensorEstimate {
            grid,
            average_relative_error: average_error,
            median_cell_relative_error: median,
            ..
        } = estimate;
        let files = write_sensor_files(dir, &grid, lit.inputs).map_err(|message| {
            RenderError::File { path: dir.join(format!("{}.*", grid.name)), message }
        })?;
        let summary = grid.summary();
        let predicted = average_error.map(|e| source.seconds * (e / 0.01).powi(2));
        reports.push(SensorReport {
            name: grid.name.clone(),
            cells: grid.cells,
            average_lux: summary.average_lux,
            minimum_lux: summary.minimum_lux,
            maximum_lux: summary.maximum_lux,
            uniformity: summary.uniformity,
            average_w_m2: summary.average_w_m2,
            average_melanopic_edi_lux: summary.average_melanopic_edi_lux,
            melanopic_der: summary.melanopic_der,
            average_relative_error: average_error,
            median_cell_relative_error: median,
            beams: source.beams,
            filled_by: source.filled_by.to_owned(),
            seconds: source.seconds,
            predicted_seconds_for_1_percent: predicted,
            worst_cell_relative_error: worst,
            target_error: source.target,
            target_reached: source.target.map(|t| worst.is_none_or(|w| w <= t)),
            files: files.iter().map(|p| p.display().to_string()).collect(),
        });
    }
    Ok(reports)
}

/// The sensors' figures in words, one line each, for the terminal.
pub fn sensor_summary(r: &SensorReport) -> String {
    let error = r
        .average_relative_error
        .map_or("no light arrived".to_owned(), |e| format!("average +/- {:.2}%", e * 100.0));
    format!(
        "sensor {}: average {:.1} lx, min {:.1} lx, max {:.1} lx, U0 {:.2}, melanopic EDI {:.1} lx \
         (DER {:.3}) ({error}, {} by {} beams)",
        r.name,
        r.average_lux,
        r.minimum_lux,
        r.maximum_lux,
        r.uniformity,
        r.average_melanopic_edi_lux,
        r.melanopic_der,
        r.filled_by,
        r.beams
    )
}

/// How a camera integrator's render fills the sensors: the setting, with `auto` resolved (the
/// path tracer when every light can be sampled from a point, else light paths).
pub fn sensor_integrator(scene: &Scene) -> SensorIntegrator {
    match scene.settings.sensor_integrator {
        SensorIntegrator::Auto if scene.lights_sampled_from_points() => SensorIntegrator::Path,
        SensorIntegrator::Auto => SensorIntegrator::Light,
        other => other,
    }
}

/// Fills and writes the sensors after an unsharded render by `tracer`: with the image's own
/// beams when the estimator filled them (the light tracer), else with a sensor pass (see
/// [`sensor_integrator`]) on `plan`'s threads. Empty for a scene without sensors.
///
/// # Errors
/// [`RenderError`] if a sensor pass's film cannot be made or a file cannot be written.
pub(crate) fn render_sensors(
    scene: &Scene,
    dir: &Path,
    tracer: &dyn Integrator,
    output: &RenderOutput,
    plan: &RenderPlan,
    effects: Effects,
) -> Result<Vec<SensorReport>, RenderError> {
    if scene.sensors.is_empty() {
        return Ok(Vec::new());
    }
    if tracer.sensor_cells() > 0 {
        let source = SensorSource {
            film: &output.film,
            beams: output.beams,
            seconds: output.seconds,
            filled_by: FILLED_BY_IMAGE,
            target: None,
        };
        return write_sensors(scene, dir, source);
    }
    let light = sensor_integrator(scene) == SensorIntegrator::Light;
    if let Some(t) = scene.settings.sensor_target_error {
        let (film, beams, seconds) = sensor_pass_to_target(scene, light, t, plan.threads, effects)?;
        let filled_by = if light { FILLED_BY_LIGHT_PASS } else { FILLED_BY_PATH_PASS };
        let source = SensorSource { film: &film, beams, seconds, filled_by, target: Some(t) };
        return write_sensors(scene, dir, source);
    }
    let (pass, filled_by) = fixed_sensor_pass(scene, plan.threads, effects, None)?;
    let source = SensorSource {
        film: &pass.output.film,
        beams: pass.output.beams / pass.items_per_sample.max(1),
        seconds: pass.output.seconds,
        filled_by,
        target: None,
    };
    write_sensors(scene, dir, source)
}
