//! Rendering tests that prove the light tracer right: analytic irradiance, energy conservation in
//! an integrating sphere, dispersion through a prism, determinism across threads, exact sharding,
//! scene errors, and every shipped scene.

use std::path::{Path, PathBuf};

use glam::DVec3;
use spectrace_geometry::{Ray, Shape, World};
use spectrace_lights::LightSource;
use spectrace_materials::{Dielectric, Incoming, Material};
use spectrace_renderer::{
    PROBE_BEAMS, RenderOptions, Scene, decide_effects, merge_parts, plan_with, probe, render_scene,
    tracer_scene,
};
use spectrace_spectrum::{CIE_Y_INTEGRAL, SpectralPowerDistribution, Uniform, xyz_of};
use spectrace_tracer::{Integrator, IntegratorChoice, LightTracer, RenderOutput, render};

/// `../shared/realworld/<sub>` beside the workspace (files people outside the project wrote,
/// kept out of the repository), if present; a test that needs it skips, saying so, without it.
pub(crate) fn realworld(sub: &str) -> Option<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/realworld").join(sub);
    if dir.is_dir() {
        Some(dir)
    } else {
        eprintln!(
            "skipped: {} is absent (the real files live outside the repository)",
            dir.display()
        );
        None
    }
}

/// A fresh, empty folder for one test's files (also used by the hostile-input tests).
pub(crate) fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("spectrace-test-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

pub(crate) fn scene(json: &str) -> Scene {
    Scene::from_json(json, Path::new("inline.json")).unwrap_or_else(|e| panic!("{e}"))
}

/// Renders with the scene's settings (overridden) and returns the film, unscaled, and the image.
fn render_inline(
    scene: &Scene,
    beams: u64,
    seed: u64,
    threads: usize,
) -> (RenderOutput, Vec<spectrace_spectrum::Xyz>) {
    let options = RenderOptions {
        beams: Some(beams),
        seed: Some(seed),
        threads: Some(threads),
        ..RenderOptions::default()
    };
    let plan = plan_with(scene, &options, IntegratorChoice::Light).unwrap();
    let effects = decide_effects(scene, None);
    let tracer_scene = tracer_scene(scene);
    let tracer = LightTracer::new(&tracer_scene, scene.tracer_settings(), effects);
    let output = render(&tracer, &plan, &|_| {}).unwrap();
    let image = spectrace_renderer::image(
        &output,
        spectrace_renderer::normalisation(IntegratorChoice::Light, scene.lights.power(), 1),
    );
    (output, image)
}

/// Renders in memory with `integrator` and `effort` paths (beams, or camera samples: `effort /
/// pixels` per pixel, rounded up), 2 threads.
pub(crate) fn render_with(
    scene: &Scene,
    integrator: IntegratorChoice,
    effort: u64,
    seed: u64,
) -> spectrace_renderer::InMemoryRender {
    let options = RenderOptions {
        beams: Some(effort),
        seed: Some(seed),
        threads: Some(2),
        integrator: Some(integrator),
        ..RenderOptions::default()
    };
    spectrace_renderer::render_in_memory(scene, &options).unwrap()
}

/// Y of a constant total radiance `l` (W m^-2 sr^-1) with the spectrum of `spd`, in film units.
pub(crate) fn y_of_radiance(l: f64, spd: &dyn SpectralPowerDistribution) -> f64 {
    l * xyz_of(spd).y / *CIE_Y_INTEGRAL
}

/// Mean and standard error, over seeds, of the Y of every block of `b x b` pixels.
pub(crate) fn block_stats(
    images: &[Vec<spectrace_spectrum::Xyz>],
    w: usize,
    h: usize,
    b: usize,
) -> Vec<(usize, usize, f64, f64)> {
    let mut out = Vec::new();
    for by in 0..h / b {
        for bx in 0..w / b {
            let per_seed: Vec<f64> = images
                .iter()
                .map(|img| {
                    let mut s = 0.0;
                    for y in by * b..(by + 1) * b {
                        for x in bx * b..(bx + 1) * b {
                            s += img[y * w + x].y;
                        }
                    }
                    s / (b * b) as f64
                })
                .collect();
            let n = per_seed.len() as f64;
            let mean = per_seed.iter().sum::<f64>() / n;
            let var = per_seed.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
            out.push((bx, by, mean, (var / n).sqrt()));
        }
    }
    out
}

/// Renders `s` (a diffuse plane y = 0 of reflectance 0.5 under a 100 W point light at
/// [`PLANE_LIGHT`] with a uniform 400-700 nm spectrum) with 16 seeds, and checks every 8x8 block
/// of the image against `rho / pi * I * cos / r^2`, with `cos` given by `cos_at(unit vector to the
/// light)`. Tolerance: 5 standard errors of each block mean from the 16 seeds (Student's t with 15
/// degrees of freedom exceeds 5 with probability 1.6e-4 per block, so a correct renderer fails
/// with probability 0.3%), plus [`LIT_PLANE_QUADRATURE`] for evaluating the closed form at 4
/// points per pixel instead of integrating it.
fn assert_lit_plane_matches(s: &Scene, first_seed: u64, cos_at: impl Fn(DVec3) -> f64) {
    assert_lit_plane_matches_with(s, IntegratorChoice::Light, 100_000, first_seed, cos_at);
}

/// [`assert_lit_plane_matches`] with any estimator, `effort` beams (or camera paths) per seed.
pub(crate) fn assert_lit_plane_matches_with(
    s: &Scene,
    integrator: IntegratorChoice,
    effort: u64,
    first_seed: u64,
    cos_at: impl Fn(DVec3) -> f64,
) {
    let images: Vec<_> =
        (0..16).map(|seed| render_with(s, integrator, effort, first_seed + seed).image).collect();
    let (w, h, b) = (32usize, 32usize, 8usize);
    for (bx, by, mean, se) in block_stats(&images, w, h, b) {
        let mut expected = 0.0;
        for y in by * b..(by + 1) * b {
            for x in bx * b..(bx + 1) * b {
                expected += lit_plane_pixel(s, x, y, &cos_at);
            }
        }
        expected /= (b * b) as f64;
        assert!(
            (mean - expected).abs() < 5.0 * se + LIT_PLANE_QUADRATURE * expected,
            "block ({bx}, {by}): {mean} vs {expected} (standard error {se})"
        );
    }
}

/// What evaluating the lit plane's closed form at 4 points per pixel instead of integrating it
/// over the pixel may be off by, relative.
pub(crate) const LIT_PLANE_QUADRATURE: f64 = 0.002;

/// The closed form of the lit plane of [`assert_lit_plane_matches`] in pixel `(x, y)` of `s`'s
/// camera: Y of `rho / pi * I * cos / r^2`, the mean of 4 points of the pixel.
pub(crate) fn lit_plane_pixel(s: &Scene, x: usize, y: usize, cos_at: impl Fn(DVec3) -> f64) -> f64 {
    let spd = Uniform::new(400.0, 700.0).unwrap();
    let intensity = 100.0 / (4.0 * std::f64::consts::PI);
    let analytic_pixel = |px: f64, py: f64| {
        let d = s.camera.direction(px, py);
        let o = s.camera.position();
        let p = o + d * (-o.y / d.y);
        let to = PLANE_LIGHT - p;
        let r2 = to.length_squared();
        y_of_radiance(0.5 / std::f64::consts::PI * intensity * cos_at(to / r2.sqrt()) / r2, &spd)
    };
    [(0.125, 0.125), (0.375, 0.625), (0.625, 0.375), (0.875, 0.875)]
        .iter()
        .map(|(sx, sy)| analytic_pixel(x as f64 + sx, y as f64 + sy))
        .sum::<f64>()
        / 4.0
}

/// The point light of the lit-plane scenes: outside the view, so it is not in the image itself.
pub(crate) const PLANE_LIGHT: DVec3 = DVec3::new(2.2, 1.0, 0.2);

pub(crate) const POINT_OVER_PLANE: &str = r#"{
  "camera": {"position": [0, 3, 0.001], "look_at": [0, 0, 0], "up": [0, 0, -1], "fov": 60, "width": 32, "height": 32},
  "objects": [{"shape": {"type": "Rectangle", "corner": [-3, 0, 3], "edge_u": [6, 0, 0], "edge_v": [0, 0, -6]},
               "material": {"type": "Diffuse", "reflectance": 0.5}}],
  "lights": [{"type": "PointLight", "position": [2.2, 1, 0.2], "power": 100,
              "spd": {"type": "Uniform", "min_nm": 400, "max_nm": 700}}]
}"#;

#[test]
fn prism_disperses_by_snells_law_with_the_sellmeier_index() {
    // A 60-degree SF11 prism; a ray enters the left face at 60 degrees and leaves the right one.
    // The deviation traced through geometry and material must equal the closed form
    // delta = theta1 + asin(n sin(A - asin(sin(theta1) / n))) - A with n from the Sellmeier
    // coefficients, at 450 nm and 650 nm, within 0.1 degree (it agrees to ~1e-9).
    let prism: Shape = serde_json::from_str(
        r#"{"type": "Prism", "apex_angle_degrees": 60, "side": 1, "length": 1}"#,
    )
    .unwrap();
    let world = World::new(vec![prism]).unwrap();
    let glass = Dielectric::glass("SF11").unwrap();
    let apex = 60f64.to_radians();
    let h = 30f64.to_radians().cos();
    // Left face from (-0.5, -h/2) to (0, h/2): outward normal up-left, tangent towards the apex.
    let n_left = DVec3::new(-(30f64.to_radians().cos()), 30f64.to_radians().sin(), 0.0);
    let tangent = DVec3::new(0.5, h, 0.0).normalize();
    let theta1 = 60f64.to_radians();
    let d_in = (-n_left * theta1.cos() - tangent * theta1.sin()).normalize();
    let target = DVec3::new(-0.25, 0.0, 0.0);
    let mut deviations = Vec::new();
    for lambda in [450.0, 650.0] {
        let mut ray = Ray::new(target - d_in * 2.0, d_in);
        for _ in 0..2 {
            let hit = world.intersect(&ray, f64::INFINITY).expect("the ray meets the prism");
            let incoming =
                Incoming { direction: ray.direction, normal: hit.shading_normal, lambda };
            // u[0] close to 1 chooses refraction (reflection has probability F, a few per cent).
            let out = glass.scatter(&incoming, [0.999_999, 0.5, 0.5]).expect("refracted");
            ray = hit.spawn_ray(out.direction);
        }
        let traced = d_in.dot(ray.direction).clamp(-1.0, 1.0).acos();
        let n = glass.ior().n(lambda);
        let theta2 = (theta1.sin() / n).asin();
        let theta4 = (n * (apex - theta2).sin()).asin();
        let expected = theta1 + theta4 - apex;
        assert!(
            (traced - expected).abs().to_degrees() < 0.1,
            "{lambda} nm: traced deviation {:.6} deg, Snell/Sellmeier {:.6} deg",
            traced.to_degrees(),
            expected.to_degrees()
        );
        deviations.push(traced);
    }
    assert!(deviations[0] > deviations[1] + 1f64.to_radians(), "blue must bend more than red");
}

#[test]
fn same_seed_same_image_with_one_two_or_four_threads() {
    // Small chunks, so that four threads interleave their flushes into the shared film.
    let s = scene(
        &POINT_OVER_PLANE
            .replace("\"lights\"", "\"settings\": {\"chunk_beams\": 3000}, \"lights\""),
    );
    let (one, _) = render_inline(&s, 60_000, 5, 1);
    let (two, _) = render_inline(&s, 60_000, 5, 2);
    let (four, _) = render_inline(&s, 60_000, 5, 4);
    assert!(one.film.accepted() > 1000, "{}", one.film.accepted());
    assert_eq!(one.film, two.film);
    assert_eq!(one.film, four.film);
    assert_eq!((one.beams, four.beams, four.stats.beams), (60_000, 60_000, 60_000));
    let (other_seed, _) = render_inline(&s, 60_000, 6, 2);
    assert_ne!(one.film, other_seed.film);
}

#[test]
fn the_light_tracer_integrator_is_trace_chunk_normalised_by_power_over_beams() {
    let s = scene(POINT_OVER_PLANE);
    let effects = decide_effects(&s, None);
    let tracer_scene = tracer_scene(&s);
    let tracer = LightTracer::new(&tracer_scene, s.tracer_settings(), effects);
    assert_eq!(tracer.name(), "light");
    assert_eq!(tracer.resolution(), (s.camera.width(), s.camera.height()));
    let (w, h) = tracer.resolution();
    let mut direct = spectrace_tracer::Film::new(w, h).unwrap();
    let mut through = spectrace_tracer::Film::new(w, h).unwrap();
    let a = spectrace_tracer::trace_chunk(
        &tracer_scene,
        &s.tracer_settings(),
        &effects,
        5,
        2,
        3000,
        &mut direct,
    );
    let work = spectrace_tracer::ChunkWork {
        seed: 5,
        chunk: 2,
        items: 3000,
        deadline: None,
        ends_pass: false,
    };
    let b = tracer.render_chunk(work, &mut through);
    assert!(direct.accepted() > 100, "{}", direct.accepted());
    assert_eq!((a, &direct), (b, &through));
    assert_eq!(tracer.image_scale(3000), s.lights.power() / 3000.0);
    assert_eq!(tracer.image_scale(0), 0.0);
    let (output, image) = render_inline(&s, 20_000, 5, 2);
    assert_eq!(image, output.film.to_xyz(tracer.image_scale(output.beams)));
}

#[test]
fn sharded_renders_merge_bit_for_bit() {
    let dir = temp_dir("shards");
    let path = dir.join("plane.json");
    std::fs::write(
        &path,
        POINT_OVER_PLANE.replace("\"lights\"", "\"settings\": {\"chunk_beams\": 5000}, \"lights\""),
    )
    .unwrap();
    let s = Scene::load(&path).unwrap();
    let base = RenderOptions {
        beams: Some(40_000),
        seed: Some(9),
        threads: Some(2),
        integrator: Some(IntegratorChoice::Light),
        ..RenderOptions::default()
    };
    let whole =
        render_scene(&s, &RenderOptions { out_dir: dir.join("whole"), ..base.clone() }).unwrap();
    assert_eq!(whole.rejected_contributions, 0);
    let mut parts = Vec::new();
    for k in 0..3 {
        let opts = RenderOptions {
            shard: Some((k, 3)),
            out_dir: dir.join("parts"),
            threads: Some(1),
            ..base.clone()
        };
        parts.push(PathBuf::from(&render_scene(&s, &opts).unwrap().outputs[0]));
    }
    let merged = merge_parts(&parts, &dir.join("merged")).unwrap();
    assert_eq!(merged.beams, 40_000);
    assert_eq!((whole.integrator.as_str(), merged.integrator.as_str()), ("light", "light"));
    for ext in ["exr", "png"] {
        let a = std::fs::read(dir.join("whole").join(format!("plane.{ext}"))).unwrap();
        let b = std::fs::read(dir.join("merged").join(format!("plane.{ext}"))).unwrap();
        assert!(a == b, "{ext} of the merged shards differs from the one-machine render");
    }
    // Missing or repeated parts are refused.
    assert!(
        merge_parts(&parts[..2], &dir.join("bad")).unwrap_err().to_string().contains("missing")
    );
    let twice = vec![parts[0].clone(), parts[0].clone(), parts[1].clone()];
    assert!(merge_parts(&twice, &dir.join("bad")).unwrap_err().to_string().contains("is also in"));
}

fn load_error(json: &str) -> String {
    Scene::from_json(json, Path::new("bad.json")).unwrap_err().to_string()
}

#[test]
fn scene_errors_name_the_file_position_and_field() {
    let e = load_error("{\n  \"camera\": {\"position\": [0, 0, 0],,}\n}");
    assert!(e.starts_with("bad.json:2:"), "{e}");
    assert!(e.contains("syntax error"), "{e}");
    let bad_ior = POINT_OVER_PLANE.replace(
        r#""material": {"type": "Diffuse", "reflectance": 0.5}"#,
        r#""material": {"type": "Dielectric", "ior": -1.5}"#,
    );
    let e = load_error(&bad_ior);
    assert!(e.contains("objects[0].material"), "{e}");
    assert!(e.contains("ior"), "{e}");
    let bad_shape = POINT_OVER_PLANE.replace(r#""type": "Rectangle""#, r#""type": "Cube""#);
    let e = load_error(&bad_shape);
    assert!(e.contains("objects[0].shape") && e.contains("Cube") && e.contains("Sphere"), "{e}");
    let bad_light = POINT_OVER_PLANE.replace(r#""type": "PointLight""#, r#""type": "Candle""#);
    let e = load_error(&bad_light);
    assert!(
        e.contains("lights[0]") && e.contains("Candle") && e.contains("UniformSpotLight"),
        "{e}"
    );
    let bad_camera = POINT_OVER_PLANE.replace(r#""fov": 60"#, r#""fov": 200"#);
    let e = load_error(&bad_camera);
    assert!(e.contains("camera") && e.contains("fov"), "{e}");
    let bad_reflectance =
        POINT_OVER_PLANE.replace(r#""reflectance": 0.5"#, r#""reflectance": 1.5"#);
    let e = load_error(&bad_reflectance);
    assert!(e.contains("objects[0].material.reflectance"), "{e}");
    // The camera estimators' settings and glowing objects name their fields too.
    let with = |settings: &str| {
        POINT_OVER_PLANE.replace("\"lights\"", &format!("\"settings\": {settings}, \"lights\""))
    };
    let e = load_error(&with(r#"{"spp": 0}"#));
    assert!(e.contains("settings.spp") && e.contains("at least 1"), "{e}");
    let e = load_error(&with(r#"{"integrator": "mlt"}"#));
    assert!(e.contains("settings.integrator") && e.contains("mlt"), "{e}");
    let e = load_error(&with(r#"{"camera_wavelengths": "red"}"#));
    assert!(e.contains("settings.camera_wavelengths"), "{e}");
    let e = load_error(&with(r#"{"kernel": "simd"}"#));
    assert!(e.contains("settings.kernel") && e.contains("simd") && e.contains("batched"), "{e}");
    let e = load_error(&with(r#"{"light_sampler": "bvh"}"#));
    assert!(e.contains("settings.light_sampler") && e.contains("bvh") && e.contains("tree"), "{e}");
    let glowing = POINT_OVER_PLANE.replace(
        r#""material": {"type": "Diffuse", "reflectance": 0.5}"#,
        r#""material": {"type": "Diffuse", "reflectance": 0.5}, "emission": {"power": -3, "spd": {"type": "Uniform"}}"#,
    );
    let e = load_error(&glowing);
    assert!(e.contains("objects[0].emission") && e.contains("power"), "{e}");
}

/// A dark image is a result: a floor of reflectance 0 under a light (the usual scene for direct
/// illuminance, with or without a sensor) renders, black, with a warning saying why; with every
/// estimator.
#[test]
fn a_lit_scene_the_camera_sees_as_black_renders_with_a_warning() {
    let black = POINT_OVER_PLANE.replace(r#""reflectance": 0.5"#, r#""reflectance": 0"#);
    let with_sensor = black.replace(
        r#""lights""#,
        r#""sensors": [{"type": "IrradianceSensor", "name": "floor", "corner": [-1, 0.01, -1],
                        "edge_u": [0, 0, 2], "edge_v": [2, 0, 0], "cells": [2, 2]}], "lights""#,
    );
    for (name, json) in [("dark", &black), ("dark-sensor", &with_sensor)] {
        for integrator in [IntegratorChoice::Light, IntegratorChoice::Path] {
            let report = render_scene(
                &scene(json),
                &RenderOptions {
                    beams: Some(2000),
                    spp: Some(1),
                    integrator: Some(integrator),
                    out_dir: temp_dir(&format!("{name}-{integrator:?}")),
                    ..RenderOptions::default()
                },
            )
            .unwrap_or_else(|e| panic!("{name}, {integrator:?}: {e}"));
            assert!(
                report.warnings.iter().any(|w| w.contains("the camera sees no light")),
                "{name}, {integrator:?}: {:?}",
                report.warnings
            );
            // The sidecar lists the light: 100 W of a flat 400-700 nm spectrum.
            let flat = Uniform::new(400.0, 700.0).unwrap();
            let lumens = 100.0 * spectrace_spectrum::luminous_efficacy(&flat);
            assert_eq!(report.lights.len(), 1);
            assert_eq!(report.lights[0].kind, "PointLight");
            assert!((report.lights[0].watts.unwrap() - 100.0).abs() < 1e-9);
            assert!((report.lights[0].lumens.unwrap() / lumens - 1.0).abs() < 1e-12);
        }
    }
}

#[test]
fn a_scene_that_cannot_light_the_camera_is_reported() {
    // The spot points away from the plane and from the camera: the image would be black.
    let json = POINT_OVER_PLANE.replace(
        r#"{"type": "PointLight", "position": [2.2, 1, 0.2], "power": 100,"#,
        r#"{"type": "UniformSpotLight", "position": [2.2, 1, 0.2], "direction": [1, 0, 0], "cone_angle": 20, "power": 100,"#,
    );
    let s = scene(&json);
    let e = render_scene(
        &s,
        &RenderOptions {
            beams: Some(1000),
            out_dir: temp_dir("black"),
            ..RenderOptions::default()
        },
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("no light can reach the camera"), "{e}");
}

#[test]
fn every_shipped_scene_renders_without_rejected_contributions() {
    let scenes_dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes");
    let mut count = 0;
    for entry in std::fs::read_dir(&scenes_dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "json") {
            continue;
        }
        let s = Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
        let out = temp_dir(&format!("scene-{count}"));
        let report = render_scene(
            &s,
            &RenderOptions {
                // 30,000 beams for the light tracer, one whole pass for a camera estimator
                // (30,000 samples would be a band of rows, which may all see the dark).
                beams: Some(30_000),
                spp: Some(1),
                threads: Some(2),
                out_dir: out,
                ..RenderOptions::default()
            },
        )
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert_eq!(report.rejected_contributions, 0, "{}", path.display());
        assert!(report.stats.splats > 0, "{}: nothing reached the film", path.display());
        count += 1;
    }
    assert!(count >= 1, "no scenes found in {}", scenes_dir.display());
}

/// The six walls of the closed box [-1, 1]^3 as scene objects, all of `material` (JSON).
pub(crate) fn box_walls(material: &str) -> [String; 6] {
    let wall = |corner: [f64; 3], u: [f64; 3], v: [f64; 3]| {
        format!(
            r#"{{"shape": {{"type": "Rectangle", "corner": {corner:?}, "edge_u": {u:?}, "edge_v": {v:?}}}, "material": {material}}}"#
        )
    };
    [
        wall([-1.0, -1.0, -1.0], [2.0, 0.0, 0.0], [0.0, 0.0, 2.0]),
        wall([-1.0, 1.0, -1.0], [2.0, 0.0, 0.0], [0.0, 0.0, 2.0]),
        wall([-1.0, -1.0, -1.0], [0.0, 2.0, 0.0], [0.0, 0.0, 2.0]),
        wall([1.0, -1.0, -1.0], [0.0, 2.0, 0.0], [0.0, 0.0, 2.0]),
        wall([-1.0, -1.0, -1.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]),
        wall([-1.0, -1.0, 1.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]),
    ]
}

#[test]
fn closed_white_box_loses_no_power() {
    // Reflectance 1 everywhere and no way out: every beam must bounce until the depth limit, never
    // escape through a seam, and never be ended by Russian roulette (its weight stays 1).
    let walls = box_walls(r#"{"type": "Diffuse", "reflectance": 1.0}"#);
    let json = format!(
        r#"{{"camera": {{"position": [0, 0, 0.5], "look_at": [0, 0, -1], "fov": 90, "width": 8, "height": 8}},
            "objects": [{}],
            "lights": [{{"type": "PointLight", "position": [0.3, 0.2, -0.1], "power": 1, "spd": {{"type": "Uniform"}}}}],
            "settings": {{"max_depth": 40, "rr_depth": 2}}}}"#,
        walls.join(",")
    );
    let s = scene(&json);
    let effects = decide_effects(&s, None);
    assert!(effects.continue_after_diffuse);
    let mut film = spectrace_tracer::Film::new(8, 8).unwrap();
    let beams = 5_000;
    let stats = spectrace_tracer::trace_chunk(
        &tracer_scene(&s),
        &s.tracer_settings(),
        &effects,
        3,
        0,
        beams,
        &mut film,
    );
    assert_eq!(stats.roulette_kills, 0);
    assert_eq!(stats.depth_limited, beams, "a beam escaped or was absorbed");
    assert_eq!(stats.hits, beams * 41);
    assert_eq!(film.rejected(), 0);
}

#[test]
fn object_transforms_apply_after_the_shape_transform() {
    let json = POINT_OVER_PLANE.replace(
        r#""material": {"type": "Diffuse", "reflectance": 0.5}}"#,
        r#""material": {"type": "Diffuse", "reflectance": 0.5}, "transform": {"translate": [0, -0.25, 0]}}"#,
    );
    let s = scene(&json);
    let b = s.world.bounds();
    assert!((b.min.y + 0.25).abs() < 1e-12 && (b.max.y + 0.25).abs() < 1e-12, "{b:?}");
    // A curved shape given a non-uniform scale at object level is refused with the field named.
    let sphere = r#"{"camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "fov": 40, "width": 8, "height": 8},
      "objects": [{"shape": {"type": "Sphere", "center": [0, 0, 0], "radius": 1}, "material": {"type": "Diffuse", "reflectance": 0.5},
                   "transform": {"scale": [1, 2, 1]}}],
      "lights": [{"type": "PointLight", "position": [0, 3, 3], "power": 1, "spd": {"type": "Uniform"}}]}"#;
    let e = Scene::from_json(sphere, Path::new("s.json")).unwrap_err().to_string();
    assert!(e.contains("objects[0].transform"), "{e}");
}

#[test]
fn a_time_budget_stops_the_render() {
    let s = scene(POINT_OVER_PLANE);
    let options = RenderOptions {
        time: Some(0.3),
        threads: Some(2),
        out_dir: temp_dir("time"),
        ..RenderOptions::default()
    };
    let started = std::time::Instant::now();
    let report = render_scene(&s, &options).unwrap();
    assert!(started.elapsed().as_secs_f64() < 30.0);
    assert!(report.beams > 0 && report.beams < u64::MAX / 4, "{}", report.beams);
    assert_eq!(report.rejected_contributions, 0);
}

#[test]
fn wavelength_bundles_survive_a_surface_that_absorbs_some_wavelengths() {
    // An integrating sphere black below 550 nm and 0.8 above: a bundle must lose only its
    // absorbed wavelengths. Per wavelength, L = rho P spd / (pi A (1 - rho)); Y integrates it
    // against ybar. Tolerance: 5 standard errors of the image mean over 6 seeds.
    let json = r#"{
      "camera": {"position": [0, 0, 0], "look_at": [0, 0, -1], "fov": 90, "width": 16, "height": 16},
      "objects": [{"shape": {"type": "Sphere", "center": [0, 0, 0], "radius": 2},
                   "material": {"type": "Diffuse", "reflectance": {"nm": [400, 549.99, 550, 700], "values": [0, 0, 0.8, 0.8]}}}],
      "lights": [{"type": "PointLight", "position": [0, 0, 0], "power": 10,
                  "spd": {"type": "Uniform", "min_nm": 400, "max_nm": 700}}],
      "settings": {"max_depth": 400, "rr_depth": 3}
    }"#;
    let s = scene(json);
    assert_eq!(decide_effects(&s, None).wavelengths_per_path, spectrace_tracer::BUNDLE);
    let area = 4.0 * std::f64::consts::PI * 4.0;
    let rho = |l: f64| {
        if l >= 550.0 {
            0.8
        } else if l > 549.99 {
            0.8 * (l - 549.99) / 0.01
        } else {
            0.0
        }
    };
    let expected = spectrace_spectrum::integrate_panels(
        &|l| {
            let r = rho(l);
            r * 10.0 / 300.0 / (std::f64::consts::PI * area * (1.0 - r))
                * spectrace_spectrum::cmf(l).y
        },
        400.0,
        700.0,
        &[549.99, 550.0],
    ) / *CIE_Y_INTEGRAL;
    let means: Vec<f64> = (0..6)
        .map(|seed| {
            let (_, image) = render_inline(&s, 100_000, 40 + seed, 2);
            image.iter().map(|p| p.y).sum::<f64>() / image.len() as f64
        })
        .collect();
    let mean = means.iter().sum::<f64>() / 6.0;
    let se = (means.iter().map(|m| (m - mean).powi(2)).sum::<f64>() / 5.0 / 6.0).sqrt();
    assert!((mean - expected).abs() < 5.0 * se, "{mean} vs {expected} (standard error {se})");
    assert!(se < 0.02 * expected);
}

#[test]
fn shading_normals_shade_light_traced_surfaces_like_camera_paths() {
    // A flat two-triangle mesh whose vertex normals all lean 30 degrees towards +x: its
    // radiance must be rho / pi * I |wi . n_s| / r^2 (the shading normal in the cosine), not the
    // flat plane's.
    let n = [30f64.to_radians().sin(), 30f64.to_radians().cos(), 0.0];
    let json = format!(
        r#"{{
      "camera": {{"position": [0, 3, 0.001], "look_at": [0, 0, 0], "up": [0, 0, -1], "fov": 60, "width": 32, "height": 32}},
      "objects": [{{"shape": {{"type": "Mesh", "positions": [[-3, 0, -3], [3, 0, -3], [3, 0, 3], [-3, 0, 3]],
                              "triangles": [[0, 2, 1], [0, 3, 2]], "normals": [{n:?}, {n:?}, {n:?}, {n:?}]}},
                   "material": {{"type": "Diffuse", "reflectance": 0.5}}}}],
      "lights": [{{"type": "PointLight", "position": [2.2, 1, 0.2], "power": 100,
                  "spd": {{"type": "Uniform", "min_nm": 400, "max_nm": 700}}}}]
    }}"#
    );
    let ns = DVec3::from_array(n);
    assert_lit_plane_matches(&scene(&json), 300, |to_light| to_light.dot(ns).max(0.0));
}

#[test]
fn extreme_settings_are_refused_or_survived_without_panics() {
    let s = scene(POINT_OVER_PLANE);
    let out = temp_dir("extreme");
    // A time budget too large for a Duration means no budget; with a beam cap it just renders.
    let report = render_scene(
        &s,
        &RenderOptions {
            beams: Some(2000),
            time: Some(1e300),
            threads: Some(1),
            out_dir: out.clone(),
            ..RenderOptions::default()
        },
    );
    assert!(report.is_ok(), "{report:?}");
    // A tiny budget still renders one chunk.
    let tiny = render_scene(
        &s,
        &RenderOptions {
            time: Some(1e-12),
            threads: Some(2),
            out_dir: out.clone(),
            ..RenderOptions::default()
        },
    )
    .unwrap();
    assert!(tiny.beams > 0);
    let e = render_scene(
        &s,
        &RenderOptions {
            beams: Some(100),
            threads: Some(100_000),
            out_dir: out.clone(),
            ..RenderOptions::default()
        },
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("threads") && e.contains("at most"), "{e}");
    // A resolution beyond the film's limit is refused before anything is allocated or traced.
    let huge = POINT_OVER_PLANE
        .replace(r#""width": 32, "height": 32"#, r#""width": 100000, "height": 100000"#);
    assert_ne!(huge, POINT_OVER_PLANE);
    let e = render_scene(
        &scene(&huge),
        &RenderOptions { beams: Some(100), out_dir: out.clone(), ..RenderOptions::default() },
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("camera") && e.contains("100000x100000") && e.contains("2^25"), "{e}");
    // Bad output names and missing OBJ files name their field.
    let bad_name =
        POINT_OVER_PLANE.replace("\"lights\"", "\"output\": {\"name\": \"../escape\"}, \"lights\"");
    assert!(load_error(&bad_name).contains("output.name"));
    let missing_obj = POINT_OVER_PLANE.replace(
        r#"{"type": "Rectangle", "corner": [-3, 0, 3], "edge_u": [6, 0, 0], "edge_v": [0, 0, -6]}"#,
        r#"{"type": "Mesh", "obj": "does-not-exist.obj"}"#,
    );
    let e = load_error(&missing_obj);
    assert!(e.contains("objects[0].shape") && e.contains("does-not-exist.obj"), "{e}");
    // Light that is all outside the visible range renders black: reported, not rendered.
    let invisible = POINT_OVER_PLANE.replace(
        r#""spd": {"type": "Uniform", "min_nm": 400, "max_nm": 700}"#,
        r#""spd": {"type": "Monochromatic", "lambda_nm": 1000}"#,
    );
    let e = render_scene(
        &scene(&invisible),
        &RenderOptions { beams: Some(1000), out_dir: out, ..RenderOptions::default() },
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("no light can reach the camera"), "{e}");
}

#[test]
fn the_same_seed_writes_the_same_files() {
    let dir = temp_dir("same-files");
    let path = dir.join("plane.json");
    std::fs::write(&path, POINT_OVER_PLANE).unwrap();
    let s = Scene::load(&path).unwrap();
    for run in ["a", "b"] {
        let opts = RenderOptions {
            beams: Some(50_000),
            seed: Some(3),
            threads: Some(2),
            out_dir: dir.join(run),
            ..RenderOptions::default()
        };
        render_scene(&s, &opts).unwrap();
    }
    for ext in ["exr", "png"] {
        let a = std::fs::read(dir.join("a").join(format!("plane.{ext}"))).unwrap();
        let b = std::fs::read(dir.join("b").join(format!("plane.{ext}"))).unwrap();
        assert!(a == b, "{ext} files differ between two renders with the same seed");
    }
}

/// A closed box of six mirror rectangles around a point light, with `max_depth = rr_depth =
/// 8000`: every beam bounces 8000 times. The camera is inside (it sees the light directly) or
/// outside (no light can reach it).
fn mirror_box(camera_inside: bool) -> Scene {
    let walls = box_walls(r#"{"type": "Mirror", "reflectance": 1.0}"#);
    let z = if camera_inside { 0.5 } else { 3.0 };
    scene(&format!(
        r#"{{"camera": {{"position": [0, 0, {z}], "look_at": [0, 0, -1], "fov": 90, "width": 8, "height": 8}},
            "objects": [{}],
            "lights": [{{"type": "PointLight", "position": [0.3, 0.2, -0.1], "power": 1, "spd": {{"type": "Uniform"}}}}],
            "settings": {{"max_depth": 8000, "rr_depth": 8000}}}}"#,
        walls.join(",")
    ))
}

#[test]
fn a_closed_mirror_box_keeps_the_beam_count_and_the_time_budget() {
    let out = temp_dir("mirror-box");
    let inside = mirror_box(true);
    let effects = decide_effects(&inside, None);
    // The probe stops at the first beam that lights the film (it used to trace 20,000 beams of
    // 8000 bounces: 55 s).
    // The light tracer's beams and deadlines are what this test is about (auto would pick BDPT:
    // a point light among mirrors).
    let beams_100 = RenderOptions {
        beams: Some(100),
        out_dir: out.clone(),
        integrator: Some(IntegratorChoice::Light),
        ..Default::default()
    };
    let probed =
        probe(&inside, &effects, &plan_with(&inside, &beams_100, IntegratorChoice::Light).unwrap())
            .unwrap();
    assert!(probed.lit);
    assert_eq!(probed.beams, 1);
    let started = std::time::Instant::now();
    let report = render_scene(&inside, &beams_100).unwrap();
    assert!(started.elapsed().as_secs_f64() < 30.0, "{:?}", started.elapsed());
    assert_eq!((report.beams, report.stats.beams, report.stats.depth_limited), (100, 100, 100));
    assert_eq!(report.stats.hits, 100 * 8001);

    // A time budget stops the render at the deadline: the first chunks (16,384 beams of 8000
    // bounces each, about 45 s) are cut short, and the output counts exactly the beams traced.
    let budget = 0.5;
    let timed = RenderOptions {
        time: Some(budget),
        threads: Some(2),
        out_dir: out.clone(),
        integrator: Some(IntegratorChoice::Light),
        ..Default::default()
    };
    let report = render_scene(&inside, &timed).unwrap();
    assert!(report.wall_seconds < budget + 5.0, "{} s", report.wall_seconds);
    assert!(report.beams > 0 && report.beams < 16_384, "{}", report.beams);
    assert_eq!(report.stats.beams, report.beams);
    assert_eq!(report.stats.depth_limited, report.beams);
    let plan = plan_with(&inside, &timed, IntegratorChoice::Light).unwrap();
    let inside_scene = tracer_scene(&inside);
    let tracer = LightTracer::new(&inside_scene, inside.tracer_settings(), effects);
    let output = render(&tracer, &plan, &|_| {}).unwrap();
    assert!(output.seconds < budget + 5.0, "{} s", output.seconds);
    assert!(output.beams > 0 && output.beams < 16_384, "{}", output.beams);
    assert_eq!(output.stats.beams, output.beams);
    assert!(!output.chunks.is_empty() && output.chunks.len() <= 2, "{:?}", output.chunks);
    assert!(output.film.accepted() > 0);

    // Camera outside: no light can reach it. The probe gives up after the plan's 100 beams; the
    // light lands on the box's mirrors, so the black image is a result, with a warning...
    let outside = mirror_box(false);
    let started = std::time::Instant::now();
    let dark = render_scene(&outside, &beams_100).unwrap();
    assert!(started.elapsed().as_secs_f64() < 30.0, "{:?}", started.elapsed());
    assert!(
        dark.warnings.iter().any(|w| w.contains("the camera sees no light")),
        "{:?}",
        dark.warnings
    );
    // ... and with a time budget it is inconclusive after a tenth of it, and the render goes on.
    let probed =
        probe(&outside, &effects, &plan_with(&outside, &timed, IntegratorChoice::Light).unwrap())
            .unwrap();
    assert!(!probed.lit);
    assert!(probed.beams > 0 && probed.beams < PROBE_BEAMS, "{}", probed.beams);
    assert!(probed.seconds < budget, "{} s", probed.seconds);
    let report = render_scene(&outside, &timed).unwrap();
    assert!(report.wall_seconds < budget + 5.0, "{} s", report.wall_seconds);
    assert_eq!(report.stats.splats, 0);
    // The black image is not silent: the report warns that no light reached the camera.
    assert!(
        report.warnings.iter().any(|w| w.contains("no light reached the camera")),
        "{:?}",
        report.warnings
    );
}

/// The issue-27 probe's deep lossless case: a closed room of reflectance 0.99 with a mirror
/// sphere and a point light, `max_depth` 8000, 256 x 256 pixels, `--beams 100`. `auto` picks
/// BDPT (a point light among mirrors), whose pass is 65,536 long samples (about a minute); the
/// budget now ends inside the first pass: exactly 100 samples, that pass cut, and a warning
/// for the pixels left without one.
#[test]
fn a_beams_budget_below_one_pass_renders_that_many_camera_samples() {
    let s = scene(
        r#"{"camera": {"position": [0, 0, 0.5], "look_at": [0, 0, -1], "fov": 60, "width": 256, "height": 256},
            "objects": [
              {"shape": {"type": "Sphere", "center": [0, 0, 0], "radius": 2}, "material": {"type": "Diffuse", "reflectance": 0.99}},
              {"shape": {"type": "Sphere", "center": [0.5, 0, -1], "radius": 0.3}, "material": {"type": "Mirror", "reflectance": 0.99}}],
            "lights": [{"type": "PointLight", "position": [0, 0.5, 0], "power": 1, "spd": {"type": "CieIlluminant", "name": "D65"}}],
            "settings": {"max_depth": 8000}}"#,
    );
    assert_eq!(spectrace_renderer::choose_integrator(&s, None).0, IntegratorChoice::Bdpt);
    let out = temp_dir("deep-budget");
    let options = RenderOptions { beams: Some(100), out_dir: out.clone(), ..Default::default() };
    let report = render_scene(&s, &options).unwrap();
    assert_eq!((report.beams, report.chunks_cut), (100, 1));
    assert!(
        report.warnings.iter().any(|w| w.contains("65436 of 65536 pixels")),
        "{:?}",
        report.warnings
    );
    let _ = std::fs::remove_dir_all(&out);
}

/// A scene's `settings.beams` counts the light tracer's beams; a camera estimator rendering
/// the default `spp` of a scene that gives beams but no spp says so, and is silent when the
/// scene gives `spp`, the command line sets the effort, or the light tracer renders.
#[test]
fn a_camera_render_says_when_it_does_not_use_the_scenes_beams() {
    let with = |settings: &str| {
        let json = POINT_OVER_PLANE.trim_end().strip_suffix('}').unwrap().to_owned();
        scene(&format!("{json}, \"settings\": {{{settings}}}}}"))
    };
    let s = with(r#""beams": 20000"#);
    assert!(s.settings_given.beams && !s.settings_given.spp);
    let render = |s: &Scene, integrator, beams| {
        let options = RenderOptions {
            integrator: Some(integrator),
            beams,
            threads: Some(2),
            out_dir: temp_dir("beams-warning"),
            ..RenderOptions::default()
        };
        render_scene(s, &options).unwrap().warnings
    };
    let warned = |w: &[String]| w.iter().any(|w| w.contains("settings.beams = 20000"));
    let path = render(&s, IntegratorChoice::Path, None);
    assert!(warned(&path), "{path:?}");
    assert!(path.iter().any(|w| w.contains("settings.spp = 64 samples per pixel")), "{path:?}");
    assert!(!warned(&render(&s, IntegratorChoice::Path, Some(4096))));
    assert!(!warned(&render(&s, IntegratorChoice::Light, None)));
    // A scene that gives both has said what each estimator renders.
    let both = with(r#""beams": 20000, "spp": 64"#);
    assert!(!warned(&render(&both, IntegratorChoice::Path, None)));
}
