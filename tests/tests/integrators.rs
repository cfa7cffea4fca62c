//! The three estimators against closed forms and against each other: the light tracer, the path
//! tracer and BDPT must give the same image wherever they all apply (fixed seeds; tolerances in
//! standard errors measured from independent seeds).

use crate::variance::pixel_noise;
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
fn bdpt_matches_the_lit_plane_closed_form() {
    let s = scene(POINT_OVER_PLANE);
    assert_lit_plane_matches_with(&s, IntegratorChoice::Bdpt, 32 * 32 * 8, 600, |to| to.y);
}

#[test]
fn the_camera_estimators_conserve_energy_in_the_integrating_sphere() {
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
    for (integrator, effort) in
        [(IntegratorChoice::Path, 16 * 16 * 32), (IntegratorChoice::Bdpt, 16 * 16 * 16)]
    {
        let (mean, se) = mean_and_error(&s, integrator, effort, 6);
        let name = integrator.name();
        assert!(
            (mean - expected).abs() < 5.0 * se,
            "{name}: {mean} vs {expected} (standard error {se})"
        );
        assert!(
            se < 0.02 * expected,
            "{name}: the test must be sharp: standard error {se} vs {expected}"
        );
    }
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
pub(crate) fn assert_agree(
    s: &Scene,
    a: (IntegratorChoice, u64),
    b: (IntegratorChoice, u64),
    seeds: u64,
) {
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

/// An area light over a floor, with a glass sphere and a diffuse one in view: what the camera
/// sees through the glass is only reachable by camera paths.
const GLASS_UNDER_AREA_LIGHT: &str = r#"{
  "camera": {"position": [0, 0.6, 2.2], "look_at": [0, 0.25, 0], "fov": 40, "width": 32, "height": 32},
  "objects": [
    {"shape": {"type": "Rectangle", "corner": [-2, 0, 2], "edge_u": [4, 0, 0], "edge_v": [0, 0, -4]},
     "material": {"type": "Diffuse", "reflectance": 0.6}},
    {"shape": {"type": "Sphere", "center": [0.12, 0.3, 0], "radius": 0.3},
     "material": {"type": "Dielectric", "ior": 1.5}},
    {"shape": {"type": "Sphere", "center": [-0.5, 0.15, -0.3], "radius": 0.15},
     "material": {"type": "Diffuse", "reflectance": 0.8}}
  ],
  "lights": [{"type": "RectangleLight", "corner": [-0.4, 1.5, -0.4], "edge_u": [0.8, 0, 0], "edge_v": [0, 0, 0.8],
              "power": 40, "spd": {"type": "CieIlluminant", "name": "D65"}}]
}"#;

#[test]
fn path_and_bdpt_agree_on_glass_seen_by_the_camera_and_it_is_not_black() {
    let s = scene(GLASS_UNDER_AREA_LIGHT);
    assert_eq!(choose_integrator(&s, None).0, IntegratorChoice::Path);
    assert_agree(
        &s,
        (IntegratorChoice::Path, 32 * 32 * 8),
        (IntegratorChoice::Bdpt, 32 * 32 * 4),
        8,
    );
    // The sphere covers the image's centre: through it the camera sees the lit floor.
    let path = render_with(&s, IntegratorChoice::Path, 32 * 32 * 16, 5);
    let light = render_with(&s, IntegratorChoice::Light, 200_000, 5);
    let centre = |r: &InMemoryRender| {
        let mut y = 0.0;
        for py in 14..18 {
            for px in 14..18 {
                y += r.image[py * 32 + px].y;
            }
        }
        y / 16.0
    };
    let mean = mean_y(&path);
    // (Measured: 15% of the image mean; the floor seen upside down and the dark sky above it.)
    assert!(centre(&path) > 0.05 * mean, "glass centre {} vs image {mean}", centre(&path));
    // The light tracer cannot see through the glass (it connects no specular surface to the
    // pinhole): the same pixels are black there, which is why camera paths are needed.
    assert_eq!(centre(&light), 0.0);
}

#[test]
fn a_thin_lens_renders_the_same_with_light_and_camera_paths() {
    // The spot over the plane, through a lens of 5 cm radius focused on the plane's centre: the
    // light tracer connects through sample_wi, the path tracer starts rays on the lens.
    let json = SPOT_OVER_PLANE.replace(
        r#""width": 32, "height": 32}"#,
        r#""width": 32, "height": 32, "aperture_radius": 0.05, "focus_distance": 3.5355}"#,
    );
    let s = scene(&json);
    assert!(!s.camera.is_pinhole());
    assert_agree(&s, (IntegratorChoice::Light, 200_000), (IntegratorChoice::Path, 32 * 32 * 8), 8);
}

#[test]
fn camera_paths_see_a_slit_through_a_prism_where_snell_and_sellmeier_put_it() {
    // The light tracer's prism test, reversed: a ray entering the 60-degree SF11 prism's left
    // face at 75 degrees (away from minimum deviation, where the exit angle hardly moves) leaves
    // with the closed-form deviation; a camera on the exit side sees a
    // far slit (a narrow glowing strip on the entry side) in the direction the ray leaves, so the
    // slit's image must land, per wavelength, in the pixel of -d_out(lambda). One wavelength band
    // of 1 nm per render; a pixel is 0.05 degree wide. Tolerance: 1 pixel.
    use glam::DVec3;
    use spectrace_geometry::{Ray, Shape, World};
    use spectrace_materials::{Dielectric, Incoming, Material};
    let prism: Shape = serde_json::from_str(
        r#"{"type": "Prism", "apex_angle_degrees": 60, "side": 1, "length": 1}"#,
    )
    .unwrap();
    let world = World::new(vec![prism]).unwrap();
    let glass = Dielectric::glass("SF11").unwrap();
    let c30 = 30f64.to_radians().cos();
    let n_left = DVec3::new(-c30, 0.5, 0.0);
    let tangent = DVec3::new(0.5, c30, 0.0).normalize();
    let theta1 = 75f64.to_radians();
    let d_in = (-n_left * theta1.cos() - tangent * theta1.sin()).normalize();
    let target = DVec3::new(-0.25, 0.0, 0.0);
    let exit = |lambda: f64| {
        let mut ray = Ray::new(target - d_in * 2.0, d_in);
        let mut point = DVec3::ZERO;
        for _ in 0..2 {
            let hit = world.intersect(&ray, f64::INFINITY).unwrap();
            let incoming =
                Incoming { direction: ray.direction, normal: hit.shading_normal, lambda };
            let out = glass.scatter(&incoming, [0.999_999, 0.5, 0.5]).unwrap();
            point = hit.point;
            ray = hit.spawn_ray(out.direction);
        }
        (point, ray.direction)
    };
    let (x_mid, d_mid) = exit(550.0);
    let camera = x_mid + d_mid * 3.0;
    let slit = target - d_in * 100.0;
    // The strip: 5 cm wide across d_in in the prism's plane, 20 m tall along z, facing the prism.
    let across = d_in.cross(DVec3::Z).normalize() * 0.05;
    let corner = slit - across * 0.5 - DVec3::Z * 10.0;
    for lambda in [450.0, 650.0] {
        let json = format!(
            r#"{{
          "camera": {{"position": {:?}, "look_at": {:?}, "up": [0, 0, 1], "fov": 12, "width": 240, "height": 8}},
          "objects": [
            {{"shape": {{"type": "Prism", "apex_angle_degrees": 60, "side": 1, "length": 1}},
             "material": {{"type": "Dielectric", "ior": {{"glass": "SF11"}}}}}},
            {{"shape": {{"type": "Rectangle", "corner": {:?}, "edge_u": {:?}, "edge_v": [0, 0, 20]}},
             "material": {{"type": "Diffuse", "reflectance": 0}},
             "emission": {{"power": 1000, "spd": {{"type": "Uniform", "min_nm": {}, "max_nm": {}}}, "two_sided": true}}}}
          ]
        }}"#,
            camera.to_array(),
            x_mid.to_array(),
            corner.to_array(),
            across.to_array(),
            lambda - 0.5,
            lambda + 0.5
        );
        let s = scene(&json);
        assert_eq!(choose_integrator(&s, None).0, IntegratorChoice::Path);
        let r = render_with(&s, IntegratorChoice::Path, 240 * 8 * 1024, 9);
        let mut columns = vec![0.0; 240];
        for (i, p) in r.image.iter().enumerate() {
            columns[i % 240] += p.x + p.y + p.z;
        }
        let total: f64 = columns.iter().sum();
        assert!(total > 0.0, "{lambda} nm: the slit is not seen through the prism");
        let seen = columns.iter().enumerate().map(|(x, c)| x as f64 * c).sum::<f64>() / total;
        let (_, d_out) = exit(lambda);
        // The traced exit direction is Snell's law with the Sellmeier index, in closed form.
        let n = glass.ior().n(lambda);
        let apex = 60f64.to_radians();
        let theta4 = (n * (apex - (theta1.sin() / n).asin()).sin()).asin();
        let deviation = d_in.dot(d_out).clamp(-1.0, 1.0).acos();
        assert!((deviation - (theta1 + theta4 - apex)).abs() < 1e-9, "{lambda} nm: {deviation}");
        let expected = s.camera.project(camera - d_out).unwrap().x as f64 + 0.5;
        eprintln!("{lambda} nm: slit seen at column {seen:.2}, expected {expected}");
        assert!(
            (seen - expected).abs() <= 1.0,
            "{lambda} nm: the slit appears at column {seen:.2}, Snell/Sellmeier put it at {expected}"
        );
    }
}

#[test]
fn camera_estimators_are_bit_identical_across_threads_and_merge_shards_exactly() {
    use spectrace_renderer::{RenderOptions, merge_parts, render_scene};
    let dir = crate::rendering::temp_dir("camera-shards");
    let path = dir.join("glass.json");
    std::fs::write(&path, GLASS_UNDER_AREA_LIGHT).unwrap();
    let s = Scene::load(&path).unwrap();
    for integrator in [IntegratorChoice::Path, IntegratorChoice::Bdpt] {
        let name = integrator.name();
        let base = RenderOptions {
            spp: Some(6),
            seed: Some(4),
            integrator: Some(integrator),
            ..quiet_defaults()
        };
        let whole = render_scene(
            &s,
            &RenderOptions {
                out_dir: dir.join(name).join("whole"),
                threads: Some(2),
                ..base.clone()
            },
        )
        .unwrap();
        assert_eq!(whole.integrator, name);
        // 6 passes of 32 x 32 samples.
        assert_eq!(whole.beams, 6 * 32 * 32);
        let one = render_in(&s, &base, 1);
        let three = render_in(&s, &base, 3);
        assert_eq!(one.output.film, three.output.film, "{name}: 1 and 3 threads differ");
        let mut parts = Vec::new();
        for k in 0..4 {
            let opts = RenderOptions {
                shard: Some((k, 4)),
                out_dir: dir.join(name).join("parts"),
                threads: Some(1),
                ..base.clone()
            };
            parts.push(std::path::PathBuf::from(&render_scene(&s, &opts).unwrap().outputs[0]));
        }
        let merged = merge_parts(&parts, &dir.join(name).join("merged")).unwrap();
        assert_eq!((merged.beams, merged.integrator.as_str()), (whole.beams, name));
        for ext in ["exr", "png"] {
            let a =
                std::fs::read(dir.join(name).join("whole").join(format!("glass.{ext}"))).unwrap();
            let b =
                std::fs::read(dir.join(name).join("merged").join(format!("glass.{ext}"))).unwrap();
            assert!(a == b, "{name}: the merged {ext} differs from the one-machine render");
        }
    }
}

/// Options that write nothing to the terminal.
fn quiet_defaults() -> spectrace_renderer::RenderOptions {
    spectrace_renderer::RenderOptions { verbose: false, ..Default::default() }
}

/// Renders in memory with `threads` threads.
fn render_in(
    s: &Scene,
    options: &spectrace_renderer::RenderOptions,
    threads: usize,
) -> InMemoryRender {
    let options = spectrace_renderer::RenderOptions { threads: Some(threads), ..options.clone() };
    spectrace_renderer::render_in_memory(s, &options).unwrap()
}

#[test]
fn observer_weighted_wavelengths_have_less_colour_noise_than_uniform_ones() {
    // The same scene, samples and seeds; only the camera paths' wavelength density differs.
    // Measured: the visible density's per-pixel variance is 0.46 of the uniform one's on this
    // scene (a D65 spot on a plane with a rising reflectance); asserted below 0.75, far outside
    // the seed-to-seed spread of the ratio (12 seeds x 1024 pixels of variance estimates: a few
    // per cent).
    let visible = SPOT_OVER_PLANE.replace(
        r#"{"type": "Blackbody", "kelvin": 3000}"#,
        r#"{"type": "CieIlluminant", "name": "D65"}"#,
    );
    let uniform = visible
        .replace(r#""lights""#, r#""settings": {"camera_wavelengths": "uniform"}, "lights""#);
    let a = pixel_noise(&scene(&visible), IntegratorChoice::Path, 32 * 32 * 4, 12, 500);
    let b = pixel_noise(&scene(&uniform), IntegratorChoice::Path, 32 * 32 * 4, 12, 500);
    eprintln!("colour noise: visible {a:.4e}, uniform {b:.4e}, ratio {:.3}", a / b);
    assert!(a < 0.75 * b, "visible {a} vs uniform {b}");
}

#[test]
fn light_and_path_agree_with_a_spot_two_points_and_an_area_light_together() {
    // Next-event estimation samples every point or spot light and chooses among the area lights
    // by power; MIS on emission must use that choice's probability. A mix of both kinds checks it.
    let json = SPOT_OVER_PLANE.replace(
        r#""power": 50, "spd": {"type": "Blackbody", "kelvin": 3000}}]"#,
        r#""power": 50, "spd": {"type": "Blackbody", "kelvin": 3000}},
           {"type": "PointLight", "position": [-1, 0.8, 0.5], "power": 10, "spd": {"type": "CieIlluminant", "name": "D65"}},
           {"type": "PointLight", "position": [1, 0.4, -1], "power": 5, "spd": {"type": "CieIlluminant", "name": "A"}},
           {"type": "RectangleLight", "corner": [-0.3, 1.2, -0.3], "edge_u": [0.6, 0, 0], "edge_v": [0, 0, 0.6], "power": 30,
            "spd": {"type": "CieIlluminant", "name": "D50"}},
           {"type": "DiskLight", "center": [0.8, 0.3, 0.8], "normal": [-1, -0.2, -1], "radius": 0.1, "power": 8,
            "spd": {"type": "Uniform", "min_nm": 380, "max_nm": 720}}]"#,
    );
    let s = scene(&json);
    assert_eq!(s.lights.lights().len(), 5);
    assert_eq!(choose_integrator(&s, None).0, IntegratorChoice::Path);
    assert_agree(&s, (IntegratorChoice::Light, 300_000), (IntegratorChoice::Path, 32 * 32 * 8), 8);
    assert_agree(&s, (IntegratorChoice::Light, 300_000), (IntegratorChoice::Bdpt, 32 * 32 * 8), 8);
}

#[test]
fn each_bdpt_strategy_alone_converges_to_the_same_image() {
    // A diffuse plane under an area light, one bounce at most (max_depth 0): every path is
    // light -> plane -> camera, which three strategies can sample: s = 0 (the camera path hits
    // the light), s = 1 (next-event estimation) and s = 2 (the light path's plane vertex joined to
    // the camera, t = 1). Unweighted, each alone must give the image MIS combines. Tolerance:
    // 5 combined standard errors of the image means over 8 seeds, and each sharp (5%).
    use spectrace_renderer::{RenderOptions, decide_effects, plan_with, tracer_scene};
    use spectrace_tracer::{Bdpt, BdptSettings, render};
    let json = r#"{
      "camera": {"position": [0, 1.2, 2.2], "look_at": [0, 0, 0], "fov": 45, "width": 24, "height": 24},
      "objects": [{"shape": {"type": "Rectangle", "corner": [-2, 0, 2], "edge_u": [4, 0, 0], "edge_v": [0, 0, -4]},
                   "material": {"type": "Diffuse", "reflectance": 0.7}}],
      "lights": [{"type": "RectangleLight", "corner": [-0.5, 0.6, -0.5], "edge_u": [1, 0, 0], "edge_v": [0, 0, 1],
                  "power": 20, "spd": {"type": "CieIlluminant", "name": "D65"}}],
      "settings": {"max_depth": 0}
    }"#;
    let s = scene(json);
    let effects = decide_effects(&s, None);
    let ts = tracer_scene(&s);
    let run = |only: Option<(usize, usize)>, seed: u64| -> f64 {
        let settings = BdptSettings { max_depth: 0, rr_depth: 4, only_strategy: only };
        let bdpt = Bdpt::new(&ts, settings, effects);
        let options = RenderOptions {
            spp: Some(32),
            seed: Some(seed),
            threads: Some(2),
            ..Default::default()
        };
        let plan = plan_with(&s, &options, IntegratorChoice::Bdpt).unwrap();
        let out = render(&bdpt, &plan, &|_| {}).unwrap();
        spectrace_lights::LightSource::reset_count(&s.lights);
        let image = out.film.to_xyz(spectrace_tracer::Integrator::image_scale(&bdpt, out.beams));
        image.iter().map(|p| p.y).sum::<f64>() / image.len() as f64
    };
    let stats = |only: Option<(usize, usize)>| {
        let v: Vec<f64> = (0..8).map(|k| run(only, 40 + k)).collect();
        let m = v.iter().sum::<f64>() / 8.0;
        (m, (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / 7.0 / 8.0).sqrt())
    };
    let (all, all_se) = stats(None);
    for strategy in [(0, 3), (1, 2), (2, 1)] {
        let (m, se) = stats(Some(strategy));
        let combined = (se * se + all_se * all_se).sqrt();
        assert!(
            (m - all).abs() < 5.0 * combined,
            "strategy {strategy:?} alone: {m} vs MIS {all} (standard errors {se}, {all_se})"
        );
        assert!(se < 0.05 * m, "strategy {strategy:?}: standard error {se} of {m}");
    }
}
