//! `auto` by measurement (`spectrace_renderer::measured`): which renders run the pilots, which
//! estimators compete, that the pick is the fastest prediction, and what happens when a pilot
//! cannot run.

use spectrace_renderer::{Scene, choose_integrator, plan_with};
use spectrace_tracer::IntegratorChoice;

use crate::integrators::{GLASS_UNDER_AREA_LIGHT, caustic_json};
use crate::rendering::{POINT_OVER_PLANE, scene};

/// `auto` by measurement (`spectrace_renderer::measured`): which renders measure, which
/// estimators compete, and that the pick is the fastest predicted one.
#[test]
fn auto_measures_the_estimators_that_see_everything_when_the_render_is_open_ended() {
    use IntegratorChoice::{Bdpt, Light, Path};
    use spectrace_renderer::RenderOptions;
    use spectrace_renderer::measured::{
        PILOT_SECONDS, PILOT_SHARE, choose, complete_estimators, measure_choice, pilot_budget,
    };
    let diffuse = scene(POINT_OVER_PLANE);
    let glass = scene(GLASS_UNDER_AREA_LIGHT);
    let caustic = scene(&caustic_json(true));
    // Who sees every pixel: all three on a diffuse scene, not the light tracer through glass,
    // only BDPT where a spot's caustic is seen.
    assert_eq!(complete_estimators(&diffuse), [Light, Path, Bdpt]);
    assert_eq!(complete_estimators(&glass), [Path, Bdpt]);
    assert_eq!(complete_estimators(&caustic), [Bdpt]);
    // When it measures: an open-ended render asked for auto, not sharded.
    let timed = RenderOptions { time: Some(4.0), ..RenderOptions::default() };
    let plan = |o: &RenderOptions| plan_with(&diffuse, o, Path).unwrap();
    assert_eq!(pilot_budget(&diffuse, &timed, &plan(&timed)), Some(PILOT_SHARE * 4.0));
    let target = RenderOptions { target_error: Some(0.1), ..RenderOptions::default() };
    assert_eq!(pilot_budget(&diffuse, &target, &plan(&target)), Some(PILOT_SECONDS));
    // A time given with a target is a cap: the target's pilot time, or the share if smaller.
    let capped = |t: f64| RenderOptions { time: Some(t), ..target.clone() };
    assert_eq!(pilot_budget(&diffuse, &capped(300.0), &plan(&capped(300.0))), Some(PILOT_SECONDS));
    assert_eq!(pilot_budget(&diffuse, &capped(4.0), &plan(&capped(4.0))), Some(PILOT_SHARE * 4.0));
    for (what, o) in [
        ("a fixed count", RenderOptions { spp: Some(4), ..timed.clone() }),
        ("a fixed count", RenderOptions { beams: Some(1000), ..timed.clone() }),
        ("an explicit estimator", RenderOptions { integrator: Some(Path), ..timed.clone() }),
        ("a shard", RenderOptions { shard: Some((0, 2)), ..timed.clone() }),
        ("no time or target", RenderOptions::default()),
    ] {
        assert_eq!(pilot_budget(&diffuse, &o, &plan(&o)), None, "{what}");
    }
    // The fastest prediction wins; without any, the analysis' pick stands.
    let fallback = (Path, "path: every light can be reached from the camera".to_owned());
    let picked = choose(
        vec![(Light, Some(2.0)), (Path, Some(0.5)), (Bdpt, None)],
        0.05,
        (0.1, Some((64, 48))),
        &fallback,
    );
    assert_eq!(picked.choice, Path);
    assert!(
        picked.reason.contains("bdpt no estimate") && picked.reason.contains("5%"),
        "{}",
        picked.reason
    );
    let none = choose(vec![(Light, None), (Bdpt, None)], 0.05, (0.1, None), &fallback);
    assert_eq!(none.choice, Path);
    // A real pilot (0.2 s each): every candidate predicted, the pick the fastest of them; a
    // scene with one complete estimator is not measured. (With 0.05 s each, a clean-clone CI run
    // on a machine loaded twice over by other work once got no estimate from one pilot: its
    // first round alone outlasted the pilot's time, too few chunks for an estimate. The choice
    // logic under test does not depend on the pilot's length.)
    let short = RenderOptions { time: Some(3.0 / PILOT_SHARE * 0.2), threads: Some(1), ..timed };
    let measured = measure_choice(&diffuse, &short, &plan(&short), &fallback).unwrap().unwrap();
    let times: Vec<f64> = measured.predictions.iter().map(|p| p.1.unwrap()).collect();
    assert_eq!(measured.predictions.iter().map(|p| p.0).collect::<Vec<_>>(), [Light, Path, Bdpt]);
    let best = measured.predictions.iter().min_by(|a, b| a.1.unwrap().total_cmp(&b.1.unwrap()));
    assert_eq!(Some(measured.choice), best.map(|b| b.0), "{times:?}");
    assert!(measured.reason.starts_with(measured.choice.name()), "{}", measured.reason);
    let caustic_plan = plan_with(&caustic, &short, Bdpt).unwrap();
    assert_eq!(measure_choice(&caustic, &short, &caustic_plan, &fallback).unwrap(), None);
    // A large image is piloted at most 128 x 128 pixels, the same view and aspect.
    let large = scene(
        &POINT_OVER_PLANE.replace(r#""width": 32, "height": 32"#, r#""width": 400, "height": 200"#),
    );
    let large_plan = plan_with(&large, &short, Path).unwrap();
    let measured = measure_choice(&large, &short, &large_plan, &fallback).unwrap().unwrap();
    assert!(measured.reason.contains("at 181x90 pixels"), "{}", measured.reason);
}

/// When the scaled-down pilot cannot load the scene again (here its OBJ mesh was removed after
/// loading), the render still runs, with the analysis' pick and a warning saying why.
#[test]
fn a_failed_pilot_falls_back_to_the_rule_with_a_warning() {
    use spectrace_renderer::{RenderOptions, render_scene};
    let dir = crate::rendering::temp_dir("pilot-fallback");
    std::fs::write(
        dir.join("quad.obj"),
        "v -3 0 3\nv 3 0 3\nv 3 0 -3\nv -3 0 -3\nf 1 2 3\nf 1 3 4\n",
    )
    .unwrap();
    let json = POINT_OVER_PLANE
        .replace(r#""width": 32, "height": 32"#, r#""width": 200, "height": 100"#)
        .replace(
            r#"{"type": "Rectangle", "corner": [-3, 0, 3], "edge_u": [6, 0, 0], "edge_v": [0, 0, -6]}"#,
            r#"{"type": "Mesh", "obj": "quad.obj"}"#,
        );
    let scene = Scene::from_json(&json, &dir.join("scene.json")).unwrap();
    std::fs::remove_file(dir.join("quad.obj")).unwrap();
    let options = RenderOptions {
        time: Some(0.5),
        threads: Some(1),
        out_dir: dir.join("out"),
        ..RenderOptions::default()
    };
    let report = render_scene(&scene, &options).unwrap();
    let (rule, _) = choose_integrator(&scene, None);
    assert_eq!(report.integrator, rule.name());
    assert!(
        report.warnings.iter().any(|w| w.contains("auto's pilot failed")),
        "{:?}",
        report.warnings
    );
    assert!(report.beams > 0);
    std::fs::remove_dir_all(&dir).unwrap();
}
