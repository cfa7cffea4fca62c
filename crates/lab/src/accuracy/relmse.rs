//! The sweep in the renderer's default measure: each estimator's time to 10% `relmse`.
//!
//! The sweep's points (up to 2^20 paths) are far from 10% `relmse` on most scenes, and the
//! sweep's reference (2^24 paths) carries several percent of `relmse` noise itself, so that
//! target cannot be interpolated between points the way the `energy` tables are. But an
//! unbiased estimator's squared error against the truth falls exactly as `1 / paths` in every
//! measure whose denominators are the truth's: the last points' errors, with the reference's own
//! noise taken out in quadrature, give the time to any smaller error by that law. The estimate
//! check renders auto's pick to the target for real, and its measured time is shown beside.

use super::report::{converges, percent, sig, sweep_configuration, sweep_reference_error};
use super::*;
use std::fmt::Write as _;

/// The estimators compared (each with independent sampling).
const ESTIMATORS: [Configuration; 3] =
    [Configuration::Baseline, Configuration::Path, Configuration::Bdpt];

/// An estimator's time to a `relmse` target from its last sweep points.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum RelmseReach {
    /// Seconds, from the last point along `1 / sqrt(time)`.
    Predicted(f64),
    /// The last points' errors are within [`ABOVE_REFERENCE`] times the reference's own noise:
    /// not measurable.
    AtReferenceNoise(f64),
    /// The estimator converges to another image on this scene.
    Biased,
    /// Not swept, or no `relmse` recorded.
    Missing,
}

/// Sweep points a time to the target is predicted from: the last three.
const LAST_POINTS: usize = 3;

/// How far above the reference's own noise a point's error must be to enter the prediction:
/// at twice it, taking it out in quadrature removes 13% of the error.
const ABOVE_REFERENCE: f64 = 2.0;

/// The time `result` takes to reach `target` in `relmse`: with `e` a point's error against the
/// reference and `r` the reference's own (`reference_noise`), the true error is
/// `sqrt(e² - r²)` at the point's time `t`, and `t (e² - r²) / target²` at the target. The
/// median of that over the last [`LAST_POINTS`] points whose error is at least
/// [`ABOVE_REFERENCE`] times `r`: a single render's `relmse` at a hundred samples per pixel is
/// heavy-tailed (the Cornell box's path tracer at 2^19 and 2^20 paths: 66% and 47%; auto's at
/// the same: 87% and 83%).
pub(super) fn relmse_reach(
    scene: &SceneResult,
    result: Option<&ConfigurationResult>,
    reference_noise: f64,
    target: f64,
) -> RelmseReach {
    let Some(result) = result.filter(|r| r.not_applicable.is_none()) else {
        return RelmseReach::Missing;
    };
    if !converges(scene, result) {
        return RelmseReach::Biased;
    }
    let points: Vec<&AccuracyPoint> =
        result.points.iter().filter(|p| p.relmse > 0.0 && p.seconds > 0.0).collect();
    let Some(last) = points.last() else { return RelmseReach::Missing };
    let r2 = reference_noise * reference_noise;
    let mut times: Vec<f64> = points[points.len().saturating_sub(LAST_POINTS)..]
        .iter()
        .filter(|p| p.relmse >= ABOVE_REFERENCE * reference_noise)
        .map(|p| p.seconds * (p.relmse * p.relmse - r2) / (target * target))
        .collect();
    if times.is_empty() {
        return RelmseReach::AtReferenceNoise(last.relmse);
    }
    times.sort_by(f64::total_cmp);
    let n = times.len();
    let median = if n % 2 == 1 { times[n / 2] } else { 0.5 * (times[n / 2 - 1] + times[n / 2]) };
    RelmseReach::Predicted(median)
}

/// An estimator's name in the table: `light` for the baseline.
fn estimator_name(c: Configuration) -> String {
    if c == Configuration::Baseline { "light".to_owned() } else { c.name().to_owned() }
}

/// A cell of the table.
fn reach_cell(reach: RelmseReach) -> String {
    match reach {
        RelmseReach::Predicted(t) => sig(t),
        RelmseReach::AtReferenceNoise(e) => format!("- ({} at the reference's noise)", percent(e)),
        RelmseReach::Biased => "biased".to_owned(),
        RelmseReach::Missing => "-".to_owned(),
    }
}

/// The section: per scene, each estimator's time to [`ROUND_TARGET`] in `relmse`, and the
/// estimate check's measured time for auto's pick.
pub(super) fn relmse_markdown(md: &mut String, report: &AccuracyReport) {
    let _ = writeln!(
        md,
        "\n## Time to {target} per-pixel relative error (relmse)\n\n\
         Seconds each estimator takes to {target} `relmse` (the renderer's default measure), \
         from its last three sweep points: each point's error against the reference with the \
         reference's own `relmse` noise taken out in quadrature (`sqrt(e^2 - r^2)`, `r` from the \
         reference's estimator in the sweep), scaled along time^(-1/2), which an unbiased \
         estimator's true error follows; the median of the three (one render's `relmse` at a \
         hundred samples per pixel is heavy-tailed), leaving out points within twice the \
         reference's noise. `-` where all three are; where the reference's own noise is several \
         percent, the points that enter are only a few times it and these times are rough (up \
         to a factor of 3.5 between two runs of this report on the Cornell box, whose 2^24-path \
         reference is far from converged per pixel); `biased` where the estimator converges to \
         another image (see the tables below). `fastest`: the fastest of light, path and bdpt \
         (independent sampling), and auto's time (with its default sampler) over it. Last \
         columns: the estimate check's render of auto's pick to {target} (stopped by its own \
         estimate; the section above), its measured time, and that over the time predicted here \
         for the same estimator.\n",
        target = percent(ROUND_TARGET)
    );
    let _ = writeln!(
        md,
        "| scene | reference's relmse noise | light | path | bdpt | auto | fastest | auto / fastest | check: estimator | check: measured | measured / predicted here |"
    );
    let _ = writeln!(md, "|---|---:|---:|---:|---:|---:|---|---:|---|---:|---:|");
    for scene in &report.scenes {
        let find = |c: Configuration| scene.configurations.iter().find(|r| r.configuration == c);
        let noise = sweep_reference_error(
            &scene.configurations,
            scene.reference.integrator,
            scene.reference.beams,
        )
        .and_then(|(_, e)| e.relmse);
        let Some(noise) = noise else {
            let _ = writeln!(md, "| {} | - | - | - | - | - | - | - | - | - | - |", scene.name);
            continue;
        };
        let reach = |c: Configuration| relmse_reach(scene, find(c), noise, ROUND_TARGET);
        let (check, measured, ratio) = match &scene.estimate_check {
            Some(check) => {
                let ratio = match reach(sweep_configuration(check.integrator)) {
                    RelmseReach::Predicted(t) => format!("{:.2}", check.measured_seconds / t),
                    _ => "-".to_owned(),
                };
                (check.integrator.name().to_owned(), sig(check.measured_seconds), ratio)
            }
            None => ("-".to_owned(), "-".to_owned(), "-".to_owned()),
        };
        let predicted = |c: Configuration| match reach(c) {
            RelmseReach::Predicted(t) => Some(t),
            _ => None,
        };
        let fastest = ESTIMATORS
            .iter()
            .filter_map(|&c| predicted(c).map(|t| (c, t)))
            .min_by(|a, b| a.1.total_cmp(&b.1));
        let (fastest_cell, auto_cell) = match (fastest, predicted(Configuration::Auto)) {
            (Some((c, t)), Some(a)) => (estimator_name(c), format!("{:.2}", a / t)),
            (Some((c, _)), None) => (estimator_name(c), "-".to_owned()),
            (None, _) => ("-".to_owned(), "-".to_owned()),
        };
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} | {} | {fastest_cell} | {auto_cell} | {check} | {measured} | {ratio} |",
            scene.name,
            percent(noise),
            reach_cell(reach(Configuration::Baseline)),
            reach_cell(reach(Configuration::Path)),
            reach_cell(reach(Configuration::Bdpt)),
            reach_cell(reach(Configuration::Auto)),
        );
    }
}
