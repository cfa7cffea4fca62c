//! `spectrace estimate`: how long a scene takes to reach a target error with each estimator,
//! predicted from a short pilot render of each, before rendering.
//!
//! For every estimator (light, path, bdpt) the pilot renders in two rounds, keeping the error
//! estimate ([`spectrace_tracer::Moments`]): one chunk per thread, which times a round, then as
//! many more rounds as fit in the pilot time, on other random streams (a camera estimator's
//! chunk is one sample per pixel, so a slow one may get only the first round). The chunks are
//! independent, so the error falls as `1 / sqrt(items)`: reaching `E` from an error `e` after
//! `N` items needs `N (e / E)^2` items, and at the second round's speed (free of start-up costs)
//! the extra ones take `(N (e / E)^2 - N_1) / rate` seconds after the first round's `t_1`. The
//! slopes of log error against log time and against log work are fitted to the second round's
//! live estimates; the time slope is reported beside the expected -1/2 (start-up costs make it
//! steeper early on), and the work slope replaces -1/2 in the prediction only when it differs by
//! more than three standard errors, and not in `relmse` (whose estimate's bias from few chunks
//! shrinks over the pilot and would pass for a slope). The stated uncertainty is the estimate's own (from its
//! degrees of freedom), doubled because time goes as the error squared; the machine's load is
//! not in it.

use std::sync::Mutex;

use serde::{Deserialize, Serialize};
use spectrace_lights::LightSource;
use spectrace_tracer::{
    ErrorMeasure, IntegratorChoice, LiveEstimates, MIN_BATCHES, Progress, RenderPlan,
    render_observed,
};

use crate::integrators::{ESTIMATORS, with_kernel};
use crate::warnings::integrator_warnings;
use crate::{
    RenderError, RenderOptions, Scene, choose_integrator, decide_effects, duration, plan_with,
};

/// Fewest chunks a live estimate of the pilot needs to enter the slope fit.
pub const MIN_PILOT_CHUNKS: u64 = 4;

/// Pilot time per estimator by default (s).
pub const DEFAULT_PILOT_SECONDS: f64 = 1.5;

/// What `spectrace estimate` is asked.
#[derive(Debug, Clone, PartialEq)]
pub struct EstimateOptions {
    /// The target relative error (in `error_measure`).
    pub target_error: f64,
    /// Pilot time per estimator (s).
    pub pilot_seconds: f64,
    /// Worker threads (0: one per core).
    pub threads: usize,
    /// Seed of the pilot renders.
    pub seed: u64,
    /// The estimators to try (default: light, path and bdpt).
    pub integrators: Vec<IntegratorChoice>,
    /// Rounds after the first, instead of as many as fit in the pilot time: a pilot whose
    /// work does not depend on the machine's speed (for tests).
    pub fixed_rounds: Option<u64>,
    /// The error measure of the target (`None`: the scene's `settings.error_measure`).
    pub error_measure: Option<spectrace_tracer::ErrorMeasure>,
}

impl Default for EstimateOptions {
    fn default() -> Self {
        Self {
            target_error: 0.05,
            pilot_seconds: DEFAULT_PILOT_SECONDS,
            threads: 0,
            seed: 0x5EED_0001,
            integrators: ESTIMATORS.to_vec(),
            fixed_rounds: None,
            error_measure: None,
        }
    }
}

/// One estimator's pilot and prediction.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Prediction {
    /// The estimator (`light`, `path`, `bdpt`).
    pub integrator: String,
    /// Work items the pilot rendered (beams, or camera samples).
    pub pilot_items: u64,
    /// Whole chunks the pilot rendered.
    pub pilot_chunks: u64,
    /// The pilot's render time (s).
    pub pilot_seconds: f64,
    /// The pilot's estimated relative error (`None`: nothing reached the camera).
    pub pilot_error: Option<f64>,
    /// Slope of log error against log time fitted to the pilot's live estimates (its second
    /// round), with its standard error (`None` with fewer than three estimates).
    pub measured_slope: Option<(f64, f64)>,
    /// The slope of error against work the prediction used: -1/2 unless the one measured in the
    /// pilot differs by more than three standard errors.
    pub slope_used: f64,
    /// Work items predicted to reach the target.
    pub predicted_items: Option<f64>,
    /// Render time predicted to reach the target (s).
    pub predicted_seconds: Option<f64>,
    /// One-sigma relative uncertainty of the predicted time.
    pub relative_uncertainty: f64,
    /// Why this estimator's image differs from the scene's true image (light it cannot reach),
    /// empty when it renders everything.
    pub misses: Vec<String>,
}

/// `spectrace estimate`'s answer.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EstimateReport {
    /// The scene file.
    pub scene: String,
    /// The target relative error.
    pub target_error: f64,
    /// The measure of the target and of the pilots' errors (`"energy"`, `"relmse"`, `"mean"`).
    pub error_measure: String,
    /// One prediction per estimator tried.
    pub predictions: Vec<Prediction>,
    /// The fastest estimator that renders everything (or, if none does, the fastest).
    pub recommended: Option<String>,
    /// What `auto` (the effects analysis) picks, and why.
    pub auto_picks: String,
    /// The reason `auto` gives.
    pub auto_reason: String,
}

/// Runs the pilots and predicts the time to `options.target_error` for each estimator.
///
/// # Errors
/// [`RenderError::Options`] for an invalid target or pilot time, or a film that cannot be
/// made.
pub fn estimate(scene: &Scene, options: &EstimateOptions) -> Result<EstimateReport, RenderError> {
    crate::check_target_error(options.target_error)
        .map_err(|m| RenderError::Options(format!("--target-error {m}")))?;
    if !(options.pilot_seconds > 0.0 && options.pilot_seconds <= 600.0) {
        return Err(RenderError::Options(format!(
            "--pilot-seconds {}: must be more than 0 and at most 600",
            options.pilot_seconds
        )));
    }
    let mut predictions = Vec::new();
    for &choice in &options.integrators {
        predictions.push(pilot(scene, options, choice)?);
    }
    let complete = |p: &&Prediction| p.misses.is_empty();
    let fastest = |ps: Vec<&Prediction>| {
        ps.into_iter()
            .filter(|p| p.predicted_seconds.is_some())
            .min_by(|a, b| {
                a.predicted_seconds
                    .partial_cmp(&b.predicted_seconds)
                    .unwrap_or(std::cmp::Ordering::Equal)
            })
            .map(|p| p.integrator.clone())
    };
    let recommended = fastest(predictions.iter().filter(complete).collect())
        .or_else(|| fastest(predictions.iter().collect()));
    let (auto, reason) = choose_integrator(scene, None);
    Ok(EstimateReport {
        scene: scene.path.display().to_string(),
        target_error: options.target_error,
        error_measure: options
            .error_measure
            .unwrap_or(scene.settings.error_measure)
            .name()
            .to_owned(),
        predictions,
        recommended,
        auto_picks: auto.name().to_owned(),
        auto_reason: reason,
    })
}

/// One estimator's pilot.
fn pilot(
    scene: &Scene,
    options: &EstimateOptions,
    choice: IntegratorChoice,
) -> Result<Prediction, RenderError> {
    let effects = decide_effects(scene, None);
    let base = RenderOptions {
        threads: Some(options.threads),
        seed: Some(options.seed),
        integrator: Some(choice),
        error_measure: options.error_measure,
        ..RenderOptions::default()
    };
    // Round 1: one chunk per thread, all at once, times a chunk.
    let first = RenderPlan {
        error_estimate: true,
        target_error: None,
        time_budget: None,
        ..plan_with(scene, &RenderOptions { beams: Some(1), ..base.clone() }, choice)?
    };
    let threads = first.threads.max(1) as u64;
    let first = RenderPlan { beams: first.chunk_beams.saturating_mul(threads), ..first };
    let run = |plan: &RenderPlan, observe: &(dyn Fn(&Progress) + Sync)| {
        // The error estimate decides here: independent passes for `auto`'s sampler, whose
        // spread is the error itself (see `sampler_of`).
        let build = (scene.settings.kernel, true);
        let out = with_kernel(scene, choice, effects, build, |tracer| {
            render_observed(tracer, plan, observe, LiveEstimates::Reported)
        })
        .map_err(|e| RenderError::Options(e.to_string()));
        scene.lights.reset_count();
        out
    };
    let mut output = run(&first, &|_| {})?;
    let round = output.seconds.max(1e-6);
    // Round 2: as many more rounds as fit in the pilot time, on other random streams. Its live
    // estimates give the measured slope, its speed the render rate (no start-up costs).
    let rounds = options.fixed_rounds.unwrap_or_else(|| {
        ((options.pilot_seconds - round) / round).floor().clamp(0.0, 1e6) as u64
    });
    let live: Mutex<Vec<(f64, u64, f64)>> = Mutex::new(Vec::new());
    let mut rate = output.beams as f64 / round;
    if rounds > 0 {
        let second = RenderPlan {
            beams: first.beams.saturating_mul(rounds),
            seed: first.seed.wrapping_add(0x9E37_79B9),
            ..first
        };
        let observe = |p: &Progress| {
            if let Some(e) = p.estimate
                && let Some(r) = e.relative_error
                && e.batches >= MIN_PILOT_CHUNKS
                && let Ok(mut v) = live.lock()
                // The live estimate is redone every few chunks: each enters the fit once.
                && v.last().is_none_or(|&(_, n, _)| n != e.items)
            {
                v.push((p.seconds, e.items, r));
            }
        };
        let more = run(&second, &observe)?;
        rate = more.beams as f64 / more.seconds.max(1e-9);
        output.merge(&more).map_err(|e| RenderError::Options(e.to_string()))?;
        output.seconds = round + more.seconds;
    }
    let estimate =
        output.estimate(first.error_measure).unwrap_or(spectrace_tracer::ErrorEstimate {
            measure: first.error_measure,
            relative_error: None,
            by_measure: spectrace_tracer::ByMeasure::default(),
            batches: 0,
            items: 0,
            degrees_of_freedom: 0.0,
        });
    let live = live.into_inner().unwrap_or_default();
    let slope_vs_time = fit_log_slope(&live.iter().map(|&(t, _, e)| (t, e)).collect::<Vec<_>>());
    let slope_vs_items =
        fit_log_slope(&live.iter().map(|&(_, n, e)| (n as f64, e)).collect::<Vec<_>>());
    // Independent chunks make the error fall as items^-1/2; a measured slope replaces it only
    // when it is clearly different (a sign of chunks that are not independent), and never in
    // `relmse`, whose estimate from few chunks is biased by the noise of its denominators, a
    // bias that shrinks as chunks come in: its slope over the pilot is that, not the error's.
    let slope_used = match slope_vs_items {
        Some((s, se))
            if first.error_measure != ErrorMeasure::RelMse
                && s < 0.0
                && (s + 0.5).abs() > 3.0 * se =>
        {
            s
        }
        _ => -0.5,
    };
    let target = options.target_error;
    // How many times the pilot's work reaching the target takes.
    let factor =
        estimate.relative_error.filter(|&e| e > 0.0).map(|e| (e / target).powf(-1.0 / slope_used));
    // A render to a target runs at least MIN_BATCHES chunks before it trusts its estimate.
    let fewest = (MIN_BATCHES * first.chunk_beams) as f64;
    let predicted_items = factor.map(|f| (output.beams as f64 * f).max(fewest));
    let predicted_seconds =
        predicted_items.map(|n| round + (n - first.beams as f64).max(0.0) / rate);
    let relative_uncertainty = 2.0 * estimate.relative_uncertainty();
    let seconds = output.seconds;
    let measured_slope = slope_vs_time;
    Ok(Prediction {
        integrator: choice.name().to_owned(),
        pilot_items: output.beams,
        pilot_chunks: estimate.batches,
        pilot_seconds: seconds,
        pilot_error: estimate.relative_error,
        measured_slope,
        slope_used,
        predicted_items,
        predicted_seconds,
        relative_uncertainty,
        misses: integrator_warnings(scene, choice),
    })
}

/// Least-squares slope of log error against log `x` (time or work), with its standard error,
/// over the points `(x, error)` (`None` for fewer than three positive ones).
fn fit_log_slope(points: &[(f64, f64)]) -> Option<(f64, f64)> {
    let logs: Vec<(f64, f64)> = points
        .iter()
        .filter(|(t, e)| *t > 0.0 && *e > 0.0)
        .map(|(t, e)| (t.ln(), e.ln()))
        .collect();
    let fit = fit_line(&logs)?;
    Some((fit.slope, fit.standard_error?))
}

/// A least-squares line's slope.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SlopeFit {
    /// The slope of `y` against `x`.
    pub slope: f64,
    /// Its standard error, from the residuals (`None` with two points: a line through both).
    pub standard_error: Option<f64>,
}

/// The least-squares slope of `y` against `x` (`None` for fewer than two distinct `x` or
/// non-finite values): the one fit of the pilot and of the accuracy report.
pub fn fit_line(points: &[(f64, f64)]) -> Option<SlopeFit> {
    if points.len() < 2 || points.iter().any(|(x, y)| !x.is_finite() || !y.is_finite()) {
        return None;
    }
    let n = points.len() as f64;
    let mx = points.iter().map(|p| p.0).sum::<f64>() / n;
    let my = points.iter().map(|p| p.1).sum::<f64>() / n;
    let sxx: f64 = points.iter().map(|p| (p.0 - mx).powi(2)).sum();
    if !(sxx > 0.0) {
        return None;
    }
    let slope = points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum::<f64>() / sxx;
    let residual: f64 = points.iter().map(|p| (p.1 - my - slope * (p.0 - mx)).powi(2)).sum();
    let standard_error = (points.len() > 2).then(|| (residual / (n - 2.0) / sxx).sqrt());
    Some(SlopeFit { slope, standard_error })
}

/// The report as a Markdown table with a recommendation.
pub fn markdown(report: &EstimateReport) -> String {
    let mut md = format!(
        "{}: time to {:.2}% relative error ({}), predicted from a pilot of each estimator\n\n\
         | estimator | pilot | pilot error | slope (measured, used) | predicted time | ± (1 sigma) | misses |\n\
         |---|---|---|---|---|---|---|\n",
        report.scene,
        report.target_error * 100.0,
        report.error_measure
    );
    for p in &report.predictions {
        let slope = match p.measured_slope {
            Some((s, se)) => format!("{s:.2} ± {se:.2}, {:.2}", p.slope_used),
            None => format!("-, {:.2}", p.slope_used),
        };
        md.push_str(&format!(
            "| {} | {} items, {} chunks, {} | {} | {} | {} | {:.0}% | {} |\n",
            p.integrator,
            p.pilot_items,
            p.pilot_chunks,
            duration(p.pilot_seconds),
            p.pilot_error.map_or("-".to_owned(), |e| format!("{:.2}%", e * 100.0)),
            slope,
            p.predicted_seconds.map_or("no light seen".to_owned(), duration),
            p.relative_uncertainty * 100.0,
            if p.misses.is_empty() { "nothing".to_owned() } else { p.misses.join("; ") }
        ));
    }
    match &report.recommended {
        Some(r) => md.push_str(&format!(
            "\nrecommended: {r}; auto picks {} ({})\n",
            report.auto_picks, report.auto_reason
        )),
        None => md.push_str("\nno estimator saw light in its pilot\n"),
    }
    md
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_line_fit_gives_the_slope_and_its_error_from_the_residuals() {
        assert_eq!(fit_line(&[(1.0, 2.0)]), None);
        assert_eq!(fit_line(&[(1.0, 2.0), (1.0, 3.0)]), None);
        assert_eq!(fit_line(&[(0.0, 1.0), (f64::NAN, 2.0)]), None);
        let two = fit_line(&[(0.0, 1.0), (2.0, 0.0)]).unwrap();
        assert_eq!((two.slope, two.standard_error), (-0.5, None));
        let exact = fit_line(&[(0.0, 1.0), (1.0, 0.5), (2.0, 0.0)]).unwrap();
        assert_eq!((exact.slope, exact.standard_error), (-0.5, Some(0.0)));
        // Residuals +-0.1 about slope 1: standard error sqrt(sum r^2 / (n - 2) / sxx).
        let noisy = fit_line(&[(0.0, 0.1), (1.0, 0.9), (2.0, 2.1), (3.0, 2.9)]).unwrap();
        assert!((noisy.slope - 0.96).abs() < 1e-12, "{noisy:?}");
        assert!(noisy.standard_error.unwrap() > 0.0);
        // Error against time on a log-log scale: e = t^-1/2 exactly.
        let pts: Vec<(f64, f64)> =
            [1.0, 4.0, 16.0].iter().map(|&t: &f64| (t, t.powf(-0.5))).collect();
        let (s, se) = fit_log_slope(&pts).unwrap();
        assert!((s + 0.5).abs() < 1e-12 && se < 1e-12);
        assert_eq!(fit_log_slope(&pts[..2]), None);
    }
}
