//! The cost of many lights: path-traced samples per second with 1 to 20,000 point lights
//! (issue 27's target: 20,000 lights within 3x of one light's cost per sample), next-event
//! estimation choosing by the light tree (`auto` beyond 16 lights) and, up to 1,000 lights, by
//! `each` (every light at every vertex) for comparison; with the time to load the scene and the
//! relative error of the image after the same samples (how well the choice follows the light).
//!
//! `cargo bench -p spectrace-renderer --bench many_lights [-- SPP]` (release build; 2 threads;
//! 16 spp unless given; the figures are ratios to the one-light scene of the same run, the
//! machines being shared). Times include building the light tree and the first pass's splats
//! of the point lights the camera sees, so that fewer samples weigh them more.

use std::path::Path;
use std::time::Instant;

use spectrace_renderer::{RenderOptions, Scene, render_in_memory};
use spectrace_tracer::{ErrorMeasure, IntegratorChoice};

/// `n` point lights of 1/n W each, scattered in a 4 x 2 x 4 m volume over a floor and a sphere
/// by a fixed low-discrepancy rule; next-event estimation's `light_sampler` as given;
/// independent samples, so that the error estimate is the error's.
fn scene_json(n: usize, light_sampler: &str) -> String {
    let lights: Vec<String> = (0..n)
        .map(|i| {
            let t = i as f64 + 0.5;
            let (x, y, z) = ((t * 0.754_877_7).fract(), (t * 0.569_840_3).fract(), t / n as f64);
            format!(
                r#"{{"type": "PointLight", "position": [{}, {}, {}], "power": {}, "spd": {{"type": "CieIlluminant", "name": "D65"}}}}"#,
                4.0 * x - 2.0,
                0.5 + 2.0 * y,
                4.0 * z - 2.0,
                1.0 / n as f64
            )
        })
        .collect();
    format!(
        r#"{{
  "camera": {{"position": [0, 1.5, 4], "look_at": [0, 0.5, 0], "fov": 50, "width": 128, "height": 128}},
  "objects": [
    {{"shape": {{"type": "Rectangle", "corner": [-3, 0, 3], "edge_u": [6, 0, 0], "edge_v": [0, 0, -6]}},
     "material": {{"type": "Diffuse", "reflectance": 0.5}}}},
    {{"shape": {{"type": "Sphere", "center": [0, 0.5, 0], "radius": 0.5}},
     "material": {{"type": "Diffuse", "reflectance": 0.7}}}}
  ],
  "lights": [{}],
  "settings": {{"light_sampler": "{light_sampler}", "sampler": "independent", "threads": 2}}
}}"#,
        lights.join(",")
    )
}

/// Loads and renders the scene of `n` lights at `spp`: (load seconds, samples per second,
/// relative error of the image).
fn measure(n: usize, light_sampler: &str, spp: u64) -> (f64, f64, f64) {
    let json = scene_json(n, light_sampler);
    let start = Instant::now();
    let scene = Scene::from_json(&json, Path::new("many_lights.json")).expect("a valid scene");
    let load = start.elapsed().as_secs_f64();
    let samples = spp * 128 * 128;
    let options = RenderOptions {
        beams: Some(samples),
        integrator: Some(IntegratorChoice::Path),
        ..RenderOptions::default()
    };
    let start = Instant::now();
    let render = render_in_memory(&scene, &options).expect("a render");
    let seconds = start.elapsed().as_secs_f64();
    let error = render
        .output
        .estimate(ErrorMeasure::RelMse)
        .and_then(|e| e.relative_error)
        .unwrap_or(f64::NAN);
    (load, samples as f64 / seconds, error)
}

fn main() {
    // `cargo bench ... -- 64` for another spp (the first argument that is a number).
    let spp = std::env::args().skip(1).find_map(|a| a.parse().ok()).unwrap_or(16);
    println!("path tracer, 128 x 128 at {spp} spp, 2 threads; point lights of 1/n W each");
    println!(
        "| lights | light_sampler | load (s) | samples/s | cost per sample vs 1 light | relative error |"
    );
    println!("|---|---|---|---|---|---|");
    let (_, one, _) = measure(1, "each", spp);
    for n in [1, 10, 100, 1_000, 10_000, 20_000] {
        for sampler in ["tree", "each"] {
            if sampler == "each" && n > 1_000 {
                continue;
            }
            let (load, rate, error) = measure(n, sampler, spp);
            println!(
                "| {n} | {sampler} | {load:.3} | {rate:.3e} | {:.2}x | {:.1}% |",
                one / rate,
                100.0 * error
            );
        }
    }
}
