//! The path tracer's two kernels: the batched one against the scalar reference (the default).
//!
//! Both call the same per-vertex steps and every camera path draws from its own sampler, so a
//! path's radiance is the same in either kernel whatever its lane and neighbours, and the exact
//! film makes the order of splats irrelevant. The test therefore asserts equality, not a
//! statistical agreement: the two films must be equal, sum for sum, on every shipped scene
//! (shrunk to a small image), for both samplers.

use std::path::{Path, PathBuf};

use serde_json::Value;
use spectrace_renderer::{RenderOptions, Scene, render_in_memory};
use spectrace_tracer::{IntegratorChoice, Kernel, SamplerKind};

fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap().join("scenes")
}

/// A shipped scene at `width` x `height` pixels with `sampler`, loaded as if it were in
/// `scenes/` (so that its luminaire files resolve).
fn shrunk(path: &Path, width: u32, height: u32, sampler: SamplerKind) -> Scene {
    let mut v: Value = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let camera = v.get_mut("camera").and_then(Value::as_object_mut).unwrap();
    camera.insert("width".to_owned(), width.into());
    camera.insert("height".to_owned(), height.into());
    let settings = v.as_object_mut().unwrap().entry("settings").or_insert(serde_json::json!({}));
    settings.as_object_mut().unwrap().insert("sampler".to_owned(), sampler.name().into());
    Scene::from_json(&v.to_string(), path).unwrap()
}

#[test]
fn the_batched_kernel_renders_the_scalar_image_bit_for_bit_on_every_shipped_scene() {
    let mut paths: Vec<PathBuf> = std::fs::read_dir(scenes_dir())
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "json"))
        .collect();
    paths.sort();
    assert!(paths.len() >= 10, "the shipped scenes are missing");
    let mut lit = 0;
    for path in &paths {
        for sampler in [SamplerKind::Independent, SamplerKind::Sobol] {
            let scene = shrunk(path, 24, 16, sampler);
            let render = |kernel| {
                let options = RenderOptions {
                    integrator: Some(IntegratorChoice::Path),
                    spp: Some(3),
                    seed: Some(7),
                    threads: Some(2),
                    kernel: Some(kernel),
                    ..RenderOptions::default()
                };
                render_in_memory(&scene, &options).unwrap()
            };
            let (batched, scalar) = (render(Kernel::Batched), render(Kernel::Scalar));
            let name = format!("{} ({})", path.display(), sampler.name());
            assert_eq!(batched.output.beams, 3 * 24 * 16, "{name}");
            assert_eq!(batched.output.stats, scalar.output.stats, "{name}: the counters differ");
            assert!(batched.output.film == scalar.output.film, "{name}: the films differ");
            lit += usize::from(batched.image.iter().any(|p| p.y > 0.0));
        }
    }
    // The comparison is not between black images.
    assert!(lit >= paths.len(), "only {lit} of {} renders saw light", 2 * paths.len());
}
