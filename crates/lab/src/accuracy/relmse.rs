//! The sweep in the renderer's default measure: each estimator's time to 10% `relmse`.
//!
//! The sweep's points (up to 2^20 paths) are far from 10% `relmse` on most scenes, and the
//! sweep's reference (2^24 paths) carries several percent of `relmse` noise itself, so that
//! target cannot be interpolated between points the way the `energy` tables are. But an
//! unbiased estimator's squared error against the truth falls exactly as `1 / paths` in every
//! measure whose denominators are the truth's: the last point's error, with the reference's own
//! noise taken out in quadrature, gives the time to any smaller error by that law. The estimate
//! check renders auto's pick to the target for real, and its measured time is shown beside.

use super::report::{converges, percent, sig, sweep_reference_error};
use super::*;
use std::fmt::Write as _;

/// The estimators compared (each with independent sampling).
const ESTIMATORS: [Configuration; 3] =
    [Configuration::Baseline, Configuration::Path, Configuration::Bdpt];

/// An estimator's time to a `relmse` target from its last sweep point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum RelmseReach {
    /// Seconds, from the last point along `1 / sqrt(time)`.
    Predicted(f64),
    /// The last point's error is within 1.5 times the reference's own noise: not measurable.
    AtReferenceNoise(f64),
    /// The estimator converges to another image on this scene.
    Biased,
    /// Not swept, or no `relmse` recorded.
    Missing,
}

/// The time `result` takes to reach `target` in `relmse`: with `e` its last point's error
/// against the reference and `r` the reference's own (`reference_noise`), the true error is
/// `sqrt(e² - r²)` at the point's time `t`, and `t (sqrt(e² - r²) / target)²` at the target.
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
    let Some(last) = result.points.last().filter(|p| p.relmse > 0.0 && p.seconds > 0.0) else {
        return RelmseReach::Missing;
    };
    if last.relmse < 1.5 * reference_noise {
        return RelmseReach::AtReferenceNoise(last.relmse);
    }
    let truth2 = last.relmse * last.relmse - reference_noise * reference_noise;
    RelmseReach::Predicted(last.seconds * truth2 / (target * target))
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
         from its last sweep point: its error against the reference with the reference's own \
         `relmse` noise taken out in quadrature (`sqrt(e^2 - r^2)`, `r` from the reference's \
         estimator in the sweep), scaled along time^(-1/2), which an unbiased estimator's true \
         error follows exactly. `-` where the last point is within 1.5 times the reference's \
         noise; `biased` where the estimator converges to another image (see the tables below). \
         `fastest`: the fastest of light, path and bdpt (independent sampling), and auto's time \
         (with its default sampler) over it. Last columns: the estimate check's render of auto's pick to {target} (stopped by its own \
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
                let peer = match check.integrator {
                    IntegratorChoice::Path => Configuration::Path,
                    IntegratorChoice::Bdpt => Configuration::Bdpt,
                    _ => Configuration::Baseline,
                };
                let ratio = match reach(peer) {
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
