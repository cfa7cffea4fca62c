//! The accuracy module's tests: the knobs on the typed scene, the sweep on a tiny scene, the
//! report's analysis (reach, slopes, auto against the fastest) on made-up results.

use super::knobs::*;
use super::report::*;
use super::*;

const TINY: &str = r#"{
  "camera": {"position": [0, 2, 3], "look_at": [0, 0, 0], "fov": 50, "width": 32, "height": 24},
  "objects": [
    {"shape": {"type": "Rectangle", "corner": [-2, 0, 2], "edge_u": [4, 0, 0], "edge_v": [0, 0, -4]},
     "material": {"type": "Diffuse", "reflectance": 0.8}}
  ],
  "lights": [
    {"type": "PointLight", "position": [0, 1.5, 0], "power": 40,
     "spd": {"type": "Tabulated", "nm": [400, 500, 600, 700], "values": [0.2, 1.0, 0.6, 0.3]}}
  ],
  "settings": {"beams": 1000, "seed": 3}
}"#;

fn temp(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("spectrace-accuracy-{}-{name}", std::process::id()))
}

#[test]
fn the_knobs_are_set_on_the_typed_scene() {
    let path = Path::new("tiny.json");
    let scene = |text: &str| load(text, path, None).unwrap();
    let light = |s: &Scene, i: usize| serde_json::to_value(&s.lights.lights()[i]).unwrap();
    let spd =
        |s: &Scene, i: usize| serde_json::to_value(s.lights.lights()[i].spd().as_ref()).unwrap();

    let mut baseline = scene(TINY);
    assert_eq!(apply(Configuration::Baseline, &mut baseline).unwrap(), "");
    // Biases known from the scene's features: none on a diffuse floor under a point light;
    // with a mirror, the light tracer's (black mirrors) and the path tracer's (caustics).
    let features = baseline.features();
    let bias = |c, f: &SceneFeatures| known_bias(c, IntegratorChoice::Path, f);
    for c in Configuration::ALL {
        let expected = c == Configuration::PiecewiseConstantSpd;
        assert_eq!(bias(c, &features).is_some(), expected, "{c:?}");
    }
    let mirror = SceneFeatures { specular: true, ..features };
    assert!(bias(Configuration::Baseline, &mirror).unwrap().contains("light tracer"));
    assert!(bias(Configuration::Auto, &mirror).unwrap().contains("path tracer"));
    assert_eq!(bias(Configuration::Bdpt, &mirror), None);
    assert_eq!(light(&baseline, 0)["wavelength_sampling"], "importance");

    let mut eq = scene(TINY);
    assert_eq!(apply(Configuration::EqualWavelengths, &mut eq).unwrap(), "1 light(s)");
    assert_eq!(light(&eq, 0)["wavelength_sampling"], "equal_wavelengths");
    let mut ob = scene(TINY);
    assert_eq!(apply(Configuration::ObserverWavelengths, &mut ob).unwrap(), "1 light(s)");
    assert_eq!(light(&ob, 0)["wavelength_sampling"], "observer");
    for c in [Configuration::Sobol, Configuration::PathSobol, Configuration::BdptSobol] {
        let mut so = scene(TINY);
        assert_eq!(apply(c, &mut so).unwrap(), "settings.sampler = sobol");
        assert_eq!(so.settings.sampler, SamplerKind::Sobol);
        assert_eq!(so.settings.seed, 3);
    }
    assert_eq!(Configuration::PathSobol.integrator(), IntegratorChoice::Path);
    assert_eq!(Configuration::from_name("path_sobol"), Some(Configuration::PathSobol));
    assert_eq!(Configuration::BdptSobol.integrator(), IntegratorChoice::Bdpt);
    assert_eq!(Configuration::from_name("bdpt_sobol"), Some(Configuration::BdptSobol));
    // `baseline`, `path` and `bdpt`, the Sobol knobs' peers, sample independently whatever the
    // scene says (`auto` draws Sobol points for a light tracer whose beams stop after a diffuse
    // hit); `auto` leaves the scene's sampler as written.
    for (c, written, expected) in [
        (Configuration::Baseline, SamplerKind::Auto, SamplerKind::Independent),
        (Configuration::Path, SamplerKind::Sobol, SamplerKind::Independent),
        (Configuration::Bdpt, SamplerKind::Sobol, SamplerKind::Independent),
        (Configuration::Auto, SamplerKind::Auto, SamplerKind::Auto),
    ] {
        let mut so = scene(TINY);
        so.settings.sampler = written;
        assert_eq!(apply(c, &mut so).unwrap(), "");
        assert_eq!(so.settings.sampler, expected, "{c:?}");
    }
    // The camera-wavelength peer of `path`: independent sampling like it, whatever the scene's.
    let mut uw = scene(TINY);
    uw.settings.sampler = SamplerKind::Sobol;
    let c = Configuration::PathUniformWavelengths;
    assert_eq!(apply(c, &mut uw).unwrap(), "settings.camera_wavelengths = uniform");
    assert_eq!(uw.settings.camera_wavelengths, spectrace_tracer::CameraWavelengths::Uniform);
    assert_eq!(uw.settings.sampler, SamplerKind::Independent);
    assert_eq!(c.sampler(), Some(SamplerKind::Independent));
    assert_eq!(c.integrator(), IntegratorChoice::Path);
    assert!(apply(c, &mut uw).is_err(), "already uniform: nothing to compare");
    // BDPT's one-wavelength peer: independent sampling, beam wavelengths; refused where BDPT
    // carries one wavelength anyway.
    let mut bw = scene(TINY);
    bw.settings.sampler = SamplerKind::Sobol;
    let c = Configuration::BdptBeam;
    assert_eq!(apply(c, &mut bw).unwrap(), "settings.bdpt_wavelengths = beam");
    assert_eq!(bw.settings.bdpt_wavelengths, spectrace_tracer::BdptWavelengths::Beam);
    assert_eq!(bw.settings.sampler, SamplerKind::Independent);
    assert_eq!(
        (c.integrator(), Configuration::from_name("bdpt_beam")),
        (IntegratorChoice::Bdpt, Some(c))
    );
    assert!(apply(c, &mut bw).is_err(), "already one wavelength: nothing to compare");

    let mut pc = scene(TINY);
    assert_eq!(apply(Configuration::PiecewiseConstantSpd, &mut pc).unwrap(), "1 light(s)");
    let binned = spd(&pc, 0);
    assert_eq!(binned["type"], "Binned");
    assert_eq!(binned["edges_nm"], serde_json::json!([350.0, 450.0, 550.0, 650.0, 750.0]));
    let values: Vec<f64> =
        binned["values"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
    // The node values, up to the normalisation.
    for (v, expected) in values.iter().zip([0.2, 1.0, 0.6, 0.3]) {
        assert!((v / values[1] - expected).abs() < 1e-12, "{values:?}");
    }

    // Inside a LightSet, with a delta line skipped and a tabulated CIE illuminant re-binned.
    let mut json: serde_json::Value = serde_json::from_str(TINY).unwrap();
    let first = json["lights"][0].clone();
    json["lights"] = serde_json::json!([{"type": "LightSet", "lights": [
        first,
        {"type": "PointLight", "position": [0, 1, 0], "power": 1,
         "spd": {"type": "Monochromatic", "lambda_nm": 550}},
        {"type": "PointLight", "position": [0, 1, 0], "power": 1,
         "spd": {"type": "CieIlluminant", "name": "D65"}}
    ]}]);
    let set = json.to_string();
    let mut eq = scene(&set);
    assert_eq!(
        apply(Configuration::EqualWavelengths, &mut eq).unwrap(),
        "2 light(s); 1 with delta lines left on importance"
    );
    assert_eq!(light(&eq, 0)["wavelength_sampling"], "equal_wavelengths");
    assert_eq!(light(&eq, 1)["wavelength_sampling"], "importance");
    let mut pc = scene(&set);
    assert_eq!(apply(Configuration::PiecewiseConstantSpd, &mut pc).unwrap(), "2 light(s)");
    let d65 = spd(&pc, 2);
    assert_eq!(d65["type"], "Binned");
    assert_eq!(d65["values"].as_array().unwrap().len(), 97);
    assert_eq!(d65["edges_nm"][0], 297.5);
    assert_eq!(spd(&pc, 1)["type"], "Monochromatic");

    // A glowing object's light (the tracer's ObjectLight) is retuned like the others.
    let mut glowing: serde_json::Value = serde_json::from_str(TINY).unwrap();
    glowing["objects"].as_array_mut().unwrap().push(serde_json::json!(
        {"shape": {"type": "Sphere", "center": [0, 0.5, 0], "radius": 0.2},
         "material": {"type": "Diffuse", "reflectance": 0.5},
         "emission": {"power": 1, "spd": {"type": "Blackbody", "kelvin": 3000}}}
    ));
    let mut eq = scene(&glowing.to_string());
    assert_eq!(apply(Configuration::EqualWavelengths, &mut eq).unwrap(), "2 light(s)");
    assert_eq!(lights_changed(1, 0, 1), "1 light(s); 1 of a type without the hook left as written");

    // Not applicable: no tabulated SPD; only delta lines.
    let bb = TINY.replace(
        r#"{"type": "Tabulated", "nm": [400, 500, 600, 700], "values": [0.2, 1.0, 0.6, 0.3]}"#,
        r#"{"type": "Blackbody", "kelvin": 3200}"#,
    );
    assert_ne!(bb, TINY);
    assert!(apply(Configuration::PiecewiseConstantSpd, &mut scene(&bb)).is_err());
    let line = TINY.replace(
        r#"{"type": "Tabulated", "nm": [400, 500, 600, 700], "values": [0.2, 1.0, 0.6, 0.3]}"#,
        r#"{"type": "Monochromatic", "lambda_nm": 550}"#,
    );
    let reason = apply(Configuration::EqualWavelengths, &mut scene(&line)).unwrap_err();
    assert!(reason.contains("delta lines"), "{reason}");

    // The resolution limit keeps the aspect ratio.
    let mut small = load(TINY, path, Some(16)).unwrap();
    assert_eq!((small.camera.width(), small.camera.height()), (16, 12));
    assert!(!limit_resolution(&mut small, 16).unwrap());
}

#[test]
fn error_falls_with_beams_and_the_report_is_written() {
    let dir = temp("run");
    let scene = dir.join("tiny.json");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(&scene, TINY).unwrap();
    let options = AccuracyOptions {
        scenes: vec![scene],
        out_dir: dir.join("docs"),
        cache_dir: dir.join("cache"),
        reference_beams: 1 << 14,
        start_beams: 1 << 10,
        steps: 3,
        threads: 2,
        seed: 7,
        max_width: None,
        configurations: Configuration::ALL.to_vec(),
        estimate_check: true,
        estimate_target: 0.3,
    };
    let report = run(&options).unwrap();
    let scene = &report.scenes[0];
    assert!(!scene.reference.cached);
    let baseline = &scene.configurations[0];
    assert_eq!(baseline.configuration, Configuration::Baseline);
    let errors: Vec<f64> = baseline.points.iter().map(|p| p.relative_rmse).collect();
    assert_eq!(errors.len(), 3);
    assert!(errors.windows(2).all(|w| w[1] < w[0]), "errors {errors:?}");
    assert!(baseline.slope_vs_beams.is_some_and(|s| s < -0.2), "{baseline:?}");
    assert!(scene.configurations.iter().all(|c| c.not_applicable.is_none()));
    let md = std::fs::read_to_string(dir.join("docs/accuracy.md")).unwrap();
    assert!(md.contains("| baseline | 2^10 |"));
    assert!(md.contains("is fastest"));
    assert!(md.contains("## Fastest to 10% and to 2%"), "{md}");
    let row = md.lines().find(|l| l.starts_with("| tiny | 32x24 | path | ")).unwrap();
    // The reference's noise, then the fastest configuration to 10% by name.
    assert!(row.contains("% | `"), "{row}");
    assert!(md.contains("To reach 2.00% (the fine target)"), "{md}");
    // The estimate check: the render's own estimate against the reference, and the pilot.
    let check = scene.estimate_check.as_ref().unwrap();
    assert_eq!(check.pilot.predictions.len(), 3);
    let (e, t) = (check.estimated_error.unwrap(), check.true_error);
    // The reference (2^14 paths) carries noise of its own, so only a loose bound here; the
    // shipped scenes' figures are in docs/accuracy.md.
    assert!(e > 0.0 && (e / t) > 0.5 && (e / t) < 1.5, "estimate {e}, truth {t}");
    assert!(md.contains("## Does the renderer know its own error?"), "{md}");
    assert!(md.contains("### Estimate against truth"), "{md}");
    // The same render in every measure: its relmse cells are the headline's, and every sweep
    // point records relmse, which the plot shows (larger than energy on this scene's dim
    // floor, as the brightest pixels rule energy).
    assert_eq!(check.measure, ErrorMeasure::RelMse);
    assert_eq!(check.true_by_measure.relmse, Some(t));
    assert_eq!(check.estimated_by_measure.relmse, Some(e));
    assert!(check.true_by_measure.energy.is_some_and(|r| r > 0.0 && r < t));
    // The check's reference has at least CHECK_REFERENCE_FACTOR times its paths.
    assert!(check.reference_paths >= CHECK_REFERENCE_FACTOR * check.paths, "{check:?}");
    let row = md
        .split("## The same renders in every error measure")
        .nth(1)
        .and_then(|t| t.lines().find(|l| l.starts_with("| tiny | ")))
        .unwrap();
    assert_eq!(row.matches('(').count(), 3, "{row}");
    assert!(baseline.points.iter().all(|p| p.relmse > p.relative_rmse), "{baseline:?}");
    // The knobs' gains: a column per pair. Hero wavelengths cut BDPT's variance on the tiny
    // scene's white light far below half (measured 0.078 in pixels, 0.031 in colour).
    let gains = md.split("## What each variance-reduction knob buys").nth(1).unwrap();
    assert!(gains.contains("hero wavelengths (BDPT): `bdpt` over `bdpt_beam`"), "{gains}");
    let row = gains.lines().find(|l| l.starts_with("| tiny | ")).unwrap();
    let hero: Vec<f64> =
        row.split('|').nth(2).unwrap().split('/').map(|v| v.trim().parse().unwrap()).collect();
    assert!(hero[0] < 0.5 && hero[1] < 0.5, "{row}");
    let svg = std::fs::read_to_string(dir.join("docs/accuracy.svg")).unwrap();
    assert!(svg.contains("<svg") && svg.contains("slope -1/2"));

    // The second run reads the reference from the cache and measures the same errors
    // (same seeds, exact film sums).
    let again = run(&options).unwrap();
    assert!(again.scenes[0].reference.cached);
    let errors_again: Vec<f64> =
        again.scenes[0].configurations[0].points.iter().map(|p| p.relative_rmse).collect();
    assert_eq!(errors, errors_again);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_integrator_knob_sweeps_every_estimator_against_an_unbiased_reference() {
    let dir = temp("integrators");
    let scene = dir.join("tiny.json");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(&scene, TINY).unwrap();
    let options = AccuracyOptions {
        scenes: vec![scene.clone()],
        out_dir: dir.join("docs"),
        cache_dir: dir.join("cache"),
        reference_beams: 1 << 16,
        start_beams: 1 << 10,
        steps: 3,
        threads: 2,
        seed: 11,
        max_width: None,
        configurations: Configuration::INTEGRATORS.to_vec(),
        estimate_check: false,
        estimate_target: 0.3,
    };
    let report = run(&options).unwrap();
    let result = &report.scenes[0];
    // A point light on a diffuse floor: every light is reachable, so auto picks the path
    // tracer and the reference is the path tracer's.
    assert_eq!(result.auto_picks, IntegratorChoice::Path);
    assert_eq!(result.reference.integrator, IntegratorChoice::Path);
    let names: Vec<_> = result.configurations.iter().map(|c| c.configuration).collect();
    assert_eq!(names, Configuration::INTEGRATORS);
    let pixels = 32 * 24;
    for c in &result.configurations {
        assert_eq!(c.points.len(), 3, "{:?}", c.configuration);
        for (k, p) in c.points.iter().enumerate() {
            let nominal = 1u64 << (10 + k);
            let expected = match c.configuration {
                Configuration::Baseline => nominal,
                // ceil(nominal / pixels) samples per pixel.
                _ => nominal.div_ceil(pixels) * pixels,
            };
            assert_eq!(p.beams, expected, "{:?} point {k}", c.configuration);
        }
    }
    for c in Configuration::INTEGRATORS {
        let r = result.configurations.iter().find(|r| r.configuration == c).unwrap();
        let errors: Vec<f64> = r.points.iter().map(|p| p.relative_rmse).collect();
        assert!(errors.windows(2).all(|w| w[1] < w[0]), "{c:?}: errors {errors:?}");
        // Unbiased against the reference: the same brightness, up to noise (every estimator
        // in the same units; the light is 40 W, so a film left relative to the power shows).
        let last = r.points.last().unwrap();
        assert!((last.mean_ratio - 1.0).abs() < 0.1, "{c:?}: {last:?}");
    }
    let md = std::fs::read_to_string(dir.join("docs/accuracy.md")).unwrap();
    assert!(md.contains("## Which estimator reaches 10.0% first"), "{md}");
    assert!(md.contains("| tiny | 32x24 | path | path |"), "{md}");
    assert!(md.contains("auto / fastest:"));

    // The bench's measurement: the same paths for every estimator.
    let loaded = Scene::load(&scene).unwrap();
    let row = spectrace_renderer::integrator_benchmark(&loaded, 2000, 2).unwrap();
    assert_eq!(row.auto_picks, IntegratorChoice::Path);
    let asked: Vec<_> = row.timings.iter().map(|t| t.integrator).collect();
    assert_eq!(
        asked,
        [
            IntegratorChoice::Light,
            IntegratorChoice::Path,
            IntegratorChoice::Bdpt,
            IntegratorChoice::Auto
        ]
    );
    let paths: Vec<u64> = row.timings.iter().map(|t| t.paths).collect();
    assert_eq!(paths, [2000, 2304, 2304, 2304]);
    assert!(row.timings.iter().all(|t| t.paths_per_second() > 0.0));

    // No configurations: an error naming the field.
    let none = AccuracyOptions { configurations: Vec::new(), ..options };
    assert!(run(&none).unwrap_err().contains("configurations"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_biased_estimator_levels_off_and_is_not_extrapolated() {
    let point = |seconds: f64, relative_rmse: f64| AccuracyPoint {
        beams: 1,
        seed: 0,
        seconds,
        relative_rmse,
        mean_ratio: 0.5,
        colour_rmse: 0.0,
        relmse: 2.0 * relative_rmse,
    };
    // Falls at first, then flattens at 40%: the overall slope is steep enough to
    // extrapolate, the last three points say bias.
    let biased = ConfigurationResult {
        configuration: Configuration::Baseline,
        changed: String::new(),
        not_applicable: None,
        known_bias: None,
        points: vec![
            point(1.0, 3.2),
            point(2.0, 1.6),
            point(4.0, 0.8),
            point(8.0, 0.42),
            point(16.0, 0.41),
            point(32.0, 0.40),
        ],
        slope_vs_time: None,
        slope_vs_beams: None,
    };
    let slope = fit_slope(
        &biased.points.iter().map(|p| (p.seconds.ln(), p.relative_rmse.ln())).collect::<Vec<_>>(),
    );
    let biased = ConfigurationResult { slope_vs_time: slope, ..biased };
    assert!(biased.slope_vs_time.is_some_and(|s| s < -0.3), "{biased:?}");
    assert!(levels_off(&biased));
    assert_eq!(time_to_reach(&biased, 0.1), Reach::NotReached);
    assert_eq!(reach_text(Some(&biased)), "does not reach 10.0% (levels off at 40.0%)");
    // Still falling at -1/2: not reached within the sweep, and said so (not extrapolated).
    let falling = ConfigurationResult {
        points: vec![point(1.0, 0.8), point(4.0, 0.4), point(16.0, 0.2)],
        slope_vs_time: Some(-0.5),
        ..biased.clone()
    };
    assert!(!levels_off(&falling));
    assert!(matches!(time_to_reach(&falling, 0.1), Reach::Extrapolated(_)));
    assert_eq!(reach_text(Some(&falling)), "does not reach 10.0% in the sweep (20.0% at the end)");

    // Auto against the fastest: auto 2 s, light 1 s, path 4 s, bdpt never.
    let fair =
        |seconds, relative_rmse| AccuracyPoint { mean_ratio: 1.0, ..point(seconds, relative_rmse) };
    let result = |configuration, seconds: f64| ConfigurationResult {
        configuration,
        points: vec![fair(seconds / 2.0, 0.2), fair(seconds * 2.0, 0.05)],
        slope_vs_time: Some(-0.5),
        ..biased.clone()
    };
    let mut scene = scene_result(
        IntegratorChoice::Path,
        1,
        vec![
            result(Configuration::Baseline, 1.0),
            result(Configuration::Path, 4.0),
            ConfigurationResult { configuration: Configuration::Bdpt, ..biased.clone() },
            result(Configuration::Auto, 2.0),
        ],
    );
    let (ratio, text) = auto_ratio(&scene);
    assert!(ratio.is_some_and(|r| (r - 2.0).abs() < 1e-9), "{ratio:?}");
    assert_eq!(text, "2.00 (fastest: light)");
    // The summary: measured at 10%, extrapolated at 2% (and said so).
    assert!(matches!(
        fastest_to(&scene, ROUND_TARGET, true),
        Some((Configuration::Baseline, Reach::Interpolated(t))) if (t - 1.0).abs() < 1e-9
    ));
    let text = fastest_text(&scene, ROUND_TARGET);
    assert!(text.starts_with("`baseline` 1.0") && !text.contains("biased"), "{text}");
    assert_eq!(auto_vs_fastest_text(&scene, ROUND_TARGET), "2.00");
    let text = fastest_text(&scene, FINE_TARGET);
    assert!(text.starts_with("`baseline` ~12.5 s (extrapolated)"), "{text}");
    assert_eq!(auto_vs_fastest_text(&scene, FINE_TARGET), "2.00 (extrapolated)");
    // A light tracer known to be biased on the scene is named, but is not "the fastest":
    // auto is (the half-bright bdpt never reaches 10%).
    scene.configurations[0].known_bias = Some("black mirrors".to_owned());
    assert!(matches!(
        fastest_to(&scene, ROUND_TARGET, true),
        Some((Configuration::Auto, Reach::Interpolated(_)))
    ));
    let text = fastest_text(&scene, ROUND_TARGET);
    assert!(text.starts_with("`auto` 2.0"), "{text}");
    assert!(text.contains("; sooner but biased: `baseline` 1.0"), "{text}");
    assert!(text.ends_with(" s (black mirrors)"), "{text}");
    assert_eq!(auto_vs_fastest_text(&scene, ROUND_TARGET), "1.00 (auto is the fastest)");
    // ... nor auto's peer in the estimator table: the path tracer is, at 4 s.
    let (ratio, text) = auto_ratio(&scene);
    assert!(ratio.is_some_and(|r| (r - 0.5).abs() < 1e-9), "{ratio:?}");
    assert_eq!(text, "0.50 (fastest: path)");
    // A brightness 2x off is a bias the report sees without knowing why.
    assert!(!converges(&scene, &scene.configurations[2]));
    assert!(converges(&scene, &scene.configurations[1]));
    scene.configurations[3] =
        ConfigurationResult { configuration: Configuration::Auto, ..biased.clone() };
    assert_eq!(auto_ratio(&scene).0, Some(f64::INFINITY));
}

#[test]
fn slopes_and_reach() {
    let pts: Vec<(f64, f64)> = (0..5).map(|k| (k as f64, 3.0 - 0.5 * k as f64)).collect();
    assert!((fit_slope(&pts).unwrap() + 0.5).abs() < 1e-12);
    let result = ConfigurationResult {
        configuration: Configuration::Baseline,
        changed: String::new(),
        not_applicable: None,
        known_bias: None,
        points: vec![
            AccuracyPoint {
                beams: 1,
                seed: 0,
                seconds: 1.0,
                relative_rmse: 0.2,
                mean_ratio: 1.0,
                colour_rmse: 0.0,
                relmse: 0.4,
            },
            AccuracyPoint {
                beams: 4,
                seed: 0,
                seconds: 4.0,
                relative_rmse: 0.1,
                mean_ratio: 1.0,
                colour_rmse: 0.0,
                relmse: 0.2,
            },
        ],
        slope_vs_time: Some(-0.5),
        slope_vs_beams: Some(-0.5),
    };
    let Reach::Interpolated(t) = time_to_reach(&result, 0.1 * 2f64.sqrt()) else { panic!() };
    assert!((t - 2.0).abs() < 1e-9);
    let Reach::Extrapolated(t) = time_to_reach(&result, 0.05) else { panic!() };
    assert!((t - 16.0).abs() < 1e-9);
    assert!(matches!(time_to_reach(&result, 0.3), Reach::AtMost(_)));
    assert_ne!(sweep_seed(5, 0, 0), 5);
}

#[test]
fn the_colour_part_of_the_error_ignores_brightness_and_adds_in_quadrature() {
    let xyz = |x, y, z| Xyz { x, y, z };
    let reference = [xyz(1.0, 2.0, 3.0), xyz(0.5, 0.5, 0.1)];
    // Twice as bright everywhere: all error, no colour error.
    let brighter: Vec<Xyz> =
        reference.iter().map(|r| xyz(2.0 * r.x, 2.0 * r.y, 2.0 * r.z)).collect();
    assert!((relative_rmse(&brighter, &reference).unwrap() - 1.0).abs() < 1e-12);
    assert!(colour_relative_rmse(&brighter, &reference).unwrap() < 1e-7);
    // Error orthogonal to the reference colour: all of it is colour.
    let hue = [xyz(1.0 + 2.0, 2.0 - 1.0, 3.0), reference[1]];
    let (total, colour) =
        (relative_rmse(&hue, &reference).unwrap(), colour_relative_rmse(&hue, &reference).unwrap());
    assert!(total > 0.1 && (colour - total).abs() < 1e-12, "{total} {colour}");
    // A mixture: brightness^2 + colour^2 = total^2, each part strictly inside.
    let mixed = [xyz(2.0 + 2.0, 4.0 - 1.0, 6.0), reference[1]];
    let (total, colour) = (
        relative_rmse(&mixed, &reference).unwrap(),
        colour_relative_rmse(&mixed, &reference).unwrap(),
    );
    let norm = reference.iter().map(|r| r.x * r.x + r.y * r.y + r.z * r.z).sum::<f64>();
    let brightness = 14f64.sqrt() / norm.sqrt();
    assert!((total * total - colour * colour - brightness * brightness).abs() < 1e-12);
    assert!(colour > 0.0 && colour < total);
    // Light where the reference is black has no colour to keep: all of it counts.
    let black = [xyz(0.0, 0.0, 0.0), xyz(1.0, 1.0, 1.0)];
    let lit = [xyz(0.3, 0.0, 0.0), xyz(1.0, 1.0, 1.0)];
    let c = colour_relative_rmse(&lit, &black).unwrap();
    assert!((c - relative_rmse(&lit, &black).unwrap()).abs() < 1e-12 && c > 0.0);
    assert!(colour_relative_rmse(&lit, &black[..1]).is_err());
}

#[test]
fn a_knobs_gain_is_its_variance_over_its_peers_at_equal_paths_and_time() {
    let point = |beams, seconds, relative_rmse: f64| AccuracyPoint {
        beams,
        seed: 0,
        seconds,
        relative_rmse,
        mean_ratio: 1.0,
        colour_rmse: relative_rmse / 2.0,
        relmse: 2.0 * relative_rmse,
    };
    let result = |configuration, points| ConfigurationResult {
        configuration,
        changed: String::new(),
        not_applicable: None,
        known_bias: None,
        points,
        slope_vs_time: None,
        slope_vs_beams: None,
    };
    // bdpt (hero, the reference's estimator): half the variance of bdpt_beam and 1.5x the time
    // at every point but the first, where the two are equal.
    let errors = [0.8, 0.4, 0.2, 0.1, 0.05];
    let hero: Vec<_> = errors.iter().enumerate().map(|(k, &e)| point(1 << k, 1.5, e)).collect();
    let beam: Vec<_> = errors
        .iter()
        .enumerate()
        .map(|(k, &e)| point(1 << k, 1.0, if k == 0 { e } else { e * 2f64.sqrt() }))
        .collect();
    let mut scene = scene_result(
        IntegratorChoice::Bdpt,
        1 << 40,
        vec![
            result(Configuration::Bdpt, hero.clone()),
            result(Configuration::BdptBeam, beam.clone()),
        ],
    );
    // A reference of 2^40 paths has no noise to speak of: the last four points, ratio 1/2 in
    // pixels and colour alike; the first point (ratio 1) is left out.
    let g = gains::gain(&scene, Configuration::Bdpt, Configuration::BdptBeam).unwrap();
    assert_eq!(g.points, 4);
    assert!((g.pixel - 0.5).abs() < 1e-9 && (g.colour - 0.5).abs() < 1e-9, "{g:?}");
    assert!((g.time - 1.5).abs() < 1e-12);
    // A reference of 8 paths: its noise is 0.05 / sqrt(1 + 8/16) (bdpt's last point), and the
    // last point's variance, less than twice that noise's, is left out; the noise is subtracted
    // from every variance used (the colour part's in proportion).
    scene.reference.beams = 8;
    let r2 = 0.05f64.powi(2) / 1.5;
    let g = gains::gain(&scene, Configuration::Bdpt, Configuration::BdptBeam).unwrap();
    assert_eq!(g.points, 4);
    let sum = |pts: &[AccuracyPoint], noise: f64| {
        pts[..4].iter().map(|p| p.relative_rmse.powi(2) - noise).sum::<f64>()
    };
    assert!((g.pixel - sum(&hero, r2) / sum(&beam, r2)).abs() < 1e-12, "{g:?}");
    assert!((g.pixel - g.colour).abs() < 1e-12, "the colour part is half of every error");
    // Not swept, or from a report without the colour part: no gain.
    assert!(gains::gain(&scene, Configuration::Path, Configuration::BdptBeam).is_none());
    for p in &mut scene.configurations[1].points {
        p.colour_rmse = 0.0;
    }
    assert!(gains::gain(&scene, Configuration::Bdpt, Configuration::BdptBeam).is_none());
}

/// A scene's results for the analysis tests: `auto` picks `auto_picks`, the reference is BDPT's
/// at `reference_beams` paths, and `configurations` were swept.
fn scene_result(
    auto_picks: IntegratorChoice,
    reference_beams: u64,
    configurations: Vec<ConfigurationResult>,
) -> SceneResult {
    SceneResult {
        scene: "s.json".to_owned(),
        name: "s".to_owned(),
        width: 1,
        height: 1,
        effects_summary: String::new(),
        auto_picks,
        auto_reason: String::new(),
        reference: ReferenceInfo {
            integrator: IntegratorChoice::Bdpt,
            beams: reference_beams,
            seed: 0,
            seconds: 0.0,
            cached: false,
            file: String::new(),
        },
        estimate_check: None,
        configurations,
    }
}

#[test]
fn the_relmse_time_takes_the_references_noise_out_and_scales_by_the_square() {
    use super::relmse::{RelmseReach, relmse_reach};
    let point = |seconds: f64, relmse: f64| AccuracyPoint {
        beams: 1,
        seed: 0,
        seconds,
        relative_rmse: relmse / 4.0,
        mean_ratio: 1.0,
        colour_rmse: 0.0,
        relmse,
    };
    let result = |configuration, last: AccuracyPoint| ConfigurationResult {
        configuration,
        changed: String::new(),
        not_applicable: None,
        known_bias: None,
        points: vec![point(last.seconds / 4.0, 2.0 * last.relmse), last],
        slope_vs_time: Some(-0.5),
        slope_vs_beams: Some(-0.5),
    };
    // Against a reference of 10% own noise, the median of the last three points: 0.5 s at
    // 100% (a heavy-tailed render: 49.5 s to 10%), 1 s at 50% (49% true: 24 s) and 2 s at
    // 30% (28.3% true: 16 s); the first point is not among them.
    let mut path = result(Configuration::Path, point(2.0, 0.3));
    path.points = vec![point(0.25, 0.1), point(0.5, 1.0), point(1.0, 0.5), point(2.0, 0.3)];
    // Within twice the reference's noise: not measurable.
    let mut bdpt = result(Configuration::Bdpt, point(2.0, 0.15));
    bdpt.points = vec![point(1.0, 0.19), point(2.0, 0.15)];
    let mut light = result(Configuration::Baseline, point(1.0, 0.5));
    light.known_bias = Some("black mirrors".to_owned());
    let scene =
        scene_result(IntegratorChoice::Path, 1, vec![path.clone(), bdpt.clone(), light.clone()]);
    let reach = |r: &ConfigurationResult| relmse_reach(&scene, Some(r), 0.1, 0.1);
    assert!(matches!(reach(&path), RelmseReach::Predicted(t) if (t - 24.0).abs() < 1e-9));
    assert_eq!(reach(&bdpt), RelmseReach::AtReferenceNoise(0.15));
    assert_eq!(reach(&light), RelmseReach::Biased);
    assert_eq!(relmse_reach(&scene, None, 0.1, 0.1), RelmseReach::Missing);
}
