//! Does the renderer know its own error? For each scene: the pilot's prediction of the time to
//! the target ([`ESTIMATE_TARGET`] by default, in the renderer's default measure `relmse`) for
//! every estimator, then a render to that target with the estimator `auto` picks, whose final
//! estimate is compared with its true error against a reference deep enough for it
//! ([`CHECK_REFERENCE_FACTOR`]) and whose time is compared with the prediction.

use serde::{Deserialize, Serialize};
use spectrace_renderer::pilot::{EstimateOptions, EstimateReport, Prediction, estimate};
use spectrace_renderer::{RenderOptions, Scene, render_in_memory};
use spectrace_spectrum::Xyz;
use spectrace_tracer::{ByMeasure, ErrorMeasure, IntegratorChoice, relative_error};

/// The target of the check: 10% `relmse`, the issue's.
pub const ESTIMATE_TARGET: f64 = 0.1;

/// The measure of the check: the renderer's default.
pub const ESTIMATE_MEASURE: ErrorMeasure = ErrorMeasure::RelMse;

/// Longest the check's render to the target may run (s): it stops there, target or not.
pub const ESTIMATE_CAP_SECONDS: f64 = 120.0;

/// The check's reference has at least this many times the paths of the check's render (the
/// sweep's reference where that is enough, else a deeper one, cached alike): its own noise is
/// then about half the render's or less, and is taken out in quadrature with the reference's own
/// estimate of it.
pub const CHECK_REFERENCE_FACTOR: u64 = 4;

/// A reference image with its own estimated error in every measure and its paths.
#[derive(Debug, Clone, PartialEq)]
pub struct CheckReference {
    /// The image.
    pub image: Vec<Xyz>,
    /// Its own estimated error in every measure (`None` where it has no estimate).
    pub own_error: ByMeasure,
    /// Its paths.
    pub paths: u64,
}

/// The estimate against the truth for one scene.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EstimateCheck {
    /// The estimator of the render (`auto`'s pick).
    pub integrator: IntegratorChoice,
    /// The target.
    pub target: f64,
    /// The measure of the target, the estimate and the truth below (serde default: `energy`,
    /// the measure of reports before `relmse` became the default).
    #[serde(default = "energy")]
    pub measure: ErrorMeasure,
    /// The pilot's predictions for light, path and bdpt, and its recommendation.
    pub pilot: EstimateReport,
    /// Wall time of the render to the target (s).
    pub measured_seconds: f64,
    /// Whether the render reached the target (on a trusted estimate) before
    /// [`ESTIMATE_CAP_SECONDS`].
    pub reached: bool,
    /// The render's own estimate of its relative error at the end, in `measure`.
    pub estimated_error: Option<f64>,
    /// Its relative error against the reference in `measure` (which carries the reference's
    /// own noise: see `reference_error`).
    pub true_error: f64,
    /// Chunks of the render.
    pub batches: u64,
    /// Paths (work items) of the render.
    #[serde(default)]
    pub paths: u64,
    /// The render's own final estimate in every measure.
    #[serde(default)]
    pub estimated_by_measure: ByMeasure,
    /// Its error against the reference in every measure (with the reference's own noise).
    #[serde(default)]
    pub true_by_measure: ByMeasure,
    /// Paths of the reference the truth is measured against (0: the sweep's).
    #[serde(default)]
    pub reference_paths: u64,
    /// The reference's own estimated error in every measure, taken out of the truth in
    /// quadrature ([`EstimateCheck::corrected_truth`]).
    #[serde(default)]
    pub reference_error: ByMeasure,
}

fn energy() -> ErrorMeasure {
    ErrorMeasure::Energy
}

impl EstimateCheck {
    /// The pilot's prediction for the estimator of the render.
    pub fn prediction(&self) -> Option<&Prediction> {
        self.pilot.predictions.iter().find(|p| p.integrator == self.integrator.name())
    }

    /// The render's true error in `measure` with the reference's own estimated error taken
    /// out (independent errors add in quadrature): `sqrt(true² - reference²)`; `None` when the
    /// reference's error is as large, or no truth was measured.
    pub fn corrected_truth(&self, measure: ErrorMeasure) -> Option<f64> {
        let t = self.true_by_measure.get(measure)?;
        let r = self.reference_error.get(measure).unwrap_or(0.0);
        let d = t * t - r * r;
        (d > 0.0).then(|| d.sqrt())
    }
}

/// Runs the check on `scene` with the estimator `auto` picks to `target`; `reference(paths)`
/// gives a reference of at least `paths` paths.
///
/// # Errors
/// A message when a render fails.
pub fn estimate_check(
    scene: &Scene,
    auto: IntegratorChoice,
    target: f64,
    reference: &mut dyn FnMut(u64) -> Result<CheckReference, String>,
    threads: usize,
    seed: u64,
) -> Result<EstimateCheck, String> {
    let pilot = estimate(
        scene,
        &EstimateOptions {
            target_error: target,
            threads,
            seed: seed ^ 0x9170_7000,
            error_measure: Some(ESTIMATE_MEASURE),
            ..EstimateOptions::default()
        },
    )
    .map_err(|e| e.to_string())?;
    let render = render_in_memory(
        scene,
        &RenderOptions {
            target_error: Some(target),
            time: Some(ESTIMATE_CAP_SECONDS),
            threads: Some(threads),
            seed: Some(seed ^ 0xE571_0000),
            integrator: Some(auto),
            error_measure: Some(ESTIMATE_MEASURE),
            ..RenderOptions::default()
        },
    )
    .map_err(|e| e.to_string())?;
    let paths = render.output.beams;
    let reference = reference(paths.saturating_mul(CHECK_REFERENCE_FACTOR))?;
    let estimate = render.output.estimate(ESTIMATE_MEASURE);
    let estimated_error = estimate.and_then(|e| e.relative_error);
    let truth = |m| relative_error(m, &render.image, &reference.image).ok();
    let [relmse, energy, mean] = ErrorMeasure::ALL.map(truth);
    let true_by_measure = ByMeasure { relmse, energy, mean };
    Ok(EstimateCheck {
        integrator: auto,
        target,
        measure: ESTIMATE_MEASURE,
        pilot,
        measured_seconds: render.output.seconds,
        reached: estimate.is_some_and(|e| e.is_trusted())
            && estimated_error.is_some_and(|e| e <= target),
        estimated_error,
        true_error: true_by_measure.get(ESTIMATE_MEASURE).unwrap_or(0.0),
        batches: estimate.map_or(0, |e| e.batches),
        paths,
        estimated_by_measure: estimate.map(|e| e.by_measure).unwrap_or_default(),
        true_by_measure,
        reference_paths: reference.paths,
        reference_error: reference.own_error,
    })
}
