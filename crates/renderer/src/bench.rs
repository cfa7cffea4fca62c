//! Measurements: the effects benchmark and every estimator with the same paths (`spectrace
//! bench`; the accuracy report in `spectrace-lab` uses [`render_xyz`] too).

use std::time::Instant;

use serde::{Deserialize, Serialize};
use spectrace_lights::LightSource;
use spectrace_tracer::{Effects, EffectsMode, IntegratorChoice, render};

use crate::integrators::{ESTIMATORS, is_camera_integrator};
use crate::{
    RenderError, RenderOptions, Scene, choose_integrator, decide_effects, plan_with,
    with_integrator,
};

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
/// As [`render_scene`](crate::render_scene).
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
        let out = with_integrator(scene, IntegratorChoice::Light, effects, |tracer| {
            render(tracer, &plan, &|_| {})
        })
        .map_err(|e| RenderError::Options(e.to_string()))?;
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
    let (choice, _) = choose_integrator(scene, Some(integrator));
    // Whole passes for a camera integrator: every pixel gets the same samples.
    let pixels = (u64::from(scene.camera.width()) * u64::from(scene.camera.height())).max(1);
    let whole = if is_camera_integrator(choice) { paths.div_ceil(pixels) * pixels } else { paths };
    let options = RenderOptions {
        beams: Some(whole),
        seed: Some(seed),
        threads: Some(threads),
        effects: Some(mode),
        ..RenderOptions::default()
    };
    let mut plan = plan_with(scene, &options, choice).map_err(|e| e.to_string())?;
    if !is_camera_integrator(choice) {
        // At least ~16 chunks per render, so small sweep points use every thread too; the chunk
        // size depends on the beams alone, so a cached reference stays valid whatever the thread
        // count. (A camera integrator's chunk is a pass of one sample per pixel.)
        plan.chunk_beams = (paths / 16).clamp(1, plan.chunk_beams.max(1024)).min(plan.chunk_beams);
    }
    let effects = decide_effects(scene, Some(mode));
    scene.lights.reset_count();
    let started = Instant::now();
    // The image by the estimator's own normalisation (its documented film units; the same as
    // the renderer's `normalisation`).
    let (output, image) = with_integrator(scene, choice, effects, |tracer| {
        render(tracer, &plan, &|_| {}).map(|out| {
            let image = tracer.image(&out);
            (out, image)
        })
    })
    .map_err(|e| e.to_string())?;
    let seconds = started.elapsed().as_secs_f64();
    scene.lights.reset_count();
    Ok((image, seconds, output.beams))
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
    for integrator in ESTIMATORS.into_iter().chain([IntegratorChoice::Auto]) {
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
