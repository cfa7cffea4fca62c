//! The three estimators against closed forms and against each other: the light tracer, the path
//! tracer and BDPT must give the same image wherever they all apply (fixed seeds; tolerances in
//! standard errors measured from independent seeds).

use spectrace_renderer::{InMemoryRender, Scene, choose_integrator};
use spectrace_spectrum::Uniform;
use spectrace_tracer::IntegratorChoice;

use crate::rendering::{
    POINT_OVER_PLANE, assert_lit_plane_matches_with, block_stats, render_with, scene, y_of_radiance,
};

/// Mean Y of an image.
fn mean_y(r: &InMemoryRender) -> f64 {
    r.image.iter().map(|p| p.y).sum::<f64>() / r.image.len() as f64
}

/// Mean and standard error of the image mean over `seeds` independent renders.
fn mean_and_error(s: &Scene, integrator: IntegratorChoice, effort: u64, seeds: u64) -> (f64, f64) {
    let means: Vec<f64> =
        (0..seeds).map(|k| mean_y(&render_with(s, integrator, effort, 1000 + k))).collect();
    let n = means.len() as f64;
    let mean = means.iter().sum::<f64>() / n;
    let var = means.iter().map(|m| (m - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

#[test]
fn the_path_tracer_matches_the_lit_plane_closed_form() {
    // L = rho / pi * I cos / r^2 on every 8x8 block (see assert_lit_plane_matches_with): 32x32
    // pixels, 8 samples per pixel per seed.
    let s = scene(POINT_OVER_PLANE);
    assert_lit_plane_matches_with(&s, IntegratorChoice::Path, 32 * 32 * 8, 300, |to| to.y);
}

#[test]
fn the_path_tracer_conserves_energy_in_the_integrating_sphere() {
    // As the light tracer's test: a point light at the centre of a diffuse sphere of reflectance
    // rho; the camera at the centre sees L = rho P / (pi A (1 - rho)) (direct light plus every
    // interreflection: Russian roulette and next-event estimation must be unbiased at every
    // depth). Tolerance: 5 standard errors over 6 seeds, and the test must be sharp (2%).
    let json = r#"{
      "camera": {"position": [0, 0, 0], "look_at": [0, 0, -1], "fov": 90, "width": 16, "height": 16},
      "objects": [{"shape": {"type": "Sphere", "center": [0, 0, 0], "radius": 2},
                   "material": {"type": "Diffuse", "reflectance": 0.8}}],
      "lights": [{"type": "PointLight", "position": [0, 0, 0], "power": 10,
                  "spd": {"type": "Uniform", "min_nm": 400, "max_nm": 700}}],
      "settings": {"max_depth": 400, "rr_depth": 3}
    }"#;
    let s = scene(json);
    let spd = Uniform::new(400.0, 700.0).unwrap();
    let (rho, p, area) = (0.8, 10.0, 4.0 * std::f64::consts::PI * 4.0);
    let expected = y_of_radiance(rho * p / (std::f64::consts::PI * area * (1.0 - rho)), &spd);
    let (mean, se) = mean_and_error(&s, IntegratorChoice::Path, 16 * 16 * 32, 6);
    assert!((mean - expected).abs() < 5.0 * se, "{mean} vs {expected} (standard error {se})");
    assert!(se < 0.02 * expected, "the test must be sharp: standard error {se} vs {expected}");
}

/// A spot over a diffuse plane, seen from above at an angle (the scene of the issue's timing).
const SPOT_OVER_PLANE: &str = r#"{
  "camera": {"position": [0, 2.5, 2.5], "look_at": [0, 0, 0], "fov": 50, "width": 32, "height": 32},
  "objects": [{"shape": {"type": "Rectangle", "corner": [-3, 0, 3], "edge_u": [6, 0, 0], "edge_v": [0, 0, -6]},
               "material": {"type": "Diffuse", "reflectance": {"nm": [400, 700], "values": [0.2, 0.8]}}}],
  "lights": [{"type": "UniformSpotLight", "position": [0.3, 1.5, 0], "direction": [0, -1, 0.2], "cone_angle": 35,
              "power": 50, "spd": {"type": "Blackbody", "kelvin": 3000}}]
}"#;

/// Asserts that two estimators agree on `s`: image means within 4 combined standard errors, and
/// every 8x8 block within 5 (Student's t with 7 degrees of freedom per side; with 16 blocks a
/// correct renderer fails with probability below 1%).
fn assert_agree(s: &Scene, a: (IntegratorChoice, u64), b: (IntegratorChoice, u64), seeds: u64) {
    let (w, h) = (s.camera.width() as usize, s.camera.height() as usize);
    let run = |(integrator, effort): (IntegratorChoice, u64)| -> Vec<_> {
        (0..seeds).map(|k| render_with(s, integrator, effort, 77 + k).image).collect::<Vec<_>>()
    };
    let (ia, ib) = (run(a), run(b));
    let (ba, bb) = (block_stats(&ia, w, h, 8), block_stats(&ib, w, h, 8));
    let mut total = (0.0, 0.0, 0.0, 0.0);
    for (x, y) in ba.iter().zip(&bb) {
        let se = (x.3 * x.3 + y.3 * y.3).sqrt();
        assert!(
            (x.2 - y.2).abs() <= 5.0 * se + 1e-12 * x.2.abs(),
            "block ({}, {}): {} {} vs {} {} (combined standard error {se})",
            x.0,
            x.1,
            a.0.name(),
            x.2,
            b.0.name(),
            y.2
        );
        total.0 += x.2;
        total.1 += y.2;
        total.2 += x.3 * x.3;
        total.3 += y.3 * y.3;
    }
    let se = (total.2 + total.3).sqrt();
    assert!(
        (total.0 - total.1).abs() <= 4.0 * se,
        "image means: {} {} vs {} {} (standard error {se})",
        a.0.name(),
        total.0,
        b.0.name(),
        total.1
    );
    assert!(total.0 > 0.0 && se < 0.05 * total.0, "the test must be sharp: {se} vs {}", total.0);
}

#[test]
fn light_and_path_agree_on_a_spot_over_a_plane() {
    let s = scene(SPOT_OVER_PLANE);
    assert_eq!(choose_integrator(&s, None).0, IntegratorChoice::Path);
    assert_agree(&s, (IntegratorChoice::Light, 200_000), (IntegratorChoice::Path, 32 * 32 * 8), 8);
}

/// A closed diffuse sphere of reflectance `a` whose inside glows with radiance `L`: every point
/// sees `L / (1 - a)` (the emission plus every interreflection: the white furnace).
fn furnace(a: f64) -> Scene {
    scene(&format!(
        r#"{{
      "camera": {{"position": [0.3, -0.2, 0.1], "look_at": [0, 0, -1], "fov": 100, "width": 16, "height": 16}},
      "objects": [{{"shape": {{"type": "Sphere", "center": [0, 0, 0], "radius": 1.5}},
                   "material": {{"type": "Diffuse", "reflectance": {a}}},
                   "emission": {{"power": 30, "spd": {{"type": "Uniform", "min_nm": 400, "max_nm": 700}}, "two_sided": true}}}}],
      "settings": {{"max_depth": 400, "rr_depth": 3}}
    }}"#
    ))
}

#[test]
fn every_integrator_passes_the_furnace_test() {
    // L = P / (2 pi A) on each side of the two-sided sphere; inside, the camera sees L / (1 - a)
    // in every pixel. Tolerance: 5 standard errors over 6 seeds; the test must be sharp (3%).
    let a = 0.6;
    let s = furnace(a);
    let spd = Uniform::new(400.0, 700.0).unwrap();
    let area = 4.0 * std::f64::consts::PI * 1.5 * 1.5;
    let l = 30.0 / (2.0 * std::f64::consts::PI * area);
    let expected = y_of_radiance(l / (1.0 - a), &spd);
    for (integrator, effort) in [
        (IntegratorChoice::Light, 100_000),
        (IntegratorChoice::Path, 16 * 16 * 16),
        (IntegratorChoice::Bdpt, 16 * 16 * 8),
    ] {
        let (mean, se) = mean_and_error(&s, integrator, effort, 6);
        let name = integrator.name();
        assert!(
            (mean - expected).abs() < 5.0 * se,
            "{name}: {mean} vs {expected} (standard error {se})"
        );
        assert!(se < 0.03 * expected, "{name}: standard error {se} vs {expected}");
    }
}
