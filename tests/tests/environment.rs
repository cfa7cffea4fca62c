//! The environment light (a scene's `environment`, `spectrace_tracer::Environment`): its
//! direction sampling against its density (chi-square), the weights of its beams, the three
//! estimators against a closed form (a white environment around a diffuse sphere) and against
//! each other (a coloured sky with a sun), refusals, and the Mitsuba `envmap` import.

use std::f64::consts::PI;
use std::path::{Path, PathBuf};

use glam::DVec3;
use rand::SeedableRng;
use spectrace_lights::{LightSource, uniform};
use spectrace_renderer::{Scene, import_mitsuba};
use spectrace_sampling::stats::chi_square;
use spectrace_spectrum::rgb::{d65_luminance, d65_visible};
use spectrace_spectrum::{CIE_Y_INTEGRAL, cmf};
use spectrace_tracer::{EffectsMode, Environment, EnvironmentMap, IntegratorChoice};

use crate::integrators::{Row, all, check_row};
use crate::rendering::temp_dir;

/// Writes a linear RGB OpenEXR of `w x h` texels, row 0 at the top.
fn write_map(path: &Path, w: usize, h: usize, texel: impl Fn(usize, usize) -> [f32; 3] + Sync) {
    exr::prelude::write_rgb_file(path, w, h, |x, y| {
        let [r, g, b] = texel(x, y);
        (r, g, b)
    })
    .unwrap();
}

/// The direction of texel centre `(x, y)` of a `w x h` map (the map's frame).
fn texel_direction(x: usize, y: usize, w: usize, h: usize) -> DVec3 {
    let phi = 2.0 * PI * (x as f64 + 0.5) / w as f64;
    let theta = PI * y as f64 / (h - 1) as f64;
    DVec3::new(phi.sin() * theta.sin(), theta.cos(), -phi.cos() * theta.sin())
}

/// A 32 x 16 sky: blue overhead, pale at the horizon, a broad warm sun, a dark green ground.
fn sky_map(dir: &Path, sun_power: i32) -> PathBuf {
    let path = dir.join("sky.exr");
    let sun = DVec3::new(0.5, 0.6, -0.62).normalize();
    write_map(&path, 32, 16, |x, y| {
        let d = texel_direction(x, y, 32, 16);
        let base = if d.y >= 0.0 {
            [0.9 - 0.6 * d.y, 0.95 - 0.5 * d.y, 1.0 - 0.1 * d.y]
        } else {
            [0.2, 0.3, 0.1]
        };
        let s = 6.0 * d.dot(sun).max(0.0).powi(sun_power);
        [base[0] + s, base[1] + 0.8 * s, base[2] + 0.5 * s].map(|v| v as f32)
    });
    path
}

/// An environment read from `file` on the unit sphere around the origin.
fn environment(file: &Path) -> Environment {
    let map: EnvironmentMap = serde_json::from_value(serde_json::json!({ "file": file }))
        .unwrap_or_else(|e| panic!("{e}"));
    Environment::new(map, DVec3::ZERO, 1.0).unwrap()
}

/// Directions drawn by `sample_direction` against `pdf_direction` integrated over 16 x 8 bins
/// of `(phi, cos theta)` (32 x 32 midpoints per bin): chi-square at the 0.1% level, and the
/// density integrates to 1 within 0.3% (the midpoint rule's error on the sun's peak).
#[test]
fn environment_directions_follow_their_density() {
    let dir = temp_dir("env-chi2");
    let env = environment(&sky_map(&dir, 8));
    let (nphi, ncos, sub) = (16usize, 8usize, 32usize);
    let bin = |d: DVec3| {
        let phi = d.z.atan2(d.x).rem_euclid(2.0 * PI);
        let i = ((phi / (2.0 * PI) * nphi as f64) as usize).min(nphi - 1);
        let j = (((d.y + 1.0) / 2.0 * ncos as f64) as usize).min(ncos - 1);
        i * ncos + j
    };
    let mut expected = vec![0.0; nphi * ncos];
    let cell = (2.0 * PI / (nphi * sub) as f64) * (2.0 / (ncos * sub) as f64);
    for a in 0..nphi * sub {
        for b in 0..ncos * sub {
            let phi = 2.0 * PI * (a as f64 + 0.5) / (nphi * sub) as f64;
            let z = -1.0 + 2.0 * (b as f64 + 0.5) / (ncos * sub) as f64;
            let r = (1.0 - z * z).sqrt();
            let d = DVec3::new(r * phi.cos(), z, r * phi.sin());
            expected[bin(d)] += env.pdf_direction(d) * cell;
        }
    }
    let total: f64 = expected.iter().sum();
    assert!((total - 1.0).abs() < 3e-3, "the density integrates to {total}");
    let n = 200_000u64;
    let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
    let mut observed = vec![0u64; nphi * ncos];
    for _ in 0..n {
        let (d, pdf) = env.sample_direction([uniform(&mut rng), uniform(&mut rng)]).unwrap();
        let again = env.pdf_direction(d);
        assert!((pdf - again).abs() <= 1e-9 * pdf, "sampled density {pdf}, evaluated {again}");
        observed[bin(d)] += 1;
    }
    let expected: Vec<f64> = expected.iter().map(|p| p / total * n as f64).collect();
    let test = chi_square(&observed, &expected, 5.0);
    assert!(test.p_value > 1e-3, "chi-square {test:?}");
}

/// The beams' weights: over beams, the mean `scale` is 1 (each beam an equal share of the
/// power; standard error measured under 0.5%, tolerance 4 of them); the spectral factor
/// averages 1 over wavelengths drawn from the map's spectrum (4 standard errors); next-event
/// samples towards a point estimate the irradiance the map gives it (`integral L cos`, by a
/// 256 x 128 midpoint sum).
#[test]
fn environment_beams_and_samples_carry_the_maps_light() {
    let dir = temp_dir("env-weights");
    let env = environment(&sky_map(&dir, 8));
    let mut rng = rand_pcg::Pcg64::seed_from_u64(11);
    let n = 400_000;
    let (mut sum, mut sum2) = (0.0, 0.0);
    for _ in 0..n {
        let s = env.next_beam(&mut rng).scale;
        assert!(s.is_finite() && s >= 0.0);
        sum += s;
        sum2 += s * s;
    }
    let mean = sum / n as f64;
    let se = ((sum2 / n as f64 - mean * mean) / n as f64).sqrt();
    assert!(se < 5e-3, "not sharp: {se}");
    assert!((mean - 1.0).abs() < 4.0 * se, "mean beam weight {mean} ± {se}");
    // The spectral factor towards the sun and towards the ground.
    let spd = env.spd();
    for omega in [DVec3::new(0.5, 0.6, -0.62).normalize(), DVec3::new(0.1, -0.9, 0.3).normalize()] {
        let (mut s, mut s2) = (0.0, 0.0);
        let m = 100_000;
        for _ in 0..m {
            let lambda = spd.sample_lambda(uniform(&mut rng));
            let f = env.spectral_factor(omega, -omega, lambda);
            s += f;
            s2 += f * f;
        }
        let mean = s / m as f64;
        let se = ((s2 / m as f64 - mean * mean) / m as f64).sqrt();
        assert!((mean - 1.0).abs() < 4.0 * se + 1e-3, "{omega}: mean factor {mean} ± {se}");
    }
    // Irradiance at a point off the centre, on a surface facing +y.
    let (receiver, normal) = (DVec3::new(0.2, -0.1, 0.3), DVec3::Y);
    let (na, nb) = (256, 128);
    let mut exact = 0.0;
    for a in 0..na {
        for b in 0..nb {
            let phi = 2.0 * PI * (a as f64 + 0.5) / na as f64;
            let theta = PI * (b as f64 + 0.5) / nb as f64;
            let d = DVec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin());
            let cos = d.dot(normal).max(0.0);
            exact +=
                env.radiance(d) * cos * theta.sin() * (2.0 * PI / na as f64) * (PI / nb as f64);
        }
    }
    let (mut s, mut s2) = (0.0, 0.0);
    let m = 200_000;
    for _ in 0..m {
        let e =
            env.sample_towards(receiver, [uniform(&mut rng), uniform(&mut rng)]).map_or(0.0, |t| {
                t.intensity * (-t.direction).dot(normal).max(0.0) / (t.distance * t.distance)
            });
        s += e;
        s2 += e * e;
    }
    let mean = s / m as f64;
    let se = ((s2 / m as f64 - mean * mean) / m as f64).sqrt();
    assert!(se < 0.01 * exact, "not sharp: {se} of {exact}");
    assert!(
        (mean - exact).abs() < 4.0 * se + 2e-3 * exact,
        "irradiance {mean} ± {se}, expected {exact}"
    );
}

/// Y of the white map (every texel 1): D65 of luminance 1, as the film integrates it.
fn white_luminance() -> f64 {
    let steps = 47_000;
    let h = (830.0 - 360.0) / steps as f64;
    let sum: f64 = (0..steps)
        .map(|k| {
            let l = 360.0 + (k as f64 + 0.5) * h;
            d65_visible(l) / d65_luminance() * cmf(l).y
        })
        .sum();
    sum * h / *CIE_Y_INTEGRAL
}

/// A white environment around a diffuse sphere (albedo 0.5) that fills the camera's view:
/// every point of the sphere receives the map's radiance from its whole hemisphere, so every
/// pixel sees `0.5 Y_white` (a convex object alone reflects nothing onto itself).
fn environment_furnace() -> Row {
    let dir = temp_dir("env-furnace");
    let file = dir.join("white.exr");
    write_map(&file, 8, 4, |_, _| [1.0; 3]);
    let json = format!(
        r#"{{
      "camera": {{"position": [0, 0, 3], "look_at": [0, 0, 0], "fov": 30, "width": 16, "height": 16}},
      "objects": [{{"shape": {{"type": "Sphere", "center": [0, 0, 0], "radius": 2}},
                   "material": {{"type": "Diffuse", "reflectance": 0.5}}}}],
      "environment": {{"file": {file:?}}}
    }}"#
    );
    let expected = 0.5 * white_luminance();
    Row {
        name: "environment_furnace",
        scene: Scene::from_json(&json, Path::new("inline.json")).unwrap_or_else(|e| panic!("{e}")),
        auto: IntegratorChoice::Path,
        effects: EffectsMode::Auto,
        closed_form: Some((Box::new(move |_: &Scene, _: usize, _: usize| expected), 1e-4)),
        cells: [all(600_000), all(16 * 16 * 8), all(16 * 16 * 8)],
        glass: None,
        seeds: 12,
        sharp: 0.03,
        mean_z: 4.0,
    }
}

/// The coloured sky (its sun rotated by `rotation`) over a floor with a sphere on it: the
/// background, the sphere and the floor's shadow, every estimator.
fn environment_sky() -> Row {
    let dir = temp_dir("env-sky");
    let file = sky_map(&dir, 8);
    let json = format!(
        r#"{{
      "camera": {{"position": [0, 1.2, 3.5], "look_at": [0, 0.4, 0], "fov": 60, "width": 16, "height": 16}},
      "objects": [{{"shape": {{"type": "Rectangle", "corner": [-2, 0, 2], "edge_u": [4, 0, 0], "edge_v": [0, 0, -4]}},
                   "material": {{"type": "Diffuse", "reflectance": {{"nm": [400, 700], "values": [0.3, 0.7]}}}}}},
                  {{"shape": {{"type": "Sphere", "center": [0, 0.5, 0], "radius": 0.5}},
                   "material": {{"type": "Diffuse", "reflectance": 0.6}}}}],
      "environment": {{"file": {file:?}, "scale": 2,
                      "rotation": [[0.8, 0, 0.6], [0, 1, 0], [-0.6, 0, 0.8]]}}
    }}"#
    );
    Row {
        name: "environment_sky",
        scene: Scene::from_json(&json, Path::new("inline.json")).unwrap_or_else(|e| panic!("{e}")),
        auto: IntegratorChoice::Path,
        effects: EffectsMode::Auto,
        closed_form: None,
        cells: [all(300_000), all(16 * 16 * 8), all(16 * 16 * 8)],
        glass: None,
        seeds: 12,
        sharp: 0.05,
        mean_z: 4.0,
    }
}

#[test]
fn matrix_environment_furnace() {
    check_row(&environment_furnace());
}

#[test]
fn matrix_environment_sky() {
    check_row(&environment_sky());
}

/// Bad environments are refused naming the field and the cause.
#[test]
fn bad_environments_are_refused() {
    let dir = temp_dir("env-bad");
    let good = sky_map(&dir, 8);
    let one_row = dir.join("one_row.exr");
    write_map(&one_row, 8, 1, |_, _| [1.0; 3]);
    let black = dir.join("black.exr");
    write_map(&black, 8, 4, |_, _| [0.0; 3]);
    let cases = [
        (format!(r#"{{"file": {good:?}, "scale": -1}}"#), "scale"),
        (
            format!(r#"{{"file": {good:?}, "rotation": [[1, 0, 0], [0, 2, 0], [0, 0, 1]]}}"#),
            "rotation",
        ),
        (
            format!(r#"{{"file": {good:?}, "rotation": [[-1, 0, 0], [0, 1, 0], [0, 0, 1]]}}"#),
            "rotation",
        ),
        (format!(r#"{{"file": {one_row:?}}}"#), "2 rows"),
        (format!(r#"{{"file": {black:?}}}"#), "file"),
        (r#"{"file": "no-such-map.exr"}"#.to_owned(), "no-such-map.exr"),
        (format!(r#"{{"file": {good:?}, "gamma": 2}}"#), "gamma"),
    ];
    for (environment, expect) in cases {
        let json = format!(
            r#"{{"camera": {{"position": [0, 0, 3], "look_at": [0, 0, 0], "fov": 30, "width": 4, "height": 4}},
                "objects": [{{"shape": {{"type": "Sphere", "center": [0, 0, 0], "radius": 1}},
                             "material": {{"type": "Diffuse", "reflectance": 0.5}}}}],
                "environment": {environment}}}"#
        );
        let e = Scene::from_json(&json, &dir.join("scene.json"))
            .err()
            .unwrap_or_else(|| panic!("{environment} was accepted"));
        let message = e.to_string();
        assert!(message.contains("environment"), "{environment}: {message}");
        assert!(message.contains(expect), "{environment}: {message}");
    }
}

/// Mitsuba's `envmap` becomes the scene's `environment`, its `to_world` rotation kept; a
/// mirrored map and an envmap beside a constant emitter are refused with the line.
#[test]
fn mitsuba_envmaps_import_as_the_environment() {
    let dir = temp_dir("env-import");
    sky_map(&dir, 8);
    let scene = |emitters: &str| {
        format!(
            r#"<scene version="3.0.0">
            <sensor type="perspective"><transform name="to_world"><lookat origin="0,0,5" target="0,0,0" up="0,1,0"/></transform>
              <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film></sensor>
            <shape type="sphere"><bsdf type="diffuse"/></shape>
            {emitters}
            </scene>"#
        )
    };
    let path = dir.join("env.xml");
    std::fs::write(
        &path,
        scene(r#"<emitter type="envmap"><string name="filename" value="sky.exr"/><float name="scale" value="3"/>
                 <transform name="to_world"><rotate y="1" angle="90"/><translate x="4"/></transform></emitter>"#),
    )
    .unwrap();
    let imported = import_mitsuba(&path, &[]).unwrap_or_else(|e| panic!("{e}"));
    let env = &imported.scene["environment"];
    assert_eq!(env["scale"], 3.0);
    assert!(env["file"].as_str().unwrap().ends_with("sky.exr"));
    let rows: [[f64; 3]; 3] = serde_json::from_value(env["rotation"].clone()).unwrap();
    // A quarter turn about +y takes +x to -z.
    assert!((rows[2][0] + 1.0).abs() < 1e-12 && (rows[0][2] - 1.0).abs() < 1e-12, "{rows:?}");
    assert!(Scene::load(&path).is_ok());
    for (emitters, expect) in [
        (
            r#"<emitter type="envmap"><string name="filename" value="sky.exr"/>
             <transform name="to_world"><scale x="-1"/></transform></emitter>"#,
            "rotation",
        ),
        (
            r#"<emitter type="envmap"><string name="filename" value="sky.exr"/></emitter>
             <emitter type="constant"><rgb name="radiance" value="1"/></emitter>"#,
            "constant",
        ),
    ] {
        std::fs::write(&path, scene(emitters)).unwrap();
        let e = import_mitsuba(&path, &[]).err().unwrap_or_else(|| panic!("{emitters} accepted"));
        let message = e.to_string();
        assert!(message.contains("env.xml:") && message.contains(expect), "{message}");
    }
}
