//! The plugin binary renders a scene that uses the plugin's `RingLight`, and the image matches the
//! closed form for the irradiance under a ring.
#![allow(clippy::unwrap_used)]

use std::f64::consts::{PI, TAU};
use std::path::{Path, PathBuf};
use std::process::Command;

use spectrace_lights::spectrum::{CIE_Y_INTEGRAL, Uniform, srgb_to_xyz_matrix, xyz_of};

/// Ring radius, height of the ring above the plane, power (W), plane reflectance.
const RADIUS: f64 = 0.5;
const HEIGHT: f64 = 1.0;
const POWER: f64 = 100.0;
const RHO: f64 = 0.5;
/// Camera height above the plane, looking straight down at the ring's centre; image size.
const CAMERA: f64 = 3.0;
const SIZE: usize = 16;
/// The checked block: the central `BLOCK x BLOCK` pixels.
const BLOCK: usize = 8;
const SEEDS: u64 = 8;
const BEAMS: &str = "200000";

const SCENE: &str = r#"{
  "camera": {"position": [0, 3, 0], "look_at": [0, 0, 0], "up": [0, 0, -1], "fov": 30,
             "width": 16, "height": 16},
  "objects": [{"shape": {"type": "Rectangle", "corner": [-5, 0, 5], "edge_u": [10, 0, 0], "edge_v": [0, 0, -10]},
               "material": {"type": "Diffuse", "reflectance": 0.5}}],
  "lights": [{"type": "RingLight", "center": [0, 1, 0], "axis": [0, 1, 0], "radius": 0.5, "power": 100,
              "spd": {"type": "Uniform", "min_nm": 400, "max_nm": 700}}]
}"#;
/// `fov` of [`SCENE`] (degrees; horizontal, and the image is square).
const FOV: f64 = 30.0;

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("spectrace-ring-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Runs `spectrace-ring` and returns its exit code, stdout and stderr.
fn spectrace_ring(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_spectrace-ring")).args(args).output().unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// The film's Y per pixel (rows top to bottom) from the EXR's linear sRGB.
fn exr_y(path: &Path) -> Vec<f64> {
    use exr::prelude::*;
    let m = srgb_to_xyz_matrix();
    let image = read_first_rgba_layer_from_file(
        path,
        |res, _| (res.width(), vec![0f64; res.width() * res.height()]),
        move |(w, buf), pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            buf[pos.y() * *w + pos.x()] =
                m[1][0] * f64::from(r) + m[1][1] * f64::from(g) + m[1][2] * f64::from(b);
        },
    )
    .unwrap();
    image.layer_data.channel_data.pixels.1
}

/// Irradiance (W m^-2) at distance `r` from the foot of the ring's axis on the plane, by
/// integrating over the ring: each element `dl` is a point source of intensity
/// `P / (4 pi) dl / (2 pi R)` (isotropic, uniform along the circle), seen at `cos = HEIGHT / d`.
/// The trapezoid rule on a smooth periodic integrand converges geometrically; 512 points are exact
/// to rounding here.
fn irradiance_by_quadrature(r: f64) -> f64 {
    let n = 512;
    let mut sum = 0.0;
    for i in 0..n {
        let phi = TAU * i as f64 / n as f64;
        let (dx, dz) = (RADIUS * phi.cos() - r, RADIUS * phi.sin());
        let d2 = dx * dx + dz * dz + HEIGHT * HEIGHT;
        sum += HEIGHT / (d2 * d2.sqrt());
    }
    POWER / (4.0 * PI) * sum / n as f64
}

/// The closed form at the centre: `E = P h / (4 pi (R^2 + h^2)^(3/2))`.
fn irradiance_at_centre() -> f64 {
    POWER * HEIGHT / (4.0 * PI * (RADIUS * RADIUS + HEIGHT * HEIGHT).powf(1.5))
}

/// The film's expected Y over the central block: the mean over its area on the image plane of
/// `Y(rho E / pi)` (Lambertian radiance in film units of the uniform 400-700 nm spectrum), with
/// `sub x sub` points per pixel.
fn expected_block_y(sub: usize) -> f64 {
    let spd = Uniform::new(400.0, 700.0).unwrap();
    let y_per_radiance = xyz_of(&spd).y / *CIE_Y_INTEGRAL;
    let half = (FOV.to_radians() / 2.0).tan();
    let first = (SIZE - BLOCK) / 2;
    let mut sum = 0.0;
    for py in first..first + BLOCK {
        for px in first..first + BLOCK {
            for j in 0..sub {
                for i in 0..sub {
                    let x = px as f64 + (i as f64 + 0.5) / sub as f64;
                    let y = py as f64 + (j as f64 + 0.5) / sub as f64;
                    // Image-plane coordinates at distance 1; the plane point is CAMERA times them.
                    let sx = (2.0 * x / SIZE as f64 - 1.0) * half;
                    let sy = (1.0 - 2.0 * y / SIZE as f64) * half;
                    let r = CAMERA * (sx * sx + sy * sy).sqrt();
                    sum += RHO / PI * irradiance_by_quadrature(r) * y_per_radiance;
                }
            }
        }
    }
    sum / (BLOCK * BLOCK * sub * sub) as f64
}

#[test]
fn the_quadrature_matches_the_closed_form_at_the_centre() {
    let (q, c) = (irradiance_by_quadrature(0.0), irradiance_at_centre());
    assert!((q - c).abs() < 1e-12 * c, "{q} vs {c}");
    // Off-centre the irradiance changes (the quadrature is not a constant).
    assert!((irradiance_by_quadrature(0.3) - c).abs() > 1e-3 * c);
}

/// Renders the ring over a diffuse plane with `SEEDS` seeds through the plugin binary, and checks
/// the mean Y of the central block against [`expected_block_y`]. Tolerance: 5 standard errors of
/// the mean over the seeds (Student's t with 7 degrees of freedom exceeds 5 with probability
/// 1.6e-3, so a correct renderer fails that rarely), plus 0.1% for evaluating the expectation at
/// 8 x 8 points per pixel (it differs from 16 x 16 points by far less; asserted below).
#[test]
fn ring_light_over_a_diffuse_plane_matches_the_closed_form() {
    let dir = temp_dir("plane");
    let scene = dir.join("ring.json");
    std::fs::write(&scene, SCENE).unwrap();
    let first = (SIZE - BLOCK) / 2;
    let means: Vec<f64> = (0..SEEDS)
        .map(|seed| {
            let out = dir.join(format!("out-{seed}"));
            let seed = (11 + seed).to_string();
            let (code, stdout, stderr) = spectrace_ring(&[
                "render",
                scene.to_str().unwrap(),
                "--beams",
                BEAMS,
                "--seed",
                &seed,
                "--threads",
                "2",
                "--quiet",
                "--out",
                out.to_str().unwrap(),
            ]);
            assert_eq!(code, 0, "{stdout}{stderr}");
            assert!(!stderr.contains("warning"), "{stderr}");
            let sidecar: serde_json::Value =
                serde_json::from_str(&std::fs::read_to_string(out.join("ring.json")).unwrap())
                    .unwrap();
            assert_eq!(sidecar["exr_scale_log2"], 0, "{sidecar}");
            assert_eq!(sidecar["rejected_contributions"], 0, "{sidecar}");
            // The ring implements only the seed's beam generator: `auto` falls back to the
            // light tracer, and the sidecar says why.
            assert_eq!(sidecar["integrator"], "light", "{sidecar}");
            let reason = sidecar["integrator_reason"].as_str().unwrap_or_default();
            assert!(reason.contains("only generates beams"), "{sidecar}");
            let y = exr_y(&out.join("ring.exr"));
            assert_eq!(y.len(), SIZE * SIZE);
            let mut s = 0.0;
            for py in first..first + BLOCK {
                for px in first..first + BLOCK {
                    s += y[py * SIZE + px];
                }
            }
            s / (BLOCK * BLOCK) as f64
        })
        .collect();
    let n = SEEDS as f64;
    let mean = means.iter().sum::<f64>() / n;
    let se = (means.iter().map(|m| (m - mean).powi(2)).sum::<f64>() / (n - 1.0) / n).sqrt();
    let expected = expected_block_y(8);
    let finer = expected_block_y(16);
    assert!((expected - finer).abs() < 1e-4 * finer, "{expected} vs {finer}");
    assert!(
        (mean - expected).abs() < 5.0 * se + 1e-3 * expected,
        "{mean} vs {expected} (standard error {se}; per seed {means:?})"
    );
    assert!(se < 0.01 * expected, "the test must be sharp: standard error {se} vs {expected}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn an_unknown_light_type_is_still_named() {
    // The plugin binary is the whole command line: a scene error names the field and the type.
    let dir = temp_dir("unknown");
    let scene = dir.join("candle.json");
    std::fs::write(&scene, SCENE.replace("RingLight", "CandleLight")).unwrap();
    let (code, _, stderr) =
        spectrace_ring(&["render", scene.to_str().unwrap(), "--out", dir.to_str().unwrap()]);
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("lights") && stderr.contains("CandleLight"), "{stderr}");
    let _ = std::fs::remove_dir_all(&dir);
}
