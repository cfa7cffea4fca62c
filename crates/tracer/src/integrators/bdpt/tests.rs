//! BDPT against itself: the MIS weights of every strategy of sampled paths sum to one, on scenes
//! built in code (its images against the other estimators and closed forms are the estimator
//! matrix, `tests/tests/integrators.rs`).
#![allow(clippy::unwrap_used)]

use rand::SeedableRng;
use rand_pcg::Pcg64;
use spectrace_geometry::{Rectangle, Shape, Sphere, World};
use spectrace_lights::LightSet;
use spectrace_materials::Material;

use std::sync::Arc;

use glam::DVec3;
use spectrace_lights::{LightId, LightSource};

use super::mis::mis_weight;
use super::subpath::Buffers;
use super::*;
use crate::{CameraRepr, EffectsMode, FovAxis, PinholeCamera};
use crate::{Effects, Emitter, TraceStats};

/// A scene built in code: shapes (with their materials), lights, camera, emitters.
struct Fixture {
    world: World,
    materials: Vec<Arc<dyn Material>>,
    lights: LightSet,
    camera: PinholeCamera,
    emitters: Vec<Option<Emitter>>,
    objects: usize,
}

impl Fixture {
    fn scene(&self) -> LightTracerScene<'_> {
        LightTracerScene::new(&self.world, &self.materials, &self.lights, &self.camera)
            .with_emitters(self.emitters.clone(), self.objects)
    }
}

fn material(json: &str) -> Arc<dyn Material> {
    let m: Box<dyn Material> = serde_json::from_str(json).unwrap();
    Arc::from(m)
}

fn light(json: &str) -> Box<dyn LightSource> {
    serde_json::from_str(json).unwrap()
}

fn rect(corner: [f64; 3], u: [f64; 3], v: [f64; 3]) -> Shape {
    Shape::Rectangle(Rectangle::new(DVec3::from(corner), DVec3::from(u), DVec3::from(v)).unwrap())
}

fn camera(position: [f64; 3], look_at: [f64; 3]) -> PinholeCamera {
    PinholeCamera::new(CameraRepr {
        position: DVec3::from(position),
        look_at: DVec3::from(look_at),
        up: DVec3::Y,
        fov: 50.0,
        fov_axis: FovAxis::Horizontal,
        width: 16,
        height: 16,
        aperture_radius: 0.0,
        focus_distance: None,
    })
    .unwrap()
}

const DIFFUSE: &str = r#"{"type": "Diffuse", "reflectance": 0.7}"#;
const SPOT: &str = r#"{"type": "FadingSpotLight", "position": [0, 1.5, 0], "direction": [0, -1, 0],
    "cone_angle": 35, "fade_per_angle": 0.2, "power": 10, "spd": {"type": "Blackbody", "kelvin": 4000}}"#;

/// A fading spot over a diffuse floor.
fn spot_scene() -> Fixture {
    let shapes = vec![rect([-2.0, 0.0, -2.0], [0.0, 0.0, 4.0], [4.0, 0.0, 0.0])];
    Fixture {
        world: World::new(shapes).unwrap(),
        materials: vec![material(DIFFUSE)],
        lights: LightSet::new(vec![light(SPOT)]).unwrap(),
        camera: camera([0.0, 1.2, 2.0], [0.0, 0.0, 0.0]),
        emitters: Vec::new(),
        objects: 1,
    }
}

/// A Cornell-like box (open at the front) lit by a rectangle under its ceiling, which the
/// camera sees.
fn box_scene() -> Fixture {
    let shapes = vec![
        rect([-1.0, 0.0, -1.0], [0.0, 0.0, 2.0], [2.0, 0.0, 0.0]), // floor
        rect([-1.0, 2.0, -1.0], [2.0, 0.0, 0.0], [0.0, 0.0, 2.0]), // ceiling
        rect([-1.0, 0.0, -1.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]), // back
        rect([-1.0, 0.0, -1.0], [0.0, 2.0, 0.0], [0.0, 0.0, 2.0]), // left
        rect([1.0, 0.0, -1.0], [0.0, 0.0, 2.0], [0.0, 2.0, 0.0]),  // right
        // The light's surface, just below the ceiling.
        rect([-0.3, 1.98, -0.3], [0.6, 0.0, 0.0], [0.0, 0.0, 0.6]),
    ];
    let materials = vec![
        material(DIFFUSE),
        material(DIFFUSE),
        material(DIFFUSE),
        material(r#"{"type": "Diffuse", "reflectance": 0.5}"#),
        material(r#"{"type": "Diffuse", "reflectance": 0.3}"#),
        material(r#"{"type": "Diffuse", "reflectance": 0.0}"#),
    ];
    let area = light(
        r#"{"type": "RectangleLight", "corner": [-0.3, 1.98, -0.3], "edge_u": [0.6, 0, 0],
        "edge_v": [0, 0, 0.6], "power": 20, "spd": {"type": "Blackbody", "kelvin": 5000}}"#,
    );
    let mut emitters = vec![None; 6];
    emitters[5] = Some(Emitter::Light(LightId(0)));
    Fixture {
        world: World::new(shapes).unwrap(),
        materials,
        lights: LightSet::new(vec![area]).unwrap(),
        camera: camera([0.0, 1.0, 3.2], [0.0, 1.0, 0.0]),
        emitters,
        objects: 5,
    }
}

/// A glass sphere under the spot, over the floor: a caustic.
fn caustic_scene() -> Fixture {
    let shapes = vec![
        rect([-2.0, 0.0, -2.0], [0.0, 0.0, 4.0], [4.0, 0.0, 0.0]),
        Shape::Sphere(Sphere::new(DVec3::new(0.0, 0.6, 0.0), 0.35).unwrap()),
    ];
    Fixture {
        world: World::new(shapes).unwrap(),
        materials: vec![material(DIFFUSE), material(r#"{"type": "Dielectric", "ior": 1.5}"#)],
        lights: LightSet::new(vec![light(SPOT)]).unwrap(),
        camera: camera([0.0, 1.4, 1.6], [0.0, 0.2, 0.0]),
        emitters: Vec::new(),
        objects: 2,
    }
}

/// A closed diffuse sphere of reflectance `a` whose surface glows on both sides (radiance
/// `L`), with the camera inside: every pixel sees `L / (1 - a)` (the white furnace).
fn furnace_scene(a: f64) -> Fixture {
    let sphere = Shape::Sphere(Sphere::new(DVec3::ZERO, 1.5).unwrap());
    let emission: crate::ObjectEmission = serde_json::from_str(
        r#"{"power": 30, "spd": {"type": "Uniform", "min_nm": 400, "max_nm": 700},
        "two_sided": true}"#,
    )
    .unwrap();
    let light = crate::ObjectLight::new(sphere.clone(), &emission).unwrap();
    let emitter = Emitter::Object {
        light: LightId(0),
        radiance: light.radiance(),
        two_sided: true,
        area: light.area(),
    };
    let mut camera = camera([0.3, -0.2, 0.1], [0.0, 0.0, -1.0]);
    camera = PinholeCamera::new(CameraRepr { fov: 100.0, ..camera.into() }).unwrap();
    Fixture {
        world: World::new(vec![sphere]).unwrap(),
        materials: vec![material(&format!(r#"{{"type": "Diffuse", "reflectance": {a}}}"#))],
        lights: LightSet::new(vec![Box::new(light)]).unwrap(),
        camera,
        emitters: vec![Some(emitter)],
        objects: 1,
    }
}

fn effects(scene: &LightTracerScene<'_>) -> Effects {
    Effects::decide(scene.features(&[false; 8]), EffectsMode::Off)
}

#[test]
fn mis_weight_counts_only_possible_strategies() {
    let v = |from_light, from_camera, delta| MisVertex { from_light, from_camera, delta };
    // Light, one diffuse vertex, camera: strategies s = 0, 1, 2 with densities
    // p0 = 2 * 3, p1 = 1 * 3, p2 = 1 * 4 (products of the chosen sides' densities).
    let path = [v(1.0, 2.0, false), v(4.0, 3.0, false), v(0.0, 0.0, false)];
    let (p0, p1, p2) = (6.0f64, 3.0f64, 4.0f64);
    let total = p0 * p0 + p1 * p1 + p2 * p2;
    for (s, p) in [(0, p0), (1, p1), (2, p2)] {
        assert!((mis_weight(&path, s, false) - p * p / total).abs() < 1e-15, "s = {s}");
    }
    // A delta light: s = 0 is impossible.
    let total = p1 * p1 + p2 * p2;
    assert!((mis_weight(&path, 1, true) - p1 * p1 / total).abs() < 1e-15);
    // A specular middle vertex: only s = 0 (the camera path hits the light) remains.
    let path = [v(1.0, 2.0, false), v(0.0, 0.0, true), v(0.0, 0.0, false)];
    assert_eq!(mis_weight(&path, 0, false), 1.0);
    assert_eq!(mis_weight(&[], 0, false), 0.0);
}

/// One BDPT sample of pixel `pixel` with fresh subpaths (left in `buffers`); every strategy that
/// gives light is checked: its full path has `s + t` vertices, it is one of the counted
/// strategies, its weight is in (0, 1] and is the weight of its path, and the weights of every
/// counted strategy of that path sum to 1. Returns the `(s, t)` of those strategies.
fn check_sample(
    bdpt: &Bdpt<'_>,
    pixel: (u32, u32),
    rng: &mut Pcg64,
    buffers: &mut Buffers,
) -> Vec<(usize, usize)> {
    let mut stats = TraceStats::default();
    let u = CameraSamples::draw(&bdpt.camera_layout, rng);
    let beam = LightSource::next_beam(bdpt.scene.lights, rng);
    let wl = bdpt.wavelengths(beam.lambda, bdpt.hero.then_some(u.wavelength));
    let end = bdpt.light_end(beam.parent, &wl).unwrap();
    bdpt.light_subpath(&beam, &end, &wl, rng, buffers, &mut stats);
    bdpt.camera_subpath(pixel, &u, &wl, rng, buffers, &mut stats);
    let (lv, cv) = (buffers.light.clone(), buffers.camera.clone());
    let mut gave = Vec::new();
    for t in 1..=cv.len() {
        for s in (0..=lv.len()).filter(|s| s + t >= 2) {
            let mis = &mut buffers.mis;
            let strategy = Strategy { light: &lv, camera: &cv, s, t };
            let Some(c) = bdpt.connect(strategy, &end, &wl, true, mis) else { continue };
            let n = mis.len();
            assert_eq!(n, s + t);
            let valid = |k: usize| {
                if k == 0 {
                    !mis[0].delta && !c.light_is_delta
                } else {
                    !mis[k - 1].delta && !mis[k].delta
                }
            };
            assert!(valid(s), "strategy ({s}, {t}) gave light but is not counted");
            assert!(c.weight > 0.0 && c.weight <= 1.0);
            assert_eq!(c.weight, mis_weight(mis, s, c.light_is_delta));
            let sum: f64 =
                (0..n).filter(|&k| valid(k)).map(|k| mis_weight(mis, k, c.light_is_delta)).sum();
            assert!((sum - 1.0).abs() < 1e-9, "({s}, {t}): weights sum to {sum}");
            gave.push((s, t));
        }
    }
    gave
}

#[test]
fn mis_weights_of_all_strategies_of_sampled_paths_sum_to_one() {
    for fixture in [box_scene(), caustic_scene(), spot_scene(), furnace_scene(0.6)] {
        let scene = fixture.scene();
        let bdpt = Bdpt::new(&scene, BdptSettings::default(), effects(&scene));
        let mut rng = Pcg64::seed_from_u64(11);
        let mut buffers = Buffers { light: Vec::new(), camera: Vec::new(), mis: Vec::new() };
        let mut strategies = [0usize; 4];
        for i in 0..4000u32 {
            for (s, t) in check_sample(&bdpt, (i % 16, (i / 16) % 16), &mut rng, &mut buffers) {
                strategies[match (s, t) {
                    (0, _) => 0,
                    (1, _) => 1,
                    (_, 1) => 2,
                    _ => 3,
                }] += 1;
            }
        }
        let checked: usize = strategies.iter().sum();
        assert!(checked > 1000, "only {checked} connections");
        assert!(strategies[1] > 0 && strategies[2] > 0, "{strategies:?}");
        // Only the box has two diffuse surfaces that see each other, and a visible emitter.
        if fixture.objects == 5 || fixture.emitters.iter().any(Option::is_some) {
            assert!(strategies[0] > 0 && strategies[3] > 0, "{strategies:?}");
        }
    }
}

#[test]
fn mis_weights_of_a_thin_lens_sum_to_one() {
    // The spot over the plane through a thin lens (aperture 0.05) focused on the plane: camera
    // subpaths start on the lens, t = 1 connections sample the lens (with the light vertex's own
    // lens uniforms), and the weights of every strategy still sum to one. (Its image against the
    // path tracer's is a cell of the estimator matrix, `tests/tests/integrators.rs`.)
    let mut fixture = spot_scene();
    let (position, look_at) = (DVec3::new(0.0, 1.2, 2.0), DVec3::ZERO);
    fixture.camera = PinholeCamera::new(CameraRepr {
        aperture_radius: 0.05,
        focus_distance: Some((look_at - position).length()),
        ..fixture.camera.clone().into()
    })
    .unwrap();
    assert!(!fixture.camera.is_pinhole());
    let scene = fixture.scene();
    let mut rng = Pcg64::seed_from_u64(3);
    let bdpt = Bdpt::new(&scene, BdptSettings::default(), effects(&scene));
    let mut buffers = Buffers { light: Vec::new(), camera: Vec::new(), mis: Vec::new() };
    let mut lens_connections = 0;
    for i in 0..2000u32 {
        let gave = check_sample(&bdpt, (i % 16, (i / 16) % 16), &mut rng, &mut buffers);
        // The camera subpath starts on the lens.
        let start = buffers.camera[0].point;
        assert!((start - position).length() <= 0.05 + 1e-12);
        lens_connections += gave.iter().filter(|&&(_, t)| t == 1).count();
    }
    assert!(lens_connections > 100, "only {lens_connections} connections to the lens");
}
