//! The rough materials in whole renders: at roughness 0 (and 1e-4) `RoughConductor`,
//! `RoughDielectric` and a rough `Plastic` give the smooth material's image bit for bit in every
//! integrator, and a rough metal, frosted glass and a rough plastic each look the same to the
//! light tracer, the path tracer and BDPT.

use spectrace_renderer::Scene;
use spectrace_spectrum::Xyz;
use spectrace_tracer::IntegratorChoice;

use crate::rendering::{render_with, scene};

const INTEGRATORS: [IntegratorChoice; 3] =
    [IntegratorChoice::Light, IntegratorChoice::Path, IntegratorChoice::Bdpt];

/// A metal sphere on a diffuse floor in front of a wall, under a rectangle light.
fn sphere_scene(metal: &str) -> Scene {
    scene(&format!(
        r#"{{
      "camera": {{"position": [0, 0.5, 2], "look_at": [0, 0.3, 0], "fov": 40, "width": 24, "height": 16}},
      "objects": [
        {{"shape": {{"type": "Rectangle", "corner": [-2, 0, 2], "edge_u": [4, 0, 0], "edge_v": [0, 0, -4]}},
          "material": {{"type": "Diffuse", "reflectance": 0.6}}}},
        {{"shape": {{"type": "Rectangle", "corner": [-2, 0, -1], "edge_u": [4, 0, 0], "edge_v": [0, 2, 0]}},
          "material": {{"type": "Diffuse", "reflectance": {{"nm": [400, 700], "values": [0.2, 0.8]}}}}}},
        {{"shape": {{"type": "Sphere", "center": [0, 0.3, 0], "radius": 0.3}}, "material": {metal}}}
      ],
      "lights": [{{"type": "RectangleLight", "corner": [-0.3, 1.5, -0.3], "edge_u": [0.6, 0, 0],
                  "edge_v": [0, 0, 0.6], "power": 30, "spd": {{"type": "CieIlluminant", "name": "D65"}}}}],
      "settings": {{"max_depth": 8}}
    }}"#
    ))
}

fn total_y(image: &[Xyz]) -> f64 {
    image.iter().map(|p| p.y).sum()
}

/// Asserts that `rough(roughness)` renders `smooth`'s image bit for bit in every integrator
/// for roughness 0 and 1e-4 (same uniforms, same results: below `SMOOTH_ALPHA` the rough
/// materials run the smooth code, and `is_specular` agrees), and that roughness 0.01 does not
/// (so the comparison can fail).
fn assert_roughness_zero_is_smooth(smooth: &str, rough: impl Fn(&str) -> String) {
    let smooth = sphere_scene(smooth);
    for roughness in ["0", "0.0001"] {
        let rough = sphere_scene(&rough(roughness));
        for integrator in INTEGRATORS {
            let effort = if integrator == IntegratorChoice::Light { 200_000 } else { 24 * 16 * 8 };
            let a = render_with(&smooth, integrator, effort, 3);
            let b = render_with(&rough, integrator, effort, 3);
            assert!(total_y(&a.image) > 0.0, "{integrator:?}");
            assert_eq!(a.image, b.image, "{integrator:?}, roughness {roughness}");
        }
    }
    let rougher = sphere_scene(&rough("0.01"));
    let a = render_with(&smooth, IntegratorChoice::Path, 24 * 16 * 8, 3);
    let b = render_with(&rougher, IntegratorChoice::Path, 24 * 16 * 8, 3);
    assert_ne!(a.image, b.image);
}

#[test]
fn roughness_zero_renders_the_smooth_conductor_bit_for_bit() {
    assert_roughness_zero_is_smooth(r#"{"type": "Conductor", "metal": "Cu"}"#, |r| {
        format!(r#"{{"type": "RoughConductor", "metal": "Cu", "roughness": {r}}}"#)
    });
}

#[test]
fn roughness_zero_renders_the_smooth_dielectric_and_plastic_bit_for_bit() {
    assert_roughness_zero_is_smooth(r#"{"type": "Dielectric", "ior": {"glass": "BK7"}}"#, |r| {
        format!(r#"{{"type": "RoughDielectric", "ior": {{"glass": "BK7"}}, "roughness": {r}}}"#)
    });
    assert_roughness_zero_is_smooth(
        r#"{"type": "Plastic", "reflectance": 0.4, "ior": 1.5}"#,
        |r| format!(r#"{{"type": "Plastic", "reflectance": 0.4, "ior": 1.5, "roughness": {r}}}"#),
    );
}

/// A rough metal floor seen from above, lit by a rectangle light: all the light the camera sees
/// comes off the rough lobe (eval and pdf for the camera integrators' connections and MIS,
/// scatter for the paths they sample).
const ROUGH_FLOOR: &str = r#"{
  "camera": {"position": [0, 1.2, 1.6], "look_at": [0, 0, 0], "fov": 50, "width": 16, "height": 12},
  "objects": [
    {"shape": {"type": "Rectangle", "corner": [-2, 0, 2], "edge_u": [4, 0, 0], "edge_v": [0, 0, -4]},
     "material": {"type": "RoughConductor", "metal": "Au", "roughness_u": 0.3, "roughness_v": 0.5}}
  ],
  "lights": [{"type": "RectangleLight", "corner": [-0.4, 1.0, -1.2], "edge_u": [0.8, 0, 0],
              "edge_v": [0, 0, 0.4], "power": 30, "spd": {"type": "CieIlluminant", "name": "D65"}}]
}"#;

/// Asserts that the light tracer, the path tracer and BDPT give the same image totals of X, Y
/// and Z on `s`: each mean over 8 seeds known to 2%, and every pair within 4 combined standard
/// errors of the path tracer's.
fn assert_every_integrator_agrees(s: &Scene, light_beams: u64, camera_samples: u64) {
    let seeds = 8u64;
    let mut results = Vec::new();
    for integrator in INTEGRATORS {
        let effort =
            if integrator == IntegratorChoice::Light { light_beams } else { camera_samples };
        let totals: Vec<[f64; 3]> = (0..seeds)
            .map(|k| {
                let r = render_with(s, integrator, effort, 500 + k);
                let sum = r.image.iter().fold(Xyz::default(), |a, &p| a + p);
                [sum.x, sum.y, sum.z]
            })
            .collect();
        let n = seeds as f64;
        let stats: Vec<(f64, f64)> = (0..3)
            .map(|c| {
                let mean = totals.iter().map(|t| t[c]).sum::<f64>() / n;
                let var = totals.iter().map(|t| (t[c] - mean).powi(2)).sum::<f64>() / (n - 1.0);
                (mean, (var / n).sqrt())
            })
            .collect();
        println!("{integrator:?}: X {:?} Y {:?} Z {:?}", stats[0], stats[1], stats[2]);
        results.push((integrator, stats));
    }
    let (_, reference) = &results[1];
    for (integrator, stats) in &results {
        for &(mean, se) in stats {
            assert!(mean > 0.0 && se < 0.02 * mean, "{integrator:?}: {mean} +- {se}");
        }
    }
    for (integrator, stats) in &results {
        for c in 0..3 {
            let (a, sa) = stats[c];
            let (b, sb) = reference[c];
            let tolerance = 4.0 * (sa * sa + sb * sb).sqrt();
            assert!(
                (a - b).abs() < tolerance,
                "{integrator:?} channel {c}: {a} vs path {b} (+- {tolerance})"
            );
        }
    }
}

#[test]
fn a_rough_metal_looks_the_same_to_every_integrator() {
    assert_every_integrator_agrees(&scene(ROUGH_FLOOR), 400_000, 16 * 12 * 32);
}

#[test]
fn frosted_glass_and_rough_plastic_look_the_same_to_every_integrator() {
    // A frosted-glass pane between the light and a diffuse floor (light reaches the floor only
    // through the rough transmission lobe, and the camera sees the pane), and a rough plastic
    // floor (its GGX coating lobe and its diffuse base).
    let pane = ROUGH_FLOOR
        .replace(
            r#""material": {"type": "RoughConductor", "metal": "Au", "roughness_u": 0.3, "roughness_v": 0.5}}"#,
            r#""material": {"type": "Diffuse", "reflectance": 0.7}},
    {"shape": {"type": "Rectangle", "corner": [-1, 0.6, -1.5], "edge_u": [2, 0, 0], "edge_v": [0, 0, 2]},
     "material": {"type": "RoughDielectric", "ior": 1.5, "roughness": 0.3}}"#,
        );
    assert_ne!(pane, ROUGH_FLOOR);
    assert_every_integrator_agrees(&scene(&pane), 400_000, 16 * 12 * 96);
    let plastic = ROUGH_FLOOR.replace(
        r#"{"type": "RoughConductor", "metal": "Au", "roughness_u": 0.3, "roughness_v": 0.5}"#,
        r#"{"type": "Plastic", "reflectance": {"nm": [400, 700], "values": [0.1, 0.6]}, "ior": 1.5, "roughness": 0.2}"#,
    );
    assert_ne!(plastic, ROUGH_FLOOR);
    assert_every_integrator_agrees(&scene(&plastic), 400_000, 16 * 12 * 32);
}
