//! Analysis and the Markdown report: times to a target, slopes, the summary and per-scene tables.

use super::*;
use std::fmt::Write as _;

/// How long a configuration takes to reach an error.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Reach {
    /// Interpolated between two sweep points (log-log).
    Interpolated(f64),
    /// Already below the target at the first point: at most this long.
    AtMost(f64),
    /// Beyond the sweep, extrapolated along the fitted slope.
    Extrapolated(f64),
    /// Not reached, and the error does not fall clearly enough to extrapolate.
    NotReached,
}

impl Reach {
    pub(super) fn seconds(self) -> Option<f64> {
        match self {
            Reach::Interpolated(t) | Reach::AtMost(t) | Reach::Extrapolated(t) => Some(t),
            Reach::NotReached => None,
        }
    }

    pub(super) fn describe(self) -> String {
        match self {
            Reach::Interpolated(t) => format!("{} s", sig(t)),
            Reach::AtMost(t) => format!("<= {} s (first point)", sig(t)),
            Reach::Extrapolated(t) => format!("~{} s (extrapolated)", sig(t)),
            Reach::NotReached => "not reached (error stops falling)".to_owned(),
        }
    }
}

pub(super) fn time_to_reach(result: &ConfigurationResult, target: f64) -> Reach {
    let pts = &result.points;
    let Some(first) = pts.first() else { return Reach::NotReached };
    if first.relative_rmse <= target {
        return Reach::AtMost(first.seconds);
    }
    for w in pts.windows(2) {
        let (a, b) = (w[0], w[1]);
        if b.relative_rmse <= target {
            let (la, lb) = (a.relative_rmse.ln(), b.relative_rmse.ln());
            let f = if la > lb { (la - target.ln()) / (la - lb) } else { 1.0 };
            let lt = a.seconds.ln() + f * (b.seconds.ln() - a.seconds.ln());
            return Reach::Interpolated(lt.exp());
        }
    }
    match (pts.last(), result.slope_vs_time) {
        (Some(last), Some(slope)) if slope < -0.3 && !levels_off(result) => {
            Reach::Extrapolated(last.seconds * (target / last.relative_rmse).powf(1.0 / slope))
        }
        _ => Reach::NotReached,
    }
}

/// Least-squares slope of log error against log time over the last three sweep points (`None`
/// for fewer than three).
pub(super) fn tail_slope(result: &ConfigurationResult) -> Option<f64> {
    let pts = &result.points;
    let tail = pts.get(pts.len().checked_sub(3)?..)?;
    fit_slope(&tail.iter().map(|p| (p.seconds.ln(), p.relative_rmse.ln())).collect::<Vec<_>>())
}

/// Whether the error levels off at the end of the sweep (the last three points' slope is flatter
/// than [`LEVELS_OFF_SLOPE`]): the estimator converges to another image (bias), so extrapolating
/// its time to a smaller error would be wrong.
pub(super) fn levels_off(result: &ConfigurationResult) -> bool {
    tail_slope(result).is_some_and(|s| s > LEVELS_OFF_SLOPE)
}

/// Time to `target` measured within the sweep only: interpolated, or at most the first point;
/// `None` when the sweep does not reach it (never extrapolated).
pub(super) fn measured_reach(result: &ConfigurationResult, target: f64) -> Option<Reach> {
    match time_to_reach(result, target) {
        r @ (Reach::Interpolated(_) | Reach::AtMost(_)) => Some(r),
        Reach::Extrapolated(_) | Reach::NotReached => None,
    }
}

/// One estimator's time to [`ROUND_TARGET`] in words, for the integrator tables.
pub(super) fn reach_text(result: Option<&ConfigurationResult>) -> String {
    let Some(result) = result.filter(|r| !r.points.is_empty()) else { return "-".to_owned() };
    match measured_reach(result, ROUND_TARGET) {
        Some(Reach::AtMost(t)) => format!("<= {}", sig(t)),
        Some(r) => r.seconds().map_or_else(|| "-".to_owned(), sig),
        None => {
            let last = result.points.last().map_or(f64::NAN, |p| p.relative_rmse);
            if levels_off(result) {
                format!(
                    "does not reach {} (levels off at {})",
                    percent(ROUND_TARGET),
                    percent(last)
                )
            } else {
                format!(
                    "does not reach {} in the sweep ({} at the end)",
                    percent(ROUND_TARGET),
                    percent(last)
                )
            }
        }
    }
}

/// The estimators `auto` is measured against: light, path and bdpt, the camera estimators with
/// either sampler.
const AUTO_PEERS: [Configuration; 5] = [
    Configuration::Baseline,
    Configuration::Path,
    Configuration::PathSobol,
    Configuration::Bdpt,
    Configuration::BdptSobol,
];

/// Auto's time to [`ROUND_TARGET`] over the fastest of light, path and bdpt (with either
/// sampler) among those that converge to the reference's image ([`converges`]: a light tracer
/// that shows mirrors black is not a peer however soon it gets there), and the text of the ratio
/// column (`None` when the ratio cannot be measured).
pub(super) fn auto_ratio(scene: &SceneResult) -> (Option<f64>, String) {
    let result = |c: Configuration| scene.configurations.iter().find(|r| r.configuration == c);
    let reach = |c: Configuration| {
        result(c).and_then(|r| measured_reach(r, ROUND_TARGET)).and_then(Reach::seconds)
    };
    let fastest = AUTO_PEERS
        .into_iter()
        .filter(|&c| result(c).is_some_and(|r| converges(scene, r)))
        .filter_map(|c| reach(c).map(|t| (c, t)))
        .min_by(|a, b| a.1.total_cmp(&b.1));
    match (reach(Configuration::Auto), fastest) {
        (Some(auto), Some((c, best))) => {
            let ratio = auto / best;
            (Some(ratio), format!("{ratio:.2} (fastest: {})", c.integrator_label()))
        }
        (None, Some((c, _))) => {
            (Some(f64::INFINITY), format!("auto does not reach it; {} does", c.integrator_label()))
        }
        (_, None) => {
            let converging: Vec<&str> = AUTO_PEERS
                .into_iter()
                .filter(|&c| {
                    scene
                        .configurations
                        .iter()
                        .find(|r| r.configuration == c)
                        .is_some_and(|r| r.points.len() >= 3 && !levels_off(r))
                })
                .map(Configuration::integrator_label)
                .collect();
            let text = if converging.is_empty() {
                "none reaches it in the sweep".to_owned()
            } else {
                format!("none reaches it in the sweep; still falling: {}", converging.join(", "))
            };
            (None, text)
        }
    }
}

/// Three significant digits.
pub(super) fn sig(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let digits = (2 - v.abs().log10().floor() as i32).max(0) as usize;
    format!("{v:.digits$}")
}

pub(super) fn percent(v: f64) -> String {
    format!("{}%", sig(v * 100.0))
}

pub(super) fn beams_text(beams: u64) -> String {
    if beams.is_power_of_two() {
        format!("2^{}", beams.trailing_zeros())
    } else {
        beams.to_string()
    }
}

pub(super) fn slope_text(slope: Option<f64>) -> String {
    slope.map_or_else(|| "-".to_owned(), |s| format!("{s:.3}"))
}

/// The report as Markdown (what `accuracy.md` holds).
pub fn markdown(report: &AccuracyReport) -> String {
    let o = &report.options;
    let mut md = String::new();
    let _ = writeln!(md, "# What accuracy costs in time\n");
    let _ = writeln!(
        md,
        "Generated by `cargo xtask accuracy` (`spectrace_lab::accuracy::run`) on {} thread(s) \
         in {:.0} s; do not edit by hand. Reference: the scene as written (effects analysis \
         `auto`), rendered by an estimator that is unbiased on it (the path tracer where `auto` \
         picks it, BDPT everywhere else), at {} paths, seed {}, cached in `{}`. Sweep: {} to {} \
         paths (doubling; a camera integrator traces ceil(paths / pixels) samples per pixel), every \
         point with its own seed. Images are scaled to at most {} pixels wide. Error: relative RMSE \
         of XYZ over all pixels, `sqrt(sum |xyz - ref|^2 / sum |ref|^2)`; time: wall time of the \
         render alone (not loading). Plain Monte Carlo error falls as time^(-1/2): a flatter \
         slope means bias (the configuration converges to another image) or costs that do not \
         grow with the beams.\n",
        report.threads,
        report.total_seconds,
        beams_text(o.reference_beams),
        o.seed,
        o.cache_dir.display(),
        beams_text(o.start_beams),
        beams_text(o.start_beams << (o.steps.saturating_sub(1)).min(62)),
        o.max_width.map_or_else(|| "(unlimited)".to_owned(), |w| w.to_string()),
    );
    let _ = writeln!(md, "Configurations:\n");
    for &c in &o.configurations {
        let _ = writeln!(md, "- `{}`: {}.", c.name(), c.description());
    }
    let _ = writeln!(md, "\nWhich knobs act on which estimator: {KNOBS_BY_ESTIMATOR}.");
    summary_markdown(&mut md, report);
    estimate_summary_markdown(&mut md, report);
    measures_summary_markdown(&mut md, report);
    if o.configurations.iter().any(|c| c.integrator() != IntegratorChoice::Light) {
        integrators_markdown(&mut md, report);
        super::relmse::relmse_markdown(&mut md, report);
    }
    super::gains::gains_markdown(&mut md, report);
    let _ = writeln!(
        md,
        "\n![per-pixel relative error against wall time, log-log](accuracy.svg)\n\n\
         *Per-pixel relative error (`relmse`) against the reference, against wall time (log-log), \
         one panel per scene, one line per configuration; the legend gives each line's fitted \
         slope against time; dashed: slope -1/2; dotted: the 10% and 2% targets. The errors \
         include the reference's own noise (the section above gives it per scene): lines flatten \
         as they approach it.*\n"
    );
    for scene in &report.scenes {
        scene_markdown(&mut md, scene);
    }
    md
}

/// The reference's own relative RMSE, estimated from the configuration that renders with the
/// reference's estimator (its last sweep point): see [`sweep_reference_error`]. `None` when
/// that configuration was not swept.
pub(super) fn reference_noise(scene: &SceneResult) -> Option<(Configuration, f64)> {
    let (same, error) = sweep_reference_error(
        &scene.configurations,
        scene.reference.integrator,
        scene.reference.beams,
    )?;
    Some((same, error.energy?))
}

/// The sweep's reference's own error in `energy` (relative RMSE) and `relmse`, estimated from
/// the configuration that renders with the reference's estimator `integrator` (its last sweep
/// point): the reference carries that estimator's noise at its own path count `beams`, which
/// adds in quadrature to every measured error. With `e` the measured error at `n` paths and `N`
/// the reference's paths, `e^2 = s^2 (1/n + 1/N)` gives the reference's
/// `s / sqrt(N) = e / sqrt(1 + N / n)`. `mean` is not swept: `None`.
pub(super) fn sweep_reference_error(
    configurations: &[ConfigurationResult],
    integrator: IntegratorChoice,
    beams: u64,
) -> Option<(Configuration, ByMeasure)> {
    let same = sweep_configuration(integrator);
    let last = configurations.iter().find(|c| c.configuration == same)?.points.last()?;
    let factor = (1.0 + beams as f64 / last.beams.max(1) as f64).sqrt();
    let error = ByMeasure {
        relmse: (last.relmse > 0.0).then(|| last.relmse / factor),
        energy: Some(last.relative_rmse / factor),
        mean: None,
    };
    Some((same, error))
}

/// The swept configuration that renders with `integrator` and independent sampling: `path`,
/// `bdpt`, or the light tracer's `baseline`.
pub(super) fn sweep_configuration(integrator: IntegratorChoice) -> Configuration {
    match integrator {
        IntegratorChoice::Path => Configuration::Path,
        IntegratorChoice::Bdpt => Configuration::Bdpt,
        _ => Configuration::Baseline,
    }
}

/// The fastest configuration to `target` among those that apply, and its reach (measured, or
/// extrapolated along the fitted slope where no sweep point gets there; never for a
/// configuration whose error levels off).
pub(super) fn fastest_to(
    scene: &SceneResult,
    target: f64,
    converging_only: bool,
) -> Option<(Configuration, Reach)> {
    scene
        .configurations
        .iter()
        .filter(|c| c.not_applicable.is_none())
        .filter(|c| !converging_only || converges(scene, c))
        .filter_map(|c| {
            let reach = time_to_reach(c, target);
            reach.seconds().map(|t| (c.configuration, reach, t))
        })
        .min_by(|a, b| a.2.total_cmp(&b.2))
        .map(|(c, reach, _)| (c, reach))
}

/// Whether a configuration converges to the reference's image as far as the report can tell: no
/// bias known from the scene's features ([`known_bias`]) and a mean brightness within 2% of the
/// reference's.
pub(super) fn converges(scene: &SceneResult, result: &ConfigurationResult) -> bool {
    result.known_bias.is_none() && visibly_biased(scene, result.configuration).is_none()
}

/// Whether a configuration's image is visibly brighter or darker than the reference's at its
/// last sweep point (mean Y off by more than 2%): it converges to another image.
pub(super) fn visibly_biased(scene: &SceneResult, configuration: Configuration) -> Option<f64> {
    let result = scene.configurations.iter().find(|r| r.configuration == configuration)?;
    let ratio = result.points.last()?.mean_ratio;
    ((ratio - 1.0).abs() > 0.02).then_some(ratio)
}

/// The "fastest to" cell of the summary table.
pub(super) fn fastest_text(scene: &SceneResult, target: f64) -> String {
    let seconds = |r: &Option<(Configuration, Reach)>| r.and_then(|(_, r)| r.seconds());
    let converging = fastest_to(scene, target, true);
    let any = fastest_to(scene, target, false);
    let mut text = match converging {
        Some((c, reach)) => format!("`{}` {}", c.name(), reach.describe()),
        None => "none that converges reaches it".to_owned(),
    };
    if let Some((c, reach)) = any
        && seconds(&any) < seconds(&converging).or(Some(f64::INFINITY))
    {
        let why = scene
            .configurations
            .iter()
            .find(|r| r.configuration == c)
            .and_then(|r| r.known_bias.clone())
            .or_else(|| visibly_biased(scene, c).map(|r| format!("mean Y {r:.2}x the reference")))
            .unwrap_or_default();
        text += &format!("; sooner but biased: `{}` {} ({why})", c.name(), reach.describe());
    }
    text
}

/// Auto's time to `target` over the fastest configuration's, as the summary table's cell
/// ("extrapolated" when either time is).
pub(super) fn auto_vs_fastest_text(scene: &SceneResult, target: f64) -> String {
    let Some(auto) = scene.configurations.iter().find(|r| r.configuration == Configuration::Auto)
    else {
        return "- (auto not swept)".to_owned();
    };
    let Some((fastest, best)) = fastest_to(scene, target, true) else { return "-".to_owned() };
    let reach = time_to_reach(auto, target);
    match (reach.seconds(), best.seconds()) {
        (Some(a), Some(b)) => {
            let extrapolated =
                matches!(reach, Reach::Extrapolated(_)) || matches!(best, Reach::Extrapolated(_));
            let note = if fastest == Configuration::Auto {
                " (auto is the fastest)"
            } else if extrapolated {
                " (extrapolated)"
            } else {
                ""
            };
            format!("{:.2}{note}", a / b.max(1e-300))
        }
        _ => "auto does not reach it".to_owned(),
    }
}

/// The summary: per scene the fastest configuration to each of [`TARGETS`] and auto's time over
/// its time.
pub(super) fn summary_markdown(md: &mut String, report: &AccuracyReport) {
    let [coarse, fine] = TARGETS.map(|t| format!("{}%", t * 100.0));
    let _ = writeln!(
        md,
        "\n## Fastest to {coarse} and to {fine}\n\n\
         Per scene, the configuration that reaches {coarse} and {fine} relative RMSE soonest \
         among those that converge to the reference's image, and auto's time to the same error \
         over that time. A configuration converges unless a bias is known from the scene (a \
         piecewise-constant SPD is another spectrum; the light tracer shows mirrors and glass \
         seen by the camera black, flagged wherever the scene has specular surfaces; the path \
         tracer misses thin lasers, lines and caustics of delta lights) or its mean brightness is \
         more than 2% off the reference's; a biased configuration that gets there sooner is \
         named after it (its image is wrong, the error target is just coarse). Times are \
         interpolated between sweep points (`<=` when the first point is already below the \
         target); `~... (extrapolated)` marks a time extrapolated along the configuration's \
         fitted slope beyond the sweep (never for one whose error levels off). Reaching {fine} \
         takes about 25 times the effort of {coarse}, so most {fine} times are extrapolated. \
         Every measured error includes the reference's own noise in quadrature (its column, \
         estimated from the reference's estimator in the sweep): a target near or below it \
         cannot be measured, only extrapolated from the slope of the larger errors.\n"
    );
    let _ = writeln!(
        md,
        "| scene | pixels | auto picks | reference's noise | fastest to {coarse} | auto / fastest | fastest to {fine} | auto / fastest |"
    );
    let _ = writeln!(md, "|---|---|---|---:|---|---:|---|---:|");
    for scene in &report.scenes {
        let _ = writeln!(
            md,
            "| {} | {}x{} | {} | {} | {} | {} | {} | {} |",
            scene.name,
            scene.width,
            scene.height,
            scene.auto_picks.name(),
            reference_noise(scene).map_or_else(|| "-".to_owned(), |(_, n)| percent(n)),
            fastest_text(scene, ROUND_TARGET),
            auto_vs_fastest_text(scene, ROUND_TARGET),
            fastest_text(scene, FINE_TARGET),
            auto_vs_fastest_text(scene, FINE_TARGET),
        );
    }
    let _ = writeln!(md);
}

/// The true error of a check's render with the reference's own noise taken out (they add in
/// quadrature): `sqrt(true^2 - noise^2)`, `None` when the noise is as large as the error.
pub(super) fn corrected_truth(scene: &SceneResult, check: &EstimateCheck) -> Option<f64> {
    if check.reference_paths > 0 {
        // The check's own reference, with its own estimate of its error.
        return check.corrected_truth(check.measure);
    }
    let noise = reference_noise(scene).map_or(0.0, |(_, n)| n);
    let d = check.true_error.powi(2) - noise * noise;
    (d > 0.0).then(|| d.sqrt())
}

/// One scene's estimate check: the pilot's predictions per estimator, and the render to the
/// target against the truth.
pub(super) fn estimate_vs_truth_markdown(md: &mut String, scene: &SceneResult) {
    let Some(check) = &scene.estimate_check else { return };
    let _ = writeln!(
        md,
        "\n### Estimate against truth\n\n\
         `spectrace estimate` (a pilot per estimator) predicts the time to {:.0}% `{}`; then a \
         render with `--target-error {}` by `{}` (auto's pick, capped at \
         {ESTIMATE_CAP_SECONDS:.0} s) ends with its own error estimate, compared with its error \
         against the reference ({}).\n",
        check.target * 100.0,
        check.measure.name(),
        check.target,
        check.integrator.name(),
        reference_text(scene, check),
    );
    let _ = writeln!(md, "{}", spectrace_renderer::pilot::markdown(&check.pilot));
    let truth = corrected_truth(scene, check);
    let _ = writeln!(
        md,
        "The render: {} batches in {} s ({}), \
         estimated error {}, error against the reference {} ({} with the reference's own noise \
         taken out): estimate / truth = {}.",
        check.batches,
        sig(check.measured_seconds),
        if check.reached { "target reached" } else { "stopped by the time cap" },
        check.estimated_error.map_or("-".to_owned(), percent),
        percent(check.true_error),
        truth.map_or("below the reference's noise".to_owned(), percent),
        match (check.estimated_error, truth) {
            (Some(e), Some(t)) => format!("{:.2}", e / t),
            _ => "-".to_owned(),
        }
    );
}

/// Which reference a check's truth is measured against.
fn reference_text(scene: &SceneResult, check: &EstimateCheck) -> String {
    if check.reference_paths > scene.reference.beams {
        format!(
            "a deeper one for this check, {} paths, whose own estimated error {} is taken out in \
             quadrature",
            check.reference_paths,
            check.reference_error.get(check.measure).map_or("-".to_owned(), percent)
        )
    } else {
        format!("the sweep's, {} paths", scene.reference.beams)
    }
}

/// The estimate check of every scene in one table.
pub(super) fn estimate_summary_markdown(md: &mut String, report: &AccuracyReport) {
    let checked: Vec<(&SceneResult, &EstimateCheck)> =
        report.scenes.iter().filter_map(|s| s.estimate_check.as_ref().map(|c| (s, c))).collect();
    if checked.is_empty() {
        return;
    }
    let _ = writeln!(
        md,
        "\n## Does the renderer know its own error?\n\n\
         Per scene, a render with `--target-error {target}` in `{measure}` (the renderer's default \
         measure) by the estimator auto picks (capped at {ESTIMATE_CAP_SECONDS:.0} s): its own \
         final error estimate (from the spread between its chunks) against its true error \
         (against a reference of at least {CHECK_REFERENCE_FACTOR} times its paths, the sweep's \
         or a deeper one rendered for the check, with that reference's own estimated error taken \
         out in quadrature), and its time against the time `spectrace estimate` predicted from a \
         pilot before it. The goals: estimate / truth within 20% and measured / predicted time \
         within 35%. Last column: the pilot's recommendation beside auto's pick.\n\n\
         | scene | estimator | paths | reference paths | estimated error | true error | \
         estimate / truth | predicted time | measured time | measured / predicted | pilot \
         recommends |\n|---|---|---:|---:|---|---|---|---|---|---|---|",
        target = checked[0].1.target,
        measure = checked[0].1.measure.name(),
    );
    for (scene, check) in checked {
        let truth = corrected_truth(scene, check);
        let predicted = check.prediction().and_then(|p| p.predicted_seconds);
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} s{} | {} | {} |",
            scene.name,
            check.integrator.name(),
            check.paths,
            check.reference_paths.max(scene.reference.beams),
            check.estimated_error.map_or("-".to_owned(), percent),
            truth.map_or("below the reference's noise".to_owned(), percent),
            match (check.estimated_error, truth) {
                (Some(e), Some(t)) => format!("{:.2}", e / t),
                _ => "-".to_owned(),
            },
            predicted.map_or("-".to_owned(), |t| format!("{} s", sig(t))),
            sig(check.measured_seconds),
            if check.reached { "" } else { " (cap; target not reached)" },
            match predicted {
                Some(p) if check.reached => format!("{:.2}", check.measured_seconds / p),
                _ => "-".to_owned(),
            },
            check.pilot.recommended.as_deref().unwrap_or("-")
        );
    }
}

/// The estimate checks' renders in every error measure: estimated against true.
pub(super) fn measures_summary_markdown(md: &mut String, report: &AccuracyReport) {
    let checked: Vec<(&SceneResult, &EstimateCheck)> = report
        .scenes
        .iter()
        .filter_map(|s| s.estimate_check.as_ref().map(|c| (s, c)))
        .filter(|(_, c)| c.paths > 0)
        .collect();
    if checked.is_empty() {
        return;
    }
    let _ = writeln!(
        md,
        "\n## The same renders in every error measure\n\n\
         The renders of the table above (stopped by the `{measure}` estimate), with their own \
         final estimate and their true error (against the reference, its own estimated error \
         taken out in quadrature where it was rendered for the check) in each measure the \
         renderer reports: `relmse` (per-pixel relative error, the renderer's default), `energy` \
         (relative RMSE weighted by energy, dominated by the brightest pixels) and `mean` (RMSE \
         over the image's mean), with estimate / truth in brackets.\n\n\
         | scene | estimator | paths / reference paths | relmse: estimated, true | energy: \
         estimated, true | mean: estimated, true |\n|---|---|---|---|---|---|",
        measure = checked[0].1.measure.name(),
    );
    for (scene, check) in checked {
        let cell = |m: ErrorMeasure| {
            let t = if check.reference_paths > 0 {
                check.corrected_truth(m)
            } else {
                check.true_by_measure.get(m)
            };
            let e = check.estimated_by_measure.get(m);
            format!(
                "{}, {} ({})",
                e.map_or("-".to_owned(), percent),
                t.map_or("-".to_owned(), percent),
                match (e, t) {
                    (Some(e), Some(t)) if t > 0.0 => format!("{:.2}", e / t),
                    _ => "-".to_owned(),
                }
            )
        };
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} | {} |",
            scene.name,
            check.integrator.name(),
            sig(check.paths as f64 / check.reference_paths.max(scene.reference.beams).max(1) as f64),
            cell(ErrorMeasure::RelMse),
            cell(ErrorMeasure::Energy),
            cell(ErrorMeasure::Mean),
        );
    }
}

/// The estimator summary: time to [`ROUND_TARGET`] per scene and estimator, and auto's ratio.
pub(super) fn integrators_markdown(md: &mut String, report: &AccuracyReport) {
    let _ = writeln!(
        md,
        "\n## Which estimator reaches {target} first\n\n\
         Seconds to reach {target} relative RMSE for each estimator (interpolated between sweep \
         points; `<=` when the first point is already below it). An estimator that is biased on \
         a scene (the light tracer where the camera sees mirrors or glass, the path tracer where \
         lights are skies, lasers or lines) levels off: it is reported as not reaching the target, \
         never extrapolated. The columns light, path and bdpt sample independently. The last \
         columns are auto's time (with the default sampler: Sobol points for path and bdpt) over \
         the fastest of light, path, path_sobol, bdpt and bdpt_sobol among those that converge \
         to the reference's image (a light tracer that shows mirrors black is not auto's peer), \
         measured in the same run (auto renders with its own seeds, so a ratio near 1 is timing \
         and noise); `auto` is a good pick when it is within {AUTO_FACTOR}x.\n",
        target = percent(ROUND_TARGET)
    );
    let _ = writeln!(
        md,
        "| scene | pixels | reference | auto picks | light | path | bdpt | auto | auto / fastest | within {AUTO_FACTOR}x |"
    );
    let _ = writeln!(md, "|---|---|---|---|---:|---:|---:|---:|---:|---|");
    for scene in &report.scenes {
        let find = |c: Configuration| scene.configurations.iter().find(|r| r.configuration == c);
        let (ratio, ratio_text) = auto_ratio(scene);
        let within = match ratio {
            Some(r) if r <= AUTO_FACTOR => "yes",
            Some(_) => "**no**",
            None => "-",
        };
        let _ = writeln!(
            md,
            "| {} | {}x{} | {} | {} | {} | {} | {} | {} | {ratio_text} | {within} |",
            scene.name,
            scene.width,
            scene.height,
            scene.reference.integrator.name(),
            scene.auto_picks.name(),
            reach_text(find(Configuration::Baseline)),
            reach_text(find(Configuration::Path)),
            reach_text(find(Configuration::Bdpt)),
            reach_text(find(Configuration::Auto)),
        );
    }
    let _ = writeln!(md, "\nWhy auto picks what it picks:\n");
    for scene in &report.scenes {
        let _ = writeln!(md, "- `{}`: {}.", scene.name, scene.auto_reason);
    }
    let _ = writeln!(md);
}

pub(super) fn scene_markdown(md: &mut String, scene: &SceneResult) {
    let r = &scene.reference;
    let _ = writeln!(md, "## {} (`{}`)\n", scene.name, scene.scene);
    let _ = writeln!(
        md,
        "{}x{} pixels; {}. Auto picks {}. Reference: {} paths by {}, {} s{}.\n",
        scene.width,
        scene.height,
        scene.effects_summary,
        scene.auto_reason,
        beams_text(r.beams),
        r.integrator.name(),
        sig(r.seconds),
        if r.cached { " (read from the cache)" } else { "" },
    );
    let baseline = scene.configurations.iter().find(|c| c.configuration == Configuration::Baseline);
    if let Some((same, noise)) = reference_noise(scene) {
        let _ = writeln!(
            md,
            "The reference's own noise is about {} (`{}`'s last error scaled to the reference's \
             paths); errors near it are inflated by it.\n",
            percent(noise),
            same.name()
        );
    }
    if scene.configurations.iter().any(|c| c.configuration.integrator() != IntegratorChoice::Light)
    {
        let _ = writeln!(
            md,
            "| estimator | seconds to {} | slope vs time (last 3 points) |",
            percent(ROUND_TARGET)
        );
        let _ = writeln!(md, "|---|---:|---:|");
        for c in Configuration::INTEGRATORS {
            let Some(result) = scene.configurations.iter().find(|r| r.configuration == c) else {
                continue;
            };
            let _ = writeln!(
                md,
                "| {} | {} | {} |",
                c.integrator_label(),
                reach_text(Some(result)),
                slope_text(tail_slope(result))
            );
        }
        let _ = writeln!(md, "\nauto / fastest: {}.\n", auto_ratio(scene).1);
    }
    let _ =
        writeln!(md, "| configuration | paths | seconds | relative RMSE | mean Y / reference |");
    let _ = writeln!(md, "|---|---:|---:|---:|---:|");
    for c in &scene.configurations {
        for p in &c.points {
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} | {:.3} |",
                c.configuration.name(),
                beams_text(p.beams),
                sig(p.seconds),
                percent(p.relative_rmse),
                p.mean_ratio
            );
        }
    }
    let _ = writeln!(
        md,
        "\n| configuration | what changed | slope vs time | slope vs beams | expected | error x sqrt(seconds) at the last point |"
    );
    let _ = writeln!(md, "|---|---|---:|---:|---:|---:|");
    for c in &scene.configurations {
        match &c.not_applicable {
            Some(reason) => {
                let _ = writeln!(
                    md,
                    "| {} | not applicable: {} | - | - | {EXPECTED_SLOPE} | - |",
                    c.configuration.name(),
                    reason.replace('|', "/").replace('\n', " ")
                );
            }
            None => {
                let merit = c
                    .points
                    .last()
                    .map_or_else(|| "-".to_owned(), |p| sig(p.relative_rmse * p.seconds.sqrt()));
                let _ = writeln!(
                    md,
                    "| {} | {} | {} | {} | {EXPECTED_SLOPE} | {merit} |",
                    c.configuration.name(),
                    match (&c.known_bias, c.changed.is_empty()) {
                        (Some(bias), true) => format!("- (biased: {bias})"),
                        (Some(bias), false) => format!("{} (biased: {bias})", c.changed),
                        (None, true) => "-".to_owned(),
                        (None, false) => c.changed.clone(),
                    },
                    slope_text(c.slope_vs_time),
                    slope_text(c.slope_vs_beams),
                );
            }
        }
    }
    let _ = writeln!(md);
    let mut targets = Vec::new();
    if let Some(last) = baseline.and_then(|b| b.points.last()) {
        targets.push((last.relative_rmse, "the smallest error the baseline reached"));
    }
    targets.push((ROUND_TARGET, "a round target"));
    targets.push((FINE_TARGET, "the fine target"));
    for (target, what) in targets {
        let applicable: Vec<_> =
            scene.configurations.iter().filter(|c| c.not_applicable.is_none()).collect();
        let reaches: Vec<_> = applicable.iter().map(|c| (c, time_to_reach(c, target))).collect();
        let fastest = reaches
            .iter()
            .filter_map(|(c, r)| r.seconds().map(|t| (c, *r, t)))
            .min_by(|a, b| a.2.total_cmp(&b.2));
        let times = reaches
            .iter()
            .map(|(c, r)| format!("`{}` {}", c.configuration.name(), r.describe()))
            .collect::<Vec<_>>()
            .join(", ");
        match fastest {
            Some((c, reach, best)) => {
                let ties: Vec<String> = reaches
                    .iter()
                    .filter(|(o, r)| {
                        o.configuration != c.configuration
                            && r.seconds().is_some_and(|t| t <= best * TIE_FACTOR)
                    })
                    .map(|(o, _)| format!("`{}`", o.configuration.name()))
                    .collect();
                let tie = if ties.is_empty() {
                    String::new()
                } else {
                    format!(
                        ", tied within timing noise (less than {:.0}% slower) with {}",
                        (TIE_FACTOR - 1.0) * 100.0,
                        ties.join(" and ")
                    )
                };
                let _ = writeln!(
                    md,
                    "To reach {} ({what}), **`{}`** is fastest{}{tie}: {times}.\n",
                    percent(target),
                    c.configuration.name(),
                    if matches!(reach, Reach::Extrapolated(_)) {
                        " (by extrapolation beyond the sweep)"
                    } else {
                        ""
                    },
                );
            }
            None => {
                let _ = writeln!(
                    md,
                    "No configuration reaches {} ({what}) within the sweep: {times}.\n",
                    percent(target)
                );
            }
        }
    }
    estimate_vs_truth_markdown(md, scene);
}
