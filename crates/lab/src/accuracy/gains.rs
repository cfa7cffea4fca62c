//! What a variance-reduction knob buys: the variance of one configuration over its peer's (the
//! same estimator without the knob), in pixels (XYZ) and in colour, at equal paths and at
//! equal time, from the sweep points both rendered.

use super::report::sig;
use super::*;
use std::fmt::Write as _;

/// The knobs whose gain the report states: (with the knob, its peer, what the knob is).
pub(super) const GAIN_PAIRS: [(Configuration, Configuration, &str); 6] = [
    (Configuration::Bdpt, Configuration::BdptBeam, "hero wavelengths (BDPT)"),
    (Configuration::BdptSobol, Configuration::Bdpt, "Sobol points (BDPT)"),
    (Configuration::PathSobol, Configuration::Path, "Sobol points (path)"),
    (
        Configuration::Path,
        Configuration::PathUniformWavelengths,
        "visible camera wavelengths (path)",
    ),
    (Configuration::ObserverWavelengths, Configuration::Baseline, "observer wavelengths (light)"),
    (Configuration::Sobol, Configuration::Baseline, "Sobol points (light)"),
];

/// Shared sweep points the ratios use at most: the last ones (the most paths) where both
/// sides' variance is at least twice the reference's own.
const LAST_POINTS: usize = 4;

/// Variance ratios of a configuration over its peer.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Gain {
    /// Variance of XYZ (squared relative RMSE, the reference's noise taken out) over the peer's,
    /// summed over the points used: the pixel variance at equal paths.
    pub pixel: f64,
    /// The same for the colour part of the error ([`colour_relative_rmse`]).
    pub colour: f64,
    /// Wall time over the peer's over the same points: the ratios at equal time are the ratios
    /// at equal paths times this.
    pub time: f64,
    /// Sweep points used.
    pub points: usize,
}

/// The reference's own noise, as (relative RMSE, its colour part): the reference estimator's
/// last sweep point scaled to the reference's paths (see [`super::report::reference_noise`]).
fn reference_noise(scene: &SceneResult) -> Option<(f64, f64)> {
    let (same, noise) = super::report::reference_noise(scene)?;
    let last = scene.configurations.iter().find(|c| c.configuration == same)?.points.last()?;
    let colour = last.colour_rmse * noise / last.relative_rmse;
    (noise.is_finite() && colour.is_finite()).then_some((noise, colour))
}

/// The gain of `with` over `peer` on a scene, from the last [`LAST_POINTS`] sweep points both
/// rendered at equal paths where every measured variance (pixel and colour, both sides) is at
/// least twice the reference's own, which is subtracted (they add). `None` when either was not
/// swept, no point qualifies, or a colour error is missing (a report from before it was
/// measured).
pub(super) fn gain(scene: &SceneResult, with: Configuration, peer: Configuration) -> Option<Gain> {
    let find = |c| scene.configurations.iter().find(|r| r.configuration == c);
    let (a, b) = (find(with)?, find(peer)?);
    let (r, rc) = reference_noise(scene)?;
    let (r2, rc2) = (r * r, rc * rc);
    let usable: Vec<[f64; 6]> = a
        .points
        .iter()
        .zip(&b.points)
        .filter(|(p, q)| p.beams == q.beams && p.colour_rmse > 0.0 && q.colour_rmse > 0.0)
        .map(|(p, q)| {
            [
                p.relative_rmse.powi(2) - r2,
                q.relative_rmse.powi(2) - r2,
                p.colour_rmse.powi(2) - rc2,
                q.colour_rmse.powi(2) - rc2,
                p.seconds,
                q.seconds,
            ]
        })
        .filter(|v| v[0] >= r2 && v[1] >= r2 && v[2] >= rc2 && v[3] >= rc2)
        .collect();
    let used = &usable[usable.len().saturating_sub(LAST_POINTS)..];
    let mut sums = [0.0; 6];
    for v in used {
        for (s, x) in sums.iter_mut().zip(v) {
            *s += x;
        }
    }
    let ratio = |n: f64, d: f64| (d > 0.0 && n.is_finite()).then(|| n / d);
    Some(Gain {
        pixel: ratio(sums[0], sums[1])?,
        colour: ratio(sums[2], sums[3])?,
        time: ratio(sums[4], sums[5])?,
        points: (!used.is_empty()).then_some(used.len())?,
    })
}

/// One table cell: pixel and colour variance ratios, at equal paths or at equal time.
fn cell(gain: Option<Gain>, equal_time: bool, biased: bool) -> String {
    let Some(g) = gain else { return "-".to_owned() };
    let t = if equal_time { g.time } else { 1.0 };
    let mark = if biased { " (biased)" } else { "" };
    format!("{} / {}{mark}", sig(g.pixel * t), sig(g.colour * t))
}

/// The section "What each variance-reduction knob buys": two tables (equal paths, equal time),
/// a row per scene, a column per knob in [`GAIN_PAIRS`] that the run swept.
pub(super) fn gains_markdown(md: &mut String, report: &AccuracyReport) {
    let swept = |c| report.options.configurations.contains(&c);
    let pairs: Vec<_> = GAIN_PAIRS.iter().filter(|(a, b, _)| swept(*a) && swept(*b)).collect();
    if pairs.is_empty() {
        return;
    }
    let _ = writeln!(
        md,
        "\n## What each variance-reduction knob buys\n\n\
         Per scene, the variance with a knob over the variance without it (the same estimator, \
         the peer named in brackets), as `pixel / colour`: pixel is the squared relative RMSE of \
         XYZ, colour its part that changes a pixel's colour rather than its brightness (each \
         pixel's error minus its component along the reference pixel's XYZ). Below 1 the knob \
         helps. Summed over the last {LAST_POINTS} sweep points (the most paths) that both \
         rendered where each measured variance is at least twice the reference's own noise, \
         which is taken out (variances add); Sobol's gain grows with the sample count, so it \
         is measured where the sweep has the most samples. Each point is one render, so ratios \
         carry some noise. `(biased)`: either side converges to another image than the \
         reference (its error includes a floor), `-`: not swept or no point qualifies, or \
         not applicable (hero wavelengths are off where a scene disperses, fluoresces or has \
         line spectra, so `bdpt` and `bdpt_beam` render alike there).\n"
    );
    for (title, equal_time) in [("At equal paths", false), ("At equal time", true)] {
        let _ = writeln!(md, "{title}:\n");
        let mut header = "| scene |".to_owned();
        let mut rule = "|---|".to_owned();
        for (a, b, what) in &pairs {
            let _ = write!(header, " {what}: `{}` over `{}` |", a.name(), b.name());
            rule.push_str("---:|");
        }
        let _ = writeln!(md, "{header}\n{rule}");
        for scene in &report.scenes {
            let mut row = format!("| {} |", scene.name);
            for (a, b, _) in &pairs {
                let applies = |c| {
                    scene
                        .configurations
                        .iter()
                        .any(|r| r.configuration == c && r.not_applicable.is_none())
                };
                let biased = [a, b].iter().any(|&&c| {
                    scene
                        .configurations
                        .iter()
                        .any(|r| r.configuration == c && !report::converges(scene, r))
                });
                let g = (applies(*a) && applies(*b)).then(|| gain(scene, *a, *b)).flatten();
                let _ = write!(row, " {} |", cell(g, equal_time, biased));
            }
            let _ = writeln!(md, "{row}");
        }
        let _ = writeln!(md);
    }
}
