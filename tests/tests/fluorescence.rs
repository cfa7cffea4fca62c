//! Fluorescence through the whole renderer: a fluorescent plane under a narrow-band violet
//! point light against the closed form of its re-emitted (and elastically reflected)
//! radiance, for every estimator; and the estimators against each other on the shipped scene.

use std::f64::consts::PI;

use glam::DVec3;
use spectrace_renderer::Scene;
use spectrace_spectrum::{CIE_Y_INTEGRAL, SpectralPowerDistribution, Tabulated, Xyz, cmf};
use spectrace_tracer::IntegratorChoice;

use crate::rendering::{PLANE_LIGHT, block_stats, render_with, scene};

/// The lit-plane scene of `rendering.rs` (camera straight above a plane y = 0, a 100 W point
/// light at [`PLANE_LIGHT`] out of view) with a plane of `material` (JSON) and a violet light
/// whose spectrum is a triangle 400-410 nm.
fn plane(material: &str) -> Scene {
    scene(&format!(
        r#"{{
  "camera": {{"position": [0, 3, 0.001], "look_at": [0, 0, 0], "up": [0, 0, -1], "fov": 60, "width": 32, "height": 32}},
  "objects": [{{"shape": {{"type": "Rectangle", "corner": [-3, 0, 3], "edge_u": [6, 0, 0], "edge_v": [0, 0, -6]}},
               "material": {material}}}],
  "lights": [{{"type": "PointLight", "position": [2.2, 1, 0.2], "power": 100,
              "spd": {{"type": "Tabulated", "nm": [400, 405, 410], "values": [0, 1, 0]}}}}],
  "settings": {{"max_depth": 8}}
}}"#
    ))
}

/// The fluorescent material of the plane.
const FLUORESCENT: &str = r#"{"type": "Fluorescent", "reflectance": 0.5,
  "absorption": {"nm": [300, 380, 450, 500], "values": [0.0, 0.8, 0.6, 0.0]},
  "emission": {"type": "Tabulated", "nm": [480, 530, 600], "values": [0, 1, 0]},
  "quantum_yield": 0.9}"#;

/// The absorbed fraction of the plane: linear between its table's points.
fn absorbed(lambda: f64) -> f64 {
    let (x, y) = ([300.0, 380.0, 450.0, 500.0], [0.0, 0.8, 0.6, 0.0]);
    for i in 0..3 {
        if lambda >= x[i] && lambda <= x[i + 1] {
            return y[i] + (y[i + 1] - y[i]) * (lambda - x[i]) / (x[i + 1] - x[i]);
        }
    }
    0.0
}

/// XYZ per unit of `I cos / r^2` leaving the plane towards the camera, in film units: the
/// re-emitted part `Y integral(a s) / pi` with the emission's colour, plus the elastic part
/// `R (1 - a(lambda)) s(lambda) / pi` at the light's wavelengths.
fn xyz_per_irradiance() -> Xyz {
    let light = Tabulated::new(&[400.0, 405.0, 410.0], &[0.0, 1.0, 0.0]).unwrap();
    let emission = Tabulated::new(&[480.0, 530.0, 600.0], &[0.0, 1.0, 0.0]).unwrap();
    let absorbed_fraction = light.integrate(&absorbed);
    // The absorption is linear across the light's symmetric band: the integral is a(405).
    assert!((absorbed_fraction - absorbed(405.0)).abs() < 1e-9);
    let colour = |spd: &dyn SpectralPowerDistribution, f: &dyn Fn(f64) -> f64| Xyz {
        x: spd.integrate(&|l| f(l) * cmf(l).x),
        y: spd.integrate(&|l| f(l) * cmf(l).y),
        z: spd.integrate(&|l| f(l) * cmf(l).z),
    };
    let reemitted = colour(&emission, &|_| 0.9 * absorbed_fraction);
    let elastic = colour(&light, &|l| 0.5 * (1.0 - absorbed(l)));
    (reemitted + elastic) * (1.0 / (PI * *CIE_Y_INTEGRAL))
}

/// The expected image of the fluorescent [`plane`]: per pixel, the closed form at 4 points.
fn expected_image(s: &Scene) -> Vec<Xyz> {
    let per = xyz_per_irradiance();
    let intensity = 100.0 / (4.0 * PI);
    let (w, h) = (s.camera.width(), s.camera.height());
    let mut out = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let mut e = 0.0;
            for (sx, sy) in [(0.125, 0.125), (0.375, 0.625), (0.625, 0.375), (0.875, 0.875)] {
                let d = s.camera.direction(f64::from(x) + sx, f64::from(y) + sy);
                let o = s.camera.position();
                let p: DVec3 = o + d * (-o.y / d.y);
                let to = PLANE_LIGHT - p;
                let r2 = to.length_squared();
                e += intensity * (to.y / r2.sqrt()) / r2 / 4.0;
            }
            out.push(per * e);
        }
    }
    out
}

/// Means over seeds of the image totals of X, Y and Z, with their standard errors.
fn totals(images: &[Vec<Xyz>]) -> [(f64, f64); 3] {
    let n = images.len() as f64;
    let per_seed: Vec<[f64; 3]> = images
        .iter()
        .map(|img| {
            let t = img.iter().fold(Xyz::default(), |a, &b| a + b);
            [t.x, t.y, t.z]
        })
        .collect();
    std::array::from_fn(|c| {
        let mean = per_seed.iter().map(|v| v[c]).sum::<f64>() / n;
        let var = per_seed.iter().map(|v| (v[c] - mean).powi(2)).sum::<f64>() / (n - 1.0);
        (mean, (var / n).sqrt())
    })
}

#[test]
fn a_fluorescent_plane_under_a_violet_light_matches_the_closed_form_with_every_estimator() {
    // Luminance: every 8x8 block's Y within 5 standard errors over 16 seeds (Student's t, 15
    // degrees of freedom: a correct renderer fails a given block with probability 1.6e-4), plus
    // 0.2% for the 4-point evaluation of the closed form. Colour: the image's X, Y and Z totals
    // each within 4 standard errors (+0.2%), so the chromaticity is the emission's mixed with
    // the elastic violet in the closed form's proportion; and the test must be sharp (each
    // total's standard error below 2%).
    let s = plane(FLUORESCENT);
    let expected = expected_image(&s);
    let (w, h) = (32usize, 32usize);
    let exp_blocks = block_stats(&[expected.clone(), expected.clone()], w, h, 8);
    let exp_total = totals(&[expected.clone(), expected]);
    for (integrator, effort) in [
        (IntegratorChoice::Light, 100_000),
        (IntegratorChoice::Path, 32 * 32 * 64),
        (IntegratorChoice::Bdpt, 32 * 32 * 8),
    ] {
        let images: Vec<_> =
            (0..16).map(|k| render_with(&s, integrator, effort, 500 + k).image).collect();
        let name = integrator.name();
        for ((bx, by, mean, se), e) in block_stats(&images, w, h, 8).into_iter().zip(&exp_blocks) {
            assert!(
                (mean - e.2).abs() < 5.0 * se + 0.002 * e.2,
                "{name} block ({bx}, {by}): {mean} vs {} (standard error {se})",
                e.2
            );
        }
        for (c, ((mean, se), (e, _))) in totals(&images).into_iter().zip(exp_total).enumerate() {
            let channel = ["X", "Y", "Z"][c];
            assert!(
                (mean - e).abs() < 4.0 * se + 0.002 * e,
                "{name} {channel}: {mean} vs {e} (standard error {se})"
            );
            assert!(se < 0.02 * e, "{name} {channel}: the test must be sharp: {se} vs {e}");
        }
    }
}

#[test]
fn re_emission_turns_violet_light_green_and_an_ordinary_plane_does_not() {
    // The re-emission goes to the emission's wavelengths only: the closed form's green share is
    // what the renders show, and a plane that does not fluoresce (the same base) reflects the
    // violet light alone. Checked through the chromaticity y/(X+Y+Z) of the whole image.
    let s = plane(FLUORESCENT);
    let plain = plane(r#"{"type": "Diffuse", "reflectance": 0.5}"#);
    let chroma = |img: &[Xyz]| {
        let t = img.iter().fold(Xyz::default(), |a, &b| a + b);
        t.y / (t.x + t.y + t.z)
    };
    let fluorescent = render_with(&s, IntegratorChoice::Path, 32 * 32 * 16, 9).image;
    let violet = render_with(&plain, IntegratorChoice::Path, 32 * 32 * 16, 9).image;
    // Violet light has chromaticity y ~ 0.02; the emission band around 530 nm has y ~ 0.7.
    assert!(chroma(&violet) < 0.1, "plain plane: y = {}", chroma(&violet));
    assert!(chroma(&fluorescent) > 0.5, "fluorescent plane: y = {}", chroma(&fluorescent));
}

#[test]
fn light_and_camera_estimators_agree_on_the_shipped_fluorescence_scene() {
    // The shipped scene (white and UV lights, fluorescent and ordinary cards) at 48 x 24
    // pixels: the light tracer against the path tracer and against BDPT, every 8x8 block and
    // the image mean (see `assert_agree` for the tolerances).
    let s = crate::estimate::small("fluorescence.json", 48, 24);
    assert_eq!(spectrace_renderer::choose_integrator(&s, None).0, IntegratorChoice::Path);
    let light = (IntegratorChoice::Light, 600_000);
    crate::integrators::assert_agree(&s, light, (IntegratorChoice::Path, 48 * 24 * 64), 8);
    crate::integrators::assert_agree(&s, light, (IntegratorChoice::Bdpt, 48 * 24 * 16), 8);
}
