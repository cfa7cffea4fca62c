//! The live error estimate, render-to-target and the pilot's prediction, on shipped scenes at
//! small size: the estimate against the true error (measured from the spread of independent
//! renders), work predicted by the pilot against the error it gives, targets with shards and
//! merges, the error image, and bad input.

use std::path::Path;

use serde_json::Value;
use spectrace_renderer::pilot::{EstimateOptions, estimate};
use spectrace_renderer::{
    ErrorImage, PartialFilm, RenderOptions, Scene, merge_parts, render_in_memory, render_scene,
};
use spectrace_tracer::{ErrorMeasure, IntegratorChoice, MIN_BATCHES, SamplerKind, relative_error};

/// A shipped scene at `width x height` pixels.
pub(crate) fn small(name: &str, width: u32, height: u32) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes").join(name);
    let mut v: Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    v["camera"]["width"] = Value::from(width);
    v["camera"]["height"] = Value::from(height);
    Scene::from_json(&v.to_string(), &path).unwrap_or_else(|e| panic!("{name}: {e}"))
}

fn options(integrator: IntegratorChoice, effort: u64, seed: u64) -> RenderOptions {
    RenderOptions {
        beams: Some(effort),
        seed: Some(seed),
        threads: Some(2),
        integrator: Some(integrator),
        ..RenderOptions::default()
    }
}

/// How many times the samples of the renders under test the reference of
/// [`truth_and_estimate`] gets.
const REFERENCE_EFFORT: u64 = 16;

/// The true relative error of one render in each measure ([`ErrorMeasure::ALL`]'s order)
/// against a converged reference, as the measures define it: `k` independent renders of
/// `effort`, each measured against one render of [`REFERENCE_EFFORT`] times the effort; the mean
/// of their squared errors, less the reference's own share of the difference's variance
/// (`1 / REFERENCE_EFFORT` of a render's), square-rooted. Beside it the mean over the renders of
/// their own estimates in that measure.
fn truth_and_estimate(
    s: &Scene,
    integrator: IntegratorChoice,
    effort: u64,
    k: u64,
) -> [(f64, f64); 3] {
    let renders: Vec<_> = (0..k)
        .map(|seed| render_in_memory(s, &options(integrator, effort, 9000 + seed)).unwrap())
        .collect();
    let reference =
        render_in_memory(s, &options(integrator, effort * REFERENCE_EFFORT, 8999)).unwrap().image;
    let keep = REFERENCE_EFFORT as f64 / (REFERENCE_EFFORT + 1) as f64;
    ErrorMeasure::ALL.map(|measure| {
        let squared: f64 = renders
            .iter()
            .map(|r| relative_error(measure, &r.image, &reference).unwrap().powi(2))
            .sum();
        let truth = (squared / k as f64 * keep).sqrt();
        let estimated = renders
            .iter()
            .map(|r| {
                let e = r.output.estimate(measure).unwrap();
                assert!(e.batches >= MIN_BATCHES, "{} batches", e.batches);
                e.relative_error.unwrap()
            })
            .sum::<f64>()
            / k as f64;
        (truth, estimated)
    })
}

/// On shipped scenes with the estimator `auto` picks, the estimate is within 20% of the true
/// error in the `energy` and `mean` measures even at 32 samples per pixel, far from
/// converged. Eight
/// renders of 32 samples per pixel: the truth from their spread has 7 degrees of freedom per
/// pixel over 1,536 pixels (a few percent of noise), the estimates 31 each. Sky is BDPT with
/// hero wavelengths (measured 0.0857 true, 0.0884 estimated in `energy`), prism BDPT with one
/// wavelength per sample (dispersive). The `relmse` estimate is printed beside the truth, not
/// asserted: at these counts most pixels are 20% to 100% noisy, where no estimate from the
/// render's own batches is within 20% (its promise is near the targets users ask for, tested
/// below); `SPECTRACE_ESTIMATE_EFFORT=K` renders K times the samples.
#[test]
fn the_estimate_is_within_20_percent_of_the_true_error_on_shipped_scenes() {
    for (name, integrator) in [
        ("fading_spot.json", IntegratorChoice::Path),
        ("cornell.json", IntegratorChoice::Path),
        ("prism.json", IntegratorChoice::Bdpt),
        ("spot_torus.json", IntegratorChoice::Light),
        ("sky.json", IntegratorChoice::Bdpt),
    ] {
        let mut s = small(name, 48, 32);
        // Independent passes: the estimate's promise (Sobol camera passes' is an upper bound;
        // the Sobol light tracer's, below, is the error itself).
        s.settings.sampler = SamplerKind::Independent;
        // 32 samples per pixel, or 32 chunks of beams.
        let effort = if integrator == IntegratorChoice::Light { 32 << 14 } else { 32 * 48 * 32 };
        let effort = effort * effort_factor();
        let results = truth_and_estimate(&s, integrator, effort, 8);
        assert_within_20_percent(&format!("{name} ({integrator:?})"), results);
    }
}

/// Prints each measure's truth and estimate ([`truth_and_estimate`]'s `results`) and asserts
/// the `energy` and `mean` estimates within 20% of the truth (relmse's estimate is asserted
/// near 10%, below).
fn assert_within_20_percent(label: &str, results: [(f64, f64); 3]) {
    for (measure, (truth, estimated)) in ErrorMeasure::ALL.into_iter().zip(results) {
        let m = measure.name();
        eprintln!("{label} ({m}): true error {truth:.4}, estimated {estimated:.4}");
        assert!(
            measure == ErrorMeasure::RelMse || (estimated / truth - 1.0).abs() < 0.2,
            "{label} ({m}): estimated {estimated}, true {truth}"
        );
    }
}

/// The light tracer with Sobol points (what `auto` draws where beams stop after a diffuse hit):
/// each chunk of beams is its own independently scrambled sequence, so chunks stay independent
/// batches and the estimate is the error itself, not an upper bound. The fading spot (its beams
/// stop after the floor) at 48 x 32, 32 chunks of beams, eight renders as above: the estimate
/// within 20% of the truth in `energy` and `mean`.
#[test]
fn the_sobol_light_tracers_estimate_is_within_20_percent_of_the_true_error() {
    let mut s = small("fading_spot.json", 48, 32);
    s.settings.sampler = SamplerKind::Sobol;
    let effort = (32 << 14) * effort_factor();
    let results = truth_and_estimate(&s, IntegratorChoice::Light, effort, 8);
    assert_within_20_percent("fading_spot (light, sobol)", results);
}

/// The promise at small scale: a render to `--target-error 0.1` in the default measure
/// (`relmse`) ends with a true relmse against a converged reference ([`REFERENCE_EFFORT`] times
/// its items) within 20% of its estimate, and not above 10% by more than 20%. Three renders per
/// scene at 16x12 pixels, their squared true errors averaged. Measured (estimated, true): spot
/// and torus with the light tracer 0.0983, 0.1003; sky with BDPT and hero wavelengths 0.0766,
/// 0.0803 (one render went on to 3.9%, see the assertion). Every shipped scene at 96 px is in
/// the accuracy report (`cargo xtask accuracy`); the fading spot at full size, whose hard-edged
/// spot lights edge pixels too rarely for any estimate to follow one render's truth, is
/// described in scenes/README.md.
#[test]
fn a_render_to_10_percent_relmse_is_10_percent_from_the_truth() {
    for (name, integrator) in
        [("spot_torus.json", IntegratorChoice::Light), ("sky.json", IntegratorChoice::Bdpt)]
    {
        let (mut squared, mut estimated) = (0.0, 0.0);
        let seeds = 9100..9103;
        for seed in seeds.clone() {
            let (truth, e) = render_to_10_percent(name, integrator, seed);
            squared += truth * truth;
            estimated += e;
        }
        let k = seeds.count() as f64;
        let (truth, estimated) = ((squared / k).sqrt(), estimated / k);
        eprintln!("{name} ({integrator:?}): estimated {estimated:.4}, true {truth:.4}");
        assert!((estimated / truth - 1.0).abs() < 0.2, "{name}: {estimated} vs {truth}");
        // Never more than 20% above the target. It may end below: a render goes on while its
        // estimate is not trusted (its own uncertainty above 10%), and on the sky's 192 pixels
        // a firefly in one half keeps it so (at 150 samples per pixel the estimate scattered
        // by 17% over ten seeds, and claimed 15%): measured 0.0924, 0.0385 and 0.0991.
        assert!(truth < 0.12, "{name}: true {truth}");
        if name == "spot_torus.json" {
            assert!(truth > 0.08, "{name}: true {truth}");
        }
    }
}

/// One render of shipped scene `name` to `--target-error 0.1` (relmse): its true relmse and
/// its estimate.
fn render_to_10_percent(name: &str, integrator: IntegratorChoice, seed: u64) -> (f64, f64) {
    let s = small(name, 16, 12);
    let target =
        RenderOptions { target_error: Some(0.1), beams: None, ..options(integrator, 0, seed) };
    let out = render_in_memory(&s, &target).unwrap();
    let e = out.output.estimate(ErrorMeasure::default()).unwrap();
    assert_eq!(e.measure, ErrorMeasure::RelMse);
    assert!(e.is_trusted(), "{name}: {e:?}");
    let mut reference = small(name, 16, 12);
    reference.settings.sampler = SamplerKind::Independent;
    let items = out.output.beams * REFERENCE_EFFORT;
    let reference = render_in_memory(&reference, &options(integrator, items, seed + 500)).unwrap();
    let keep = REFERENCE_EFFORT as f64 / (REFERENCE_EFFORT + 1) as f64;
    let error = relative_error(ErrorMeasure::RelMse, &out.image, &reference.image).unwrap();
    let truth = error * keep.sqrt();
    let estimated = e.relative_error.unwrap();
    eprintln!(
        "{name} seed {seed}: {} items, estimated {estimated:.4}, true {truth:.4}",
        out.output.beams
    );
    (truth, estimated)
}

/// `SPECTRACE_ESTIMATE_EFFORT` (a whole number, default 1): the estimate test's effort factor.
fn effort_factor() -> u64 {
    std::env::var("SPECTRACE_ESTIMATE_EFFORT").ok().and_then(|v| v.parse().ok()).unwrap_or(1).max(1)
}

/// Under Sobol points (the camera estimators' default for fixed efforts and time budgets) a
/// pixel's passes are one stratified sequence, not independent batches: the estimate measures
/// the independent sampler's error, an upper bound of the true one. Same renders as above.
/// Measured estimated / true: 1.92 (Cornell box, path; its independent renders: 0.1293 true
/// error, 0.0695 under Sobol), 1.65 (laser, BDPT with one wavelength), 1.40 (plastic, BDPT with
/// hero wavelengths) and 1.01 (sky, BDPT with hero wavelengths). Asserted above 1.2 where Sobol
/// points gain at 32 samples per pixel: the estimate bounds the error from above with a margin
/// larger than its own noise (the 20% allowed above), which only holds if Sobol's true error is
/// well below the independent sampler's. On the sky they gain little at 32 samples per pixel
/// (with one wavelength per sample they took its colour noise, 1.68; hero wavelengths now do),
/// so there the assertion is only that the estimate does not fall below the truth by more than
/// its own noise.
#[test]
fn under_sobol_points_the_estimate_is_an_upper_bound() {
    for (name, integrator, bound) in [
        ("cornell.json", IntegratorChoice::Path, 1.2),
        ("laser.json", IntegratorChoice::Bdpt, 1.2),
        ("plastic.json", IntegratorChoice::Bdpt, 1.2),
        ("sky.json", IntegratorChoice::Bdpt, 0.8),
    ] {
        let mut s = small(name, 48, 32);
        s.settings.sampler = SamplerKind::Auto;
        let effort = 32 * 48 * 32;
        let (truth, estimated) = truth_and_estimate(&s, integrator, effort, 8)[1];
        eprintln!(
            "{name} ({integrator:?}, sobol): true error {truth:.4}, estimated {estimated:.4}"
        );
        assert!(estimated / truth > bound, "{name}: estimated {estimated}, true {truth}");
    }
}

/// The pilot's predicted work gives the target: rendering exactly the predicted number of
/// items ends with an estimate within 20% of the target (the estimate itself is checked
/// against the truth above), in the default `relmse` measure, at 10% for the path tracer and 7%
/// for the light tracer (whose pilot alone reaches 10% since its wavelength bundles are
/// stratified together: pilot errors 0.097 to 0.102). Five pilot seeds (11 to 14 and the
/// default) predicted 51,945 to 60,317 items for the path tracer (estimates 0.098 to 0.108 after
/// them) and 502,378 to 559,950 for the light tracer (0.071 to 0.076); before the pilot took
/// slope -1/2 in `relmse` and the denominators' floor, 68,000 to 260,000 for the path tracer.
#[test]
fn the_work_the_pilot_predicts_reaches_the_target() {
    let s = small("fading_spot.json", 48, 32);
    for (integrator, target) in [(IntegratorChoice::Path, 0.1), (IntegratorChoice::Light, 0.07)] {
        let report = estimate(
            &s,
            &EstimateOptions {
                target_error: target,
                pilot_seconds: 0.2,
                threads: 2,
                // Reproducible: 8 rounds of 2 chunks whatever the machine's speed.
                fixed_rounds: Some(7),
                integrators: vec![integrator],
                error_measure: Some(ErrorMeasure::RelMse),
                ..EstimateOptions::default()
            },
        )
        .unwrap();
        let p = &report.predictions[0];
        assert_eq!(p.integrator, integrator.name());
        assert!(p.pilot_error.unwrap() > target, "the pilot should not reach the target");
        let items = p.predicted_items.unwrap().ceil() as u64;
        let out = render_in_memory(&s, &options(integrator, items, 77)).unwrap();
        let e = out.output.estimate(ErrorMeasure::RelMse).unwrap().relative_error.unwrap();
        eprintln!("{integrator:?}: predicted {items} items for {target}: estimate {e:.4}");
        assert!((e / target - 1.0).abs() < 0.2, "{integrator:?}: {e} after {items} items");
        assert!(p.predicted_seconds.unwrap() > 0.0 && p.relative_uncertainty.is_finite());
    }
}

fn sidecar(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// `--target-error` stops once the estimate (from at least 16 batches) reaches the target; the
/// sidecar says so; `output.error_image` writes the standard error beside the image.
#[test]
fn a_render_to_a_target_stops_there_and_writes_its_error_image() {
    let mut s = small("fading_spot.json", 48, 32);
    s.output.error_image = ErrorImage::Absolute;
    let out = crate::rendering::temp_dir("estimate-target");
    let report = render_scene(
        &s,
        &RenderOptions {
            target_error: Some(0.1),
            threads: Some(2),
            integrator: Some(IntegratorChoice::Light),
            out_dir: out.clone(),
            ..RenderOptions::default()
        },
    )
    .unwrap();
    let e = report.error_estimate.clone().unwrap();
    assert_eq!(e.target_error, Some(0.1));
    assert_eq!(e.target_reached, Some(true));
    // In the default measure, relmse.
    assert_eq!(e.measure, "relmse");
    assert!(e.relative_error.unwrap() <= 0.1 && e.batches >= MIN_BATCHES, "{e:?}");
    // Not far past it: the render stops within a few chunks of reaching it (the checks are
    // spaced in wall time, so a loaded machine may overshoot; 0.05 would be 4x the work).
    assert!(e.relative_error.unwrap() > 0.05, "{e:?}");
    let json = sidecar(&out.join("fading_spot.json"));
    assert_eq!(json["error_estimate"]["target_reached"], Value::Bool(true));
    let error = exr::prelude::read_first_rgba_layer_from_file(
        out.join("fading_spot.error.exr"),
        |size, _| vec![[0f32; 3]; size.0 * size.1],
        |px: &mut Vec<[f32; 3]>, pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            px[pos.y() * 48 + pos.x()] = [r, g, b];
        },
    )
    .unwrap();
    let px = &error.layer_data.channel_data.pixels;
    assert_eq!(error.layer_data.size.0, 48);
    assert!(px.iter().flatten().all(|v| v.is_finite() && *v >= 0.0));
    assert!(px.iter().flatten().any(|v| *v > 0.0));
    assert!(report.outputs.iter().any(|f| f.ends_with("fading_spot.error.exr")));
}

/// Each shard stops on its share of the target (the target times sqrt(N)); `merge` reports the
/// merged estimate, which reaches the target.
#[test]
fn shards_stop_on_their_share_and_the_merge_reports_the_merged_estimate() {
    let s = small("fading_spot.json", 48, 32);
    let out = crate::rendering::temp_dir("estimate-shards");
    let target = 0.1;
    let mut parts = Vec::new();
    let mut batches = 0;
    for k in 0..2 {
        let r = render_scene(
            &s,
            &RenderOptions {
                target_error: Some(target),
                threads: Some(1),
                shard: Some((k, 2)),
                integrator: Some(IntegratorChoice::Light),
                out_dir: out.clone(),
                ..RenderOptions::default()
            },
        )
        .unwrap();
        let e = r.error_estimate.unwrap();
        assert!(e.relative_error.unwrap() <= target * 2f64.sqrt(), "{e:?}");
        batches += e.batches;
        parts.push(out.join(format!("fading_spot.part-{k}-of-2.bin")));
    }
    let merged = merge_parts(&parts, &out.join("merged")).unwrap();
    let e = merged.error_estimate.unwrap();
    assert_eq!(e.batches, batches);
    assert!(e.relative_error.unwrap() <= target * 1.05, "{e:?}");
    assert_eq!(e.target_reached, Some(e.relative_error.unwrap() <= target));
    // A part whose moments do not match its film is refused, naming the field.
    let mut part = PartialFilm::read(&parts[0]).unwrap();
    part.output.moments = Some(spectrace_tracer::Moments::new(3, 3).unwrap());
    let bytes = part.encode().unwrap();
    let err = PartialFilm::decode(&bytes).unwrap_err();
    assert!(err.contains("output.moments"), "{err}");
}

/// Bad targets are refused with the field and the cause, in scene files and on the command
/// line.
#[test]
fn bad_targets_are_refused_naming_the_field() {
    for bad in ["0", "-0.1", "1", "1e-400", "\"x\""] {
        let mut v: Value = serde_json::from_str(crate::rendering::POINT_OVER_PLANE).unwrap();
        v["settings"]["target_error"] = serde_json::from_str(bad).unwrap_or(Value::Null);
        let json = v.to_string().replace("null", bad);
        let err = Scene::from_json(&json, Path::new("t.json")).unwrap_err().to_string();
        assert!(err.contains("settings.target_error"), "{bad}: {err}");
    }
    for bad in ["0", "1.5", "nan", "-1"] {
        let code = spectrace_renderer::cli::main_with_args([
            "spectrace",
            "render",
            "scenes/fading_spot.json",
            "--target-error",
            bad,
        ]);
        assert_eq!(code, std::process::ExitCode::from(2), "{bad}");
    }
}

/// `--time` caps a render to a target it cannot reach in time: the sidecar says the target was
/// not reached, with the estimate it got to.
#[test]
fn a_time_cap_stops_a_render_to_an_unreachable_target() {
    let s = small("fading_spot.json", 48, 32);
    let out = crate::rendering::temp_dir("estimate-cap");
    let report = render_scene(
        &s,
        &RenderOptions {
            target_error: Some(1e-5),
            time: Some(0.5),
            threads: Some(2),
            integrator: Some(IntegratorChoice::Path),
            out_dir: out,
            ..RenderOptions::default()
        },
    )
    .unwrap();
    let e = report.error_estimate.unwrap();
    assert_eq!(e.target_reached, Some(false));
    assert!(e.relative_error.unwrap() > 1e-5);
    // The sidecar predicts what the target would take (far beyond the cap), and lists only
    // errors below the one reached.
    assert!(e.seconds_to_target.unwrap() > 1e3 * report.wall_seconds, "{e:?}");
    let reached = e.relative_error.unwrap();
    assert!(e.predicted_seconds.iter().all(|[t, s]| *t < reached && *s > 0.0), "{e:?}");
}

/// `spectrace estimate` on the command line: a Markdown table on stdout and, with `--json`, the
/// report as JSON; the JSON file may not replace the scene.
#[test]
fn the_estimate_command_writes_its_report() {
    let dir = crate::rendering::temp_dir("estimate-cli");
    let scene = dir.join("scene.json");
    let mut v: Value = serde_json::from_str(crate::rendering::POINT_OVER_PLANE).unwrap();
    v["camera"]["width"] = Value::from(32);
    v["camera"]["height"] = Value::from(24);
    std::fs::write(&scene, v.to_string()).unwrap();
    let json = dir.join("estimate.json");
    let run = |out: &Path| {
        spectrace_renderer::cli::main_with_args([
            "spectrace".as_ref(),
            "estimate".as_ref(),
            scene.as_os_str(),
            "--target-error".as_ref(),
            "0.05".as_ref(),
            "--pilot-seconds".as_ref(),
            "0.1".as_ref(),
            "--integrators".as_ref(),
            "light,path".as_ref(),
            "--error-measure".as_ref(),
            "mean".as_ref(),
            "--json".as_ref(),
            out.as_os_str(),
        ])
    };
    assert_eq!(run(&json), std::process::ExitCode::SUCCESS);
    let report: Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let predictions = report["predictions"].as_array().unwrap();
    assert_eq!(predictions.len(), 2);
    assert!(predictions.iter().all(|p| p["predicted_seconds"].as_f64().unwrap() > 0.0));
    assert!(report["recommended"].is_string());
    assert_eq!(report["error_measure"], "mean");
    // The JSON may not replace the scene file.
    let before = std::fs::read(&scene).unwrap();
    assert_eq!(run(&scene), std::process::ExitCode::from(2));
    assert_eq!(std::fs::read(&scene).unwrap(), before);
}

/// `settings.error_measure` and `--error-measure` choose the headline of the sidecar's
/// estimate, which gives every measure; a bad value names the field.
#[test]
fn the_error_measure_is_chosen_by_the_scene_or_the_command_line() {
    let json = crate::rendering::POINT_OVER_PLANE.trim_end().strip_suffix('}').unwrap().to_owned();
    let with = |measure: &str| format!("{json}, \"settings\": {{\"error_measure\": {measure}}}}}");
    let s = Scene::from_json(&with("\"relmse\""), Path::new("inline.json")).unwrap();
    assert_eq!(s.settings.error_measure, ErrorMeasure::RelMse);
    let out = crate::rendering::temp_dir("error-measure");
    let render = |measure: Option<ErrorMeasure>| {
        let options = RenderOptions {
            beams: Some(32 * 32 * 32),
            threads: Some(2),
            integrator: Some(IntegratorChoice::Path),
            error_measure: measure,
            out_dir: out.clone(),
            ..RenderOptions::default()
        };
        render_scene(&s, &options).unwrap().error_estimate.unwrap()
    };
    let scene_choice = render(None);
    assert_eq!(scene_choice.measure, "relmse");
    assert_eq!(scene_choice.relative_error, scene_choice.relative_error_by_measure.relmse);
    let by = scene_choice.relative_error_by_measure;
    assert!(by.relmse.is_some() && by.energy.is_some() && by.mean.is_some(), "{by:?}");
    assert_eq!(scene_choice.relative_rmse, by.energy);
    let [lo, hi] = scene_choice.interval.unwrap();
    assert!(lo < scene_choice.relative_error.unwrap() && scene_choice.relative_error.unwrap() < hi);
    let overridden = render(Some(ErrorMeasure::Mean));
    assert_eq!(overridden.measure, "mean");
    assert_eq!(overridden.relative_error, overridden.relative_error_by_measure.mean);
    let e = Scene::from_json(&with("\"rmse\""), Path::new("inline.json")).unwrap_err().to_string();
    assert!(e.contains("settings.error_measure") && e.contains("`relmse`"), "{e}");
    let code = spectrace_renderer::cli::main_with_args([
        "spectrace",
        "render",
        "scene.json",
        "--error-measure",
        "rmse",
    ]);
    assert_eq!(code, std::process::ExitCode::from(2));
}

/// The pixels of an EXR written by the renderer (`width` pixels wide), as linear RGB.
fn read_rgb(path: &Path, width: usize) -> Vec<[f32; 3]> {
    let image = exr::prelude::read_first_rgba_layer_from_file(
        path,
        |size, _| vec![[0f32; 3]; size.0 * size.1],
        move |px: &mut Vec<[f32; 3]>, pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            px[pos.y() * width + pos.x()] = [r, g, b];
        },
    )
    .unwrap();
    image.layer_data.channel_data.pixels
}

/// `output.error_image: "relative"` writes each pixel's standard error over its value (`eps`,
/// 1% of the image's mean level, below dark pixels): the same render's absolute error image
/// divided by its image, to f32 rounding. `true` and `"absolute"` are the same; other values
/// are refused naming the field.
#[test]
fn the_relative_error_image_is_the_absolute_one_over_the_image() {
    let mut s = small("fading_spot.json", 48, 32);
    let out = crate::rendering::temp_dir("relative-error-image");
    let mut render = |kind: ErrorImage, dir: &str| {
        s.output.error_image = kind;
        let options = RenderOptions {
            beams: Some(32 * 48 * 32),
            seed: Some(5),
            threads: Some(2),
            integrator: Some(IntegratorChoice::Path),
            out_dir: out.join(dir),
            ..RenderOptions::default()
        };
        render_scene(&s, &options).unwrap();
        let read = |name: &str| read_rgb(&out.join(dir).join(name), 48);
        (read("fading_spot.exr"), read("fading_spot.error.exr"))
    };
    let (image, absolute) = render(ErrorImage::Absolute, "absolute");
    let (same, relative) = render(ErrorImage::Relative, "relative");
    assert_eq!(image, same, "the same render");
    // The relative image also comes as a false-colour PNG of the image's size (its colours are
    // checked in the renderer's unit tests); the absolute one does not.
    assert!(!out.join("absolute/fading_spot.error.png").exists());
    let png = std::fs::read(out.join("relative/fading_spot.error.png")).unwrap();
    assert_eq!(&png[1..4], b"PNG");
    assert_eq!((&png[16..20], &png[20..24]), (&48u32.to_be_bytes()[..], &32u32.to_be_bytes()[..]));
    let level = image.iter().flatten().map(|&v| f64::from(v)).sum::<f64>() / (3.0 * 1536.0);
    let eps = 0.01 * level;
    let mut checked = 0;
    for ((v, a), r) in image.iter().zip(&absolute).zip(&relative) {
        for c in 0..3 {
            let want = f64::from(a[c]) / f64::from(v[c]).abs().max(eps);
            assert!((f64::from(r[c]) - want).abs() <= 1e-5 * want + 1e-30, "{r:?} vs {want}");
            checked += usize::from(a[c] > 0.0);
        }
    }
    assert!(checked > 1000, "only {checked} noisy channels");
    let json = crate::rendering::POINT_OVER_PLANE.trim_end().strip_suffix('}').unwrap();
    let with = |value: &str| format!("{json}, \"output\": {{\"error_image\": {value}}}}}");
    let parse = |value: &str| Scene::from_json(&with(value), Path::new("inline.json"));
    assert_eq!(parse("true").unwrap().output.error_image, ErrorImage::Absolute);
    assert_eq!(parse("\"absolute\"").unwrap().output.error_image, ErrorImage::Absolute);
    assert_eq!(parse("\"relative\"").unwrap().output.error_image, ErrorImage::Relative);
    assert_eq!(parse("false").unwrap().output.error_image, ErrorImage::Off);
    let e = parse("\"percent\"").unwrap_err().to_string();
    assert!(e.contains("output.error_image") && e.contains("relative"), "{e}");
    // `--error-image` overrides the scene's: the relative kind writes both error files.
    let scene = out.join("scene.json");
    std::fs::write(&scene, crate::rendering::POINT_OVER_PLANE).unwrap();
    let cli = |kind: &str, dir: &str| {
        spectrace_renderer::cli::main_with_args(
            ["spectrace", "render", &scene.display().to_string(), "--beams", "65536"]
                .into_iter()
                .map(String::from)
                .chain(["--error-image".into(), kind.into(), "--quiet".into()])
                .chain(["--out".into(), out.join(dir).display().to_string()]),
        )
    };
    assert_eq!(cli("relative", "cli"), std::process::ExitCode::SUCCESS);
    let name = scene_name(&scene);
    for file in [format!("{name}.error.exr"), format!("{name}.error.png")] {
        assert!(out.join("cli").join(&file).is_file(), "{file}");
    }
    assert_ne!(cli("percent", "bad"), std::process::ExitCode::SUCCESS);
    assert!(!out.join("bad").exists());
}

/// The output base name of a scene file with no `output.name`: its file stem.
fn scene_name(path: &Path) -> String {
    path.file_stem().unwrap().to_string_lossy().into_owned()
}
