//! Does the renderer know its own error? For each scene: the pilot's prediction of the time to
//! [`ESTIMATE_TARGET`] for every estimator, then a render to that target with the estimator
//! `auto` picks, whose final estimate is compared with its true error against the reference and
//! whose time is compared with the prediction.

use serde::{Deserialize, Serialize};
use spectrace_renderer::pilot::{EstimateOptions, EstimateReport, Prediction, estimate};
use spectrace_renderer::{RenderOptions, Scene, render_in_memory};
use spectrace_spectrum::Xyz;
use spectrace_tracer::{ByMeasure, ErrorMeasure, IntegratorChoice, relative_error};

use super::relative_rmse;

/// The target of the check: 5%, the issue's.
pub const ESTIMATE_TARGET: f64 = 0.05;

/// Longest the check's render to the target may run (s): it stops there, target or not.
pub const ESTIMATE_CAP_SECONDS: f64 = 60.0;

/// The estimate against the truth for one scene.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EstimateCheck {
    /// The estimator of the render (`auto`'s pick).
    pub integrator: IntegratorChoice,
    /// The target.
    pub target: f64,
    /// The pilot's predictions for light, path and bdpt, and its recommendation.
    pub pilot: EstimateReport,
    /// Wall time of the render to the target (s).
    pub measured_seconds: f64,
    /// Whether the render reached the target before [`ESTIMATE_CAP_SECONDS`].
    pub reached: bool,
    /// The render's own estimate of its relative error at the end.
    pub estimated_error: Option<f64>,
    /// Its relative RMSE against the reference (which carries the reference's own noise).
    pub true_error: f64,
    /// Chunks of the render.
    pub batches: u64,
    /// Paths (work items) of the render.
    #[serde(default)]
    pub paths: u64,
    /// The render's own final estimate in every measure (the headline above is `energy`'s).
    #[serde(default)]
    pub estimated_by_measure: ByMeasure,
    /// Its error against the reference in every measure (with the reference's own noise).
    #[serde(default)]
    pub true_by_measure: ByMeasure,
}

impl EstimateCheck {
    /// The pilot's prediction for the estimator of the render.
    pub fn prediction(&self) -> Option<&Prediction> {
        self.pilot.predictions.iter().find(|p| p.integrator == self.integrator.name())
    }
}

/// Runs the check on `scene` with the estimator `auto` picks, against `reference`.
///
/// # Errors
/// A message when a render fails.
pub fn estimate_check(
    scene: &Scene,
    auto: IntegratorChoice,
    reference: &[Xyz],
    threads: usize,
    seed: u64,
) -> Result<EstimateCheck, String> {
    let pilot = estimate(
        scene,
        &EstimateOptions {
            target_error: ESTIMATE_TARGET,
            threads,
            seed: seed ^ 0x9170_7000,
            error_measure: Some(ErrorMeasure::Energy),
            ..EstimateOptions::default()
        },
    )
    .map_err(|e| e.to_string())?;
    let render = render_in_memory(
        scene,
        &RenderOptions {
            target_error: Some(ESTIMATE_TARGET),
            time: Some(ESTIMATE_CAP_SECONDS),
            threads: Some(threads),
            seed: Some(seed ^ 0xE571_0000),
            integrator: Some(auto),
            // The report's headline measure; the others are recorded beside it.
            error_measure: Some(ErrorMeasure::Energy),
            ..RenderOptions::default()
        },
    )
    .map_err(|e| e.to_string())?;
    let estimate = render.output.estimate(ErrorMeasure::Energy);
    let estimated_error = estimate.and_then(|e| e.relative_error);
    let truth = |m| relative_error(m, &render.image, reference).ok();
    let [relmse, energy, mean] = ErrorMeasure::ALL.map(truth);
    Ok(EstimateCheck {
        integrator: auto,
        target: ESTIMATE_TARGET,
        pilot,
        measured_seconds: render.output.seconds,
        reached: estimate.is_some_and(|e| e.is_trusted())
            && estimated_error.is_some_and(|e| e <= ESTIMATE_TARGET),
        estimated_error,
        true_error: relative_rmse(&render.image, reference)?,
        batches: estimate.map_or(0, |e| e.batches),
        paths: render.output.beams,
        estimated_by_measure: estimate.map(|e| e.by_measure).unwrap_or_default(),
        true_by_measure: ByMeasure { relmse, energy, mean },
    })
}
