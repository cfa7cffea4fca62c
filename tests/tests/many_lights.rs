//! Many lights: the image of a scene of `N` lights, rendered by the path tracer choosing one
//! light per vertex from a light tree (`settings.light_sampler` `auto`, beyond 16 lights), is
//! the sum of the `N` images of one light each (rendered with every light sampled at every
//! vertex, the other area lights' surfaces standing in as black objects), block by block; and
//! lights of one spectrum share one spectrum object.

use spectrace_renderer::{Scene, tracer_scene};
use spectrace_spectrum::Xyz;
use spectrace_tracer::{IntegratorChoice, LightSamplerKind};

use crate::integrators::{Z_BLOCK, blocks, region_stats};
use crate::rendering::{render_with, scene};

/// One light of the test: its scene-file entry, and for an area light the black object of its
/// shape (a light's surface blocks light and reflects none).
struct TestLight {
    light: String,
    surface: Option<String>,
}

/// The 24 lights of the test: points, spots, rectangles and disks over a 4 x 4 m floor, of
/// two spectra.
fn lights() -> Vec<TestLight> {
    let black = r#""material": {"type": "Diffuse", "reflectance": 0}"#;
    (0..24)
        .map(|i| {
            let t = f64::from(i);
            let p = [1.8 * (t * 0.61).sin(), 0.6 + 0.5 * (1.0 + (t * 0.37).cos()), 1.8 * (t * 1.1).cos()];
            let spd = if i % 3 == 0 {
                r#"{"type": "Blackbody", "kelvin": 3000}"#
            } else {
                r#"{"type": "CieIlluminant", "name": "D65"}"#
            };
            let rectangle = format!(r#""corner": {p:?}, "edge_u": [0.3, 0, 0], "edge_v": [0, 0, 0.3]"#);
            let disk = format!(r#""center": {p:?}, "normal": [0, -1, 0.2], "radius": 0.12"#);
            let (light, surface) = match i % 4 {
                0 => (format!(r#"{{"type": "PointLight", "position": {p:?}, "power": {}, "spd": {spd}}}"#, 2.0 + t), None),
                1 => (format!(r#"{{"type": "UniformSpotLight", "position": {p:?}, "direction": [0.2, -1, 0.1], "cone_angle": 25, "power": 8, "spd": {spd}}}"#), None),
                2 => (
                    format!(r#"{{"type": "RectangleLight", {rectangle}, "power": 6, "spd": {spd}}}"#),
                    Some(format!(r#"{{"shape": {{"type": "Rectangle", {rectangle}}}, {black}}}"#)),
                ),
                _ => (
                    format!(r#"{{"type": "DiskLight", {disk}, "power": 5, "spd": {spd}}}"#),
                    Some(format!(r#"{{"shape": {{"type": "Disk", {disk}}}, {black}}}"#)),
                ),
            };
            TestLight { light, surface }
        })
        .collect()
}

/// A floor and a sphere under the lights `lit` of `all`; the surfaces of the others' area
/// lights stand in as black objects, so that every scene has the same geometry. Seen from
/// above at 32 x 32.
fn scene_of(all: &[TestLight], lit: impl Fn(usize) -> bool) -> Scene {
    let lights: Vec<&str> =
        all.iter().enumerate().filter(|(i, _)| lit(*i)).map(|(_, l)| l.light.as_str()).collect();
    let mut objects = vec![
        r#"{"shape": {"type": "Rectangle", "corner": [-3, 0, 3], "edge_u": [6, 0, 0], "edge_v": [0, 0, -6]},
            "material": {"type": "Diffuse", "reflectance": 0.5}}"#
            .to_owned(),
        r#"{"shape": {"type": "Sphere", "center": [0.2, 0.4, 0], "radius": 0.4},
            "material": {"type": "Diffuse", "reflectance": 0.7}}"#
            .to_owned(),
    ];
    objects.extend(
        all.iter().enumerate().filter(|(i, _)| !lit(*i)).filter_map(|(_, l)| l.surface.clone()),
    );
    scene(&format!(
        r#"{{
  "camera": {{"position": [0, 3, 3.5], "look_at": [0, 0, 0], "fov": 60, "width": 32, "height": 32}},
  "objects": [{}],
  "lights": [{}]
}}"#,
        objects.join(","),
        lights.join(",")
    ))
}

/// Renders `scene` with the path tracer at `spp`, one image per seed.
fn renders(scene: &Scene, spp: u64, seeds: std::ops::Range<u64>) -> Vec<Vec<Xyz>> {
    let pixels = u64::from(scene.camera.width() * scene.camera.height());
    seeds.map(|seed| render_with(scene, IntegratorChoice::Path, spp * pixels, seed).image).collect()
}

/// The image of 24 lights chosen by the tree equals the sum of the 24 one-light images: every
/// 8 x 8 block within [`Z_BLOCK`] combined standard errors (12 seeds a side: Welch's t with
/// about 22 degrees of freedom, beyond 5 with probability 5e-5 per block), the image mean
/// within 4, and the test sharp (standard error under 3% of the mean).
#[test]
fn the_image_of_many_lights_is_the_sum_of_their_one_light_images() {
    let all = lights();
    let many = scene_of(&all, |_| true);
    assert_eq!(tracer_scene(&many).next_event().kind(), LightSamplerKind::Tree);
    let seeds = 12;
    let tree = renders(&many, 16, 0..seeds);
    let mut sum = vec![vec![Xyz::default(); 32 * 32]; seeds as usize];
    for i in 0..all.len() {
        let one = scene_of(&all, |k| k == i);
        assert_eq!(tracer_scene(&one).next_event().kind(), LightSamplerKind::Each);
        let first = 100 * (i as u64 + 1);
        for (total, image) in sum.iter_mut().zip(renders(&one, 4, first..first + seeds)) {
            for (t, p) in total.iter_mut().zip(image) {
                *t += p;
            }
        }
    }
    let keep = vec![true; 32 * 32];
    for ((bx, by), mask) in blocks(32, 32, &keep) {
        let (mt, st) = region_stats(&tree, &mask).unwrap();
        let (ms, ss) = region_stats(&sum, &mask).unwrap();
        let se = st.hypot(ss);
        assert!(
            (mt - ms).abs() <= Z_BLOCK * se,
            "block ({bx}, {by}): tree {mt} vs sum {ms} ({se})"
        );
    }
    let (mt, st) = region_stats(&tree, &keep).unwrap();
    let (ms, ss) = region_stats(&sum, &keep).unwrap();
    let se = st.hypot(ss);
    eprintln!(
        "24 lights: tree vs sum of one-light images: {:+.2} standard errors, {:.2}%",
        (mt - ms) / se,
        100.0 * se / ms
    );
    assert!((mt - ms).abs() <= 4.0 * se, "image means: tree {mt} vs sum {ms} ({se})");
    assert!(se < 0.03 * ms, "the test must be sharp: {se} of {ms}");
}

/// Lights whose spectra are equal in the scene file share one spectrum object, so that the
/// set's spectrum is a mixture of the distinct spectra only (two here, not 24).
#[test]
fn lights_of_one_spectrum_share_it() {
    let many = scene_of(&lights(), |_| true);
    let spds: Vec<_> = many.lights.lights().iter().map(|l| l.spd()).collect();
    let distinct = spds
        .iter()
        .enumerate()
        .filter(|(i, a)| !spds[..*i].iter().any(|b| std::sync::Arc::ptr_eq(a, b)))
        .count();
    assert_eq!(distinct, 2);
}
