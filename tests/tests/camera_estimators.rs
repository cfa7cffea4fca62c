//! The camera estimators beyond the integrator matrix (`integrators.rs`): geometry seen
//! through glass, determinism across threads and shards, colour noise of the camera
//! wavelengths, and BDPT's strategies each converging alone.

use spectrace_renderer::{InMemoryRender, Scene, choose_integrator, plan_with};
use spectrace_tracer::IntegratorChoice;

use crate::integrators::{GLASS_UNDER_AREA_LIGHT, SPOT_OVER_PLANE};
use crate::rendering::{render_with, scene};
use crate::variance::pixel_noise;

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
fn each_bdpt_strategy_alone_converges_to_the_same_image() {
    // A diffuse plane under an area light, one bounce at most (max_depth 0): every path is
    // light -> plane -> camera, which three strategies can sample: s = 0 (the camera path hits
    // the light), s = 1 (next-event estimation) and s = 2 (the light path's plane vertex joined to
    // the camera, t = 1). Unweighted, each alone must give the image MIS combines. Tolerance:
    // 5 combined standard errors of the image means over 8 seeds, and each sharp (5%).
    use spectrace_renderer::{RenderOptions, decide_effects, tracer_scene};
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
        let settings =
            BdptSettings { max_depth: 0, rr_depth: 4, only_strategy: only, ..Default::default() };
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
