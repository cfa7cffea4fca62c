//! `auto` decided by measurement: when the effects analysis finds more than one estimator that
//! renders the whole image, a short pilot of each ([`crate::pilot::estimate`], the machinery of
//! `spectrace estimate`) predicts which reaches the error soonest, and the render uses that one.
//!
//! # When it runs
//! Only for an open-ended render (`--time` or a target error, and no `--beams` / `--spp`: the
//! estimators count work in different units, so a fixed count has no common measure), asked for
//! `auto` (on the command line or by `settings.integrator`), not sharded (every shard must render
//! with the same estimator), and when at least two of light, path and bdpt see every pixel (none
//! of them warns that it misses light, as a render with it would). Otherwise the analysis' static
//! rule stands ([`crate::choose_integrator`]).
//!
//! # What it costs
//! The pilots together take [`PILOT_SHARE`] of a `--time` budget (which the render then has that
//! much less of), or [`PILOT_SECONDS`] when a target error bounds the render (at most that share
//! of a `--time` given as its cap: a render that reaches its target in a fraction of a second
//! under a cap of minutes once waited 11 s for its pilots); the time is
//! split evenly between the candidates. Each pilot renders at least one chunk per thread, and a
//! camera estimator's chunk is a pass over the image, so the pilots render the scene with its
//! camera scaled down to at most [`PILOT_PIXELS`] pixels (same view and aspect; the scene is
//! loaded again from its canonical JSON, which the pilots' time includes). Every estimator's
//! time to a given per-pixel error grows in proportion to the pixels (a camera pass costs its
//! pixels, and a light tracer needs beams in proportion to them), so the predicted times are
//! scaled by the ratio of pixels and their ranking is the pilot's. On a budget of a fraction of
//! a second the pilots can still take longer than their share. The prediction ranks the
//! candidates by their predicted time to the render's target error (5% when only a time is
//! given; the ranking is the same for every target when errors fall as `1 / sqrt(time)`).
//!
//! # Reproducibility
//! The choice depends on the machine's speed at the time, so two runs may choose differently
//! where two estimators are close; each says which it chose and why (printed, and
//! `integrator_reason` in the sidecar), and `--integrator` fixes it. Given the estimator, the
//! image is as reproducible as ever.

use std::time::Instant;

use spectrace_tracer::{IntegratorChoice, RenderPlan};

use crate::integrators::ESTIMATORS;
use crate::pilot::{EstimateOptions, estimate};
use crate::sensor_output::format_value;
use crate::warnings::integrator_warnings;
use crate::{LoadOptions, RenderError, RenderOptions, Scene};

/// Share of a `--time` budget the pilots may take together.
pub const PILOT_SHARE: f64 = 0.05;

/// Seconds the pilots may take together when only a target error bounds the render.
pub const PILOT_SECONDS: f64 = 2.0;

/// Most pixels of the image the pilots render.
pub const PILOT_PIXELS: u64 = 128 * 128;

/// The target error the pilots predict for when the render has none (only a time budget).
const DEFAULT_TARGET: f64 = 0.05;

/// The estimator the pilots chose, and what they measured.
#[derive(Debug, Clone, PartialEq)]
pub struct MeasuredChoice {
    /// The fastest candidate.
    pub choice: IntegratorChoice,
    /// Why, in words: the predictions and what the static rule would have picked.
    pub reason: String,
    /// Each candidate with its predicted time to the target (s; `None`: nothing reached the
    /// camera in its pilot), in the order light, path, bdpt.
    pub predictions: Vec<(IntegratorChoice, Option<f64>)>,
    /// Wall time of the pilots together (s).
    pub pilot_seconds: f64,
}

/// The estimators that render every pixel of `scene` (no warning that they miss light).
pub fn complete_estimators(scene: &Scene) -> Vec<IntegratorChoice> {
    ESTIMATORS.into_iter().filter(|&c| integrator_warnings(scene, c).is_empty()).collect()
}

/// The pilots' time in all for a render planned as `plan` with `options`, or `None` when the
/// choice is not measured (see the module documentation).
pub fn pilot_budget(scene: &Scene, options: &RenderOptions, plan: &RenderPlan) -> Option<f64> {
    let asked_auto =
        options.integrator.unwrap_or(scene.settings.integrator) == IntegratorChoice::Auto;
    let counted = options.beams.is_some() || options.spp.is_some();
    if !asked_auto || counted || plan.shard.is_some() {
        return None;
    }
    match (options.time, plan.target_error) {
        (Some(t), None) => Some(PILOT_SHARE * t),
        (Some(t), Some(_)) => Some((PILOT_SHARE * t).min(PILOT_SECONDS)),
        (None, Some(_)) => Some(PILOT_SECONDS),
        (None, None) => None,
    }
}

/// Runs the pilots when the choice is measured and more than one estimator sees every pixel;
/// `None` otherwise. `fallback` is the static rule's choice and reason.
///
/// # Errors
/// As [`estimate`], or when the scene no longer loads for the scaled-down pilot (a file it names
/// changed meanwhile). [`crate::render_scene`] then renders with the rule's pick and warns.
pub fn measure_choice(
    scene: &Scene,
    options: &RenderOptions,
    plan: &RenderPlan,
    fallback: &(IntegratorChoice, String),
) -> Result<Option<MeasuredChoice>, RenderError> {
    let Some(budget) = pilot_budget(scene, options, plan) else { return Ok(None) };
    let candidates = complete_estimators(scene);
    if candidates.len() < 2 {
        return Ok(None);
    }
    let target = plan.target_error.unwrap_or(DEFAULT_TARGET);
    let estimate_options = EstimateOptions {
        target_error: target,
        pilot_seconds: budget / candidates.len() as f64,
        threads: plan.threads,
        seed: plan.seed,
        integrators: candidates.clone(),
        fixed_rounds: None,
        error_measure: Some(plan.error_measure),
    };
    let start = Instant::now();
    let small = pilot_scene(scene, options)?;
    let (pilot, scale) = match &small {
        Some(s) => (s, pixels(scene) as f64 / pixels(s) as f64),
        None => (scene, 1.0),
    };
    let report = estimate(pilot, &estimate_options)?;
    let pilot_seconds = start.elapsed().as_secs_f64();
    let predictions: Vec<(IntegratorChoice, Option<f64>)> = candidates
        .iter()
        .map(|&c| {
            let p = report.predictions.iter().find(|p| p.integrator == c.name());
            (c, p.and_then(|p| p.predicted_seconds).map(|t| t * scale))
        })
        .collect();
    let size = small.as_ref().map(|s| (s.camera.width(), s.camera.height()));
    Ok(Some(choose(predictions, target, (pilot_seconds, size), fallback)))
}

/// Pixels of the scene's image.
fn pixels(scene: &Scene) -> u64 {
    u64::from(scene.camera.width()) * u64::from(scene.camera.height())
}

/// The scene with its camera scaled down to at most [`PILOT_PIXELS`] pixels (each side at least
/// 1, the aspect kept), loaded again from its canonical JSON with the render's load options
/// (`--restrict-paths` holds for the reload too); `None` when it is that small already.
///
/// # Errors
/// [`RenderError::Scene`] if the scene no longer loads (a file it names changed meanwhile).
fn pilot_scene(scene: &Scene, options: &RenderOptions) -> Result<Option<Scene>, RenderError> {
    let (w, h) = (scene.camera.width(), scene.camera.height());
    if pixels(scene) <= PILOT_PIXELS {
        return Ok(None);
    }
    let shrink = (PILOT_PIXELS as f64 / pixels(scene) as f64).sqrt();
    let side = |n: u32| ((f64::from(n) * shrink).floor() as u32).max(1);
    let mut value: serde_json::Value = serde_json::from_str(&scene.canonical_json)
        .map_err(|e| RenderError::Options(format!("the scene's canonical JSON: {e}")))?;
    value["camera"]["width"] = side(w).into();
    value["camera"]["height"] = side(h).into();
    let load = LoadOptions { restrict_paths: options.restrict_paths };
    Ok(Some(Scene::from_json_with(&value.to_string(), &scene.path, load)?))
}

/// The fastest of `predictions` (the static rule's choice when none could be predicted), with
/// its reason; `pilot` is the pilots' time and, when they rendered a smaller image, its size.
pub fn choose(
    predictions: Vec<(IntegratorChoice, Option<f64>)>,
    target: f64,
    pilot: (f64, Option<(u32, u32)>),
    fallback: &(IntegratorChoice, String),
) -> MeasuredChoice {
    let (pilot_seconds, size) = pilot;
    let fastest = predictions
        .iter()
        .filter_map(|&(c, t)| t.filter(|t| t.is_finite()).map(|t| (c, t)))
        .min_by(|a, b| a.1.total_cmp(&b.1));
    let listed: Vec<String> = predictions
        .iter()
        .map(|(c, t)| match t {
            Some(t) => format!("{} {} s", c.name(), format_value(*t)),
            None => format!("{} no estimate", c.name()),
        })
        .collect();
    let (choice, verdict) = match fastest {
        Some((c, _)) => (c, "predicted fastest"),
        None => (fallback.0, "no pilot gave an estimate, so the analysis decides"),
    };
    let percent = (100_000.0 * target).round() / 1000.0;
    let at = size.map_or(String::new(), |(w, h)| {
        format!(" at {w}x{h} pixels (times scaled to the full image)")
    });
    let reason = format!(
        "{}: {verdict} to {percent}% relative error by a {pilot_seconds:.2} s pilot{at} of every \
         estimator that sees the whole image ({}); the analysis alone picks {}",
        choice.name(),
        listed.join(", "),
        fallback.1,
    );
    MeasuredChoice { choice, reason, predictions, pilot_seconds }
}
