//! BDPT against itself (MIS weights of every strategy of sampled paths sum to one) and against
//! the other estimators and closed forms on scenes built in code.
#![allow(clippy::unwrap_used)]

use rand::SeedableRng;
use rand_pcg::Pcg64;
use spectrace_geometry::{Rectangle, Shape, Sphere, World};
use spectrace_lights::LightSet;
use spectrace_materials::Material;

use std::f64::consts::PI;
use std::sync::Arc;

use glam::DVec3;
use spectrace_geometry::Ray;
use spectrace_lights::{LightId, LightSource};
use spectrace_spectrum::CIE_Y_INTEGRAL;

use super::mis::mis_weight;
use super::subpath::Buffers;
use super::vertex::Wavelength;
use super::*;
use crate::{
    CameraRepr, EffectsMode, FovAxis, LightTracer, LightTracerSettings, PathTracer,
    PathTracerSettings, PinholeCamera, RenderPlan, render,
};
use crate::{Effects, Emitter, Integrator, TraceStats};

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

/// Mean Y over the image (the pixels `mask` keeps) of `runs` independent renders (seeds
/// 1..=runs) of `items` work items each (chunks of `chunk`), and its standard error.
fn mean_y(
    integrator: &dyn Integrator,
    runs: u64,
    items: u64,
    chunk: u64,
    mask: &[bool],
) -> (f64, f64) {
    let means: Vec<f64> = (1..=runs)
        .map(|seed| {
            let plan = RenderPlan {
                beams: items,
                chunk_beams: chunk,
                seed,
                threads: 2,
                shard: None,
                time_budget: None,
                error_estimate: false,
                target_error: None,
            };
            let out = render(integrator, &plan, &|_| {}).unwrap();
            let image = out.film.to_xyz(integrator.image_scale(out.beams));
            let kept = image.iter().zip(mask).filter(|(_, keep)| **keep);
            let n = kept.clone().count();
            kept.map(|(p, _)| p.y).sum::<f64>() / n as f64
        })
        .collect();
    let k = means.len() as f64;
    let mean = means.iter().sum::<f64>() / k;
    let var = means.iter().map(|m| (m - mean) * (m - mean)).sum::<f64>() / (k - 1.0);
    (mean, (var / k).sqrt())
}

fn assert_agree(name: &str, a: (f64, f64), b: (f64, f64)) {
    let combined = (a.1 * a.1 + b.1 * b.1).sqrt();
    assert!(a.0 > 0.0 && b.0 > 0.0, "{name}: {a:?} {b:?}");
    // The test is only meaningful if the estimates are precise.
    assert!(combined < 0.05 * a.0, "{name}: standard errors too large: {a:?} {b:?}");
    assert!((a.0 - b.0).abs() < 3.0 * combined, "{name}: {a:?} vs {b:?}");
}

const ALL: [bool; 256] = [true; 256];

fn bdpt_mean(scene: &LightTracerScene<'_>, runs: u64, passes: u64, mask: &[bool]) -> (f64, f64) {
    let bdpt = Bdpt::new(scene, BdptSettings::default(), effects(scene));
    let pixels = bdpt.pass_samples();
    mean_y(&bdpt, runs, passes * pixels, pixels, mask)
}

fn light_mean(scene: &LightTracerScene<'_>, runs: u64, beams: u64, mask: &[bool]) -> (f64, f64) {
    let lt = LightTracer::new(scene, LightTracerSettings::default(), effects(scene));
    mean_y(&lt, runs, beams, 20_000, mask)
}

fn path_mean(scene: &LightTracerScene<'_>, runs: u64, passes: u64) -> (f64, f64) {
    let pt = PathTracer::new(scene, PathTracerSettings::default(), effects(scene));
    let pixels = pt.pass_samples();
    mean_y(&pt, runs, passes * pixels, pixels, &ALL)
}

/// The pixels in which no camera ray (on an 8 x 8 grid) sees shape `shape` first.
fn pixels_not_seeing(fixture: &Fixture, shape: u32) -> Vec<bool> {
    let camera = &fixture.camera;
    let mut mask = vec![true; 256];
    for (p, keep) in mask.iter_mut().enumerate() {
        let (px, py) = ((p % 16) as f64, (p / 16) as f64);
        for k in 0..64 {
            let (u, v) = ((k % 8) as f64 / 7.0, (k / 8) as f64 / 7.0);
            let ray =
                Ray { origin: camera.position(), direction: camera.direction(px + u, py + v) };
            if fixture.world.intersect(&ray, f64::INFINITY).is_some_and(|h| h.primitive == shape) {
                *keep = false;
            }
        }
    }
    mask
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

#[test]
fn mis_weights_of_all_strategies_of_sampled_paths_sum_to_one() {
    for fixture in [box_scene(), caustic_scene(), spot_scene(), furnace_scene(0.6)] {
        let scene = fixture.scene();
        let bdpt = Bdpt::new(&scene, BdptSettings::default(), effects(&scene));
        let mut rng = Pcg64::seed_from_u64(11);
        let mut buffers = Buffers { light: Vec::new(), camera: Vec::new(), mis: Vec::new() };
        let mut stats = TraceStats::default();
        let mut checked = 0;
        let mut strategies = [0usize; 4];
        for i in 0..4000u32 {
            let beam = LightSource::next_beam(scene.lights, &mut rng);
            let density = bdpt.set_spd.value(beam.lambda);
            let wl = Wavelength { lambda: beam.lambda, density };
            let end = bdpt.light_end(beam.parent, &wl).unwrap();
            bdpt.light_subpath(&beam, &end, &wl, true, &mut rng, &mut buffers, &mut stats);
            buffers.camera.clear();
            bdpt.camera_subpath(i % 16, (i / 16) % 16, &wl, &mut rng, &mut buffers, &mut stats);
            let (lv, cv) = (buffers.light.clone(), buffers.camera.clone());
            for t in 1..=cv.len() {
                for s in 0..=lv.len() {
                    if s + t < 2 {
                        continue;
                    }
                    let mis = &mut buffers.mis;
                    let Some(c) = bdpt.connect(
                        Strategy { light: &lv, camera: &cv, s, t },
                        &end,
                        &wl,
                        true,
                        mis,
                    ) else {
                        continue;
                    };
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
                    let sum: f64 = (0..n)
                        .filter(|&k| valid(k))
                        .map(|k| mis_weight(mis, k, c.light_is_delta))
                        .sum();
                    assert!((sum - 1.0).abs() < 1e-9, "({s}, {t}): weights sum to {sum}");
                    checked += 1;
                    strategies[match (s, t) {
                        (0, _) => 0,
                        (1, _) => 1,
                        (_, 1) => 2,
                        _ => 3,
                    }] += 1;
                }
            }
        }
        assert!(checked > 1000, "only {checked} connections");
        assert!(strategies[1] > 0 && strategies[2] > 0, "{strategies:?}");
        // Only the box has two diffuse surfaces that see each other, and a visible emitter.
        if fixture.objects == 5 || fixture.emitters.iter().any(Option::is_some) {
            assert!(strategies[0] > 0 && strategies[3] > 0, "{strategies:?}");
        }
    }
}

#[test]
fn spot_over_a_plane_matches_the_light_and_path_tracers() {
    let fixture = spot_scene();
    let scene = fixture.scene();
    let bdpt = bdpt_mean(&scene, 8, 16, &ALL);
    assert_agree("bdpt vs light", bdpt, light_mean(&scene, 8, 200_000, &ALL));
    assert_agree("bdpt vs path", bdpt, path_mean(&scene, 8, 32));
}

#[test]
fn cornell_box_matches_the_light_and_path_tracers() {
    let fixture = box_scene();
    let scene = fixture.scene();
    let bdpt = bdpt_mean(&scene, 8, 10, &ALL);
    assert_agree("bdpt vs light", bdpt, light_mean(&scene, 8, 80_000, &ALL));
    assert_agree("bdpt vs path", bdpt, path_mean(&scene, 8, 12));
}

#[test]
fn glass_caustic_matches_the_light_tracer() {
    let fixture = caustic_scene();
    let scene = fixture.scene();
    // The light tracer cannot see anything through the glass (its paths end at a diffuse
    // vertex connected to the pinhole): compare the pixels where the sphere is not seen.
    let mask = pixels_not_seeing(&fixture, 1);
    let kept = mask.iter().filter(|k| **k).count();
    assert!((100..240).contains(&kept), "{kept} pixels kept");
    let bdpt = bdpt_mean(&scene, 8, 10, &mask);
    assert_agree("bdpt vs light", bdpt, light_mean(&scene, 8, 80_000, &mask));
    // The caustic is there: the floor under the sphere is brighter than without it.
    let plain = spot_scene();
    let plain_scene = plain.scene();
    let without = light_mean(&plain_scene, 4, 40_000, &mask);
    assert!(bdpt.0 > without.0 + 3.0 * (bdpt.1 + without.1), "{bdpt:?} vs {without:?}");
}

#[test]
fn glowing_furnace_matches_the_closed_form_in_the_renderers_units() {
    // A closed two-sided glowing diffuse sphere seen from inside: L / (1 - a) everywhere.
    let a = 0.6;
    let fixture = furnace_scene(a);
    let scene = fixture.scene();
    let bdpt = Bdpt::new(&scene, BdptSettings::default(), effects(&scene));
    let pt = PathTracer::new(&scene, PathTracerSettings::default(), effects(&scene));
    // The renderer turns every camera integrator's film into an image with the lights'
    // power times the pixels over the samples: BDPT's film must be in the path tracer's
    // units (it was in absolute units, 30x too bright here, the lights' power).
    let (power, pixels) = (scene.lights.power(), bdpt.pass_samples());
    for samples in [256, 4096, 12_345] {
        let renderer = crate::image_scale(power, samples) * pixels as f64;
        assert!((bdpt.image_scale(samples) - renderer).abs() <= 1e-12 * renderer);
        assert_eq!(bdpt.image_scale(samples), pt.image_scale(samples));
    }
    let spd = spectrace_spectrum::Uniform::new(400.0, 700.0).unwrap();
    let l = 30.0 / (2.0 * PI * 4.0 * PI * 1.5 * 1.5);
    let expected = l / (1.0 - a) * spectrace_spectrum::xyz_of(&spd).y / *CIE_Y_INTEGRAL;
    let (mean, se) = mean_y(&bdpt, 6, 8 * pixels, pixels, &ALL);
    assert!((mean - expected).abs() < 4.0 * se, "{mean} vs {expected} (standard error {se})");
    assert!(se < 0.02 * expected, "standard error {se} vs {expected}");
}

#[test]
fn thin_lens_matches_the_path_tracer() {
    // The spot over the plane through a thin lens (aperture 0.05) focused on the plane: camera
    // subpaths start on the lens, t = 1 connections sample the lens; the image mean is the
    // path tracer's within 4 combined standard errors.
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
    let bdpt = bdpt_mean(&scene, 8, 16, &ALL);
    let path = path_mean(&scene, 8, 32);
    let combined = (bdpt.1 * bdpt.1 + path.1 * path.1).sqrt();
    assert!(combined < 0.03 * path.0, "standard errors too large: {bdpt:?} {path:?}");
    assert!((bdpt.0 - path.0).abs() < 4.0 * combined, "bdpt {bdpt:?} vs path {path:?}");
    // The MIS weights of the lens's strategies still sum to one.
    let mut rng = Pcg64::seed_from_u64(3);
    let bdpt = Bdpt::new(&scene, BdptSettings::default(), effects(&scene));
    let mut buffers = Buffers { light: Vec::new(), camera: Vec::new(), mis: Vec::new() };
    let mut stats = TraceStats::default();
    let mut lens_connections = 0;
    for i in 0..2000u32 {
        let beam = LightSource::next_beam(scene.lights, &mut rng);
        let wl = Wavelength { lambda: beam.lambda, density: bdpt.set_spd.value(beam.lambda) };
        let end = bdpt.light_end(beam.parent, &wl).unwrap();
        bdpt.light_subpath(&beam, &end, &wl, true, &mut rng, &mut buffers, &mut stats);
        buffers.camera.clear();
        let (px, py) = (i % 16, (i / 16) % 16);
        bdpt.camera_subpath(px, py, &wl, &mut rng, &mut buffers, &mut stats);
        // The camera subpath starts on the lens.
        let start = buffers.camera[0].point;
        assert!((start - position).length() <= 0.05 + 1e-12);
        let (lv, cv) = (buffers.light.clone(), buffers.camera.clone());
        for t in 1..=cv.len() {
            for s in 0..=lv.len() {
                if s + t < 2 {
                    continue;
                }
                let mis = &mut buffers.mis;
                let Some(c) =
                    bdpt.connect(Strategy { light: &lv, camera: &cv, s, t }, &end, &wl, true, mis)
                else {
                    continue;
                };
                let n = mis.len();
                let valid = |k: usize| {
                    if k == 0 {
                        !mis[0].delta && !c.light_is_delta
                    } else {
                        !mis[k - 1].delta && !mis[k].delta
                    }
                };
                let sum: f64 = (0..n)
                    .filter(|&k| valid(k))
                    .map(|k| mis_weight(mis, k, c.light_is_delta))
                    .sum();
                assert!((sum - 1.0).abs() < 1e-9, "({s}, {t}): weights sum to {sum}");
                if t == 1 {
                    lens_connections += 1;
                }
            }
        }
    }
    assert!(lens_connections > 100, "only {lens_connections} connections to the lens");
}

#[test]
fn passes_are_normalised_per_pixel() {
    let fixture = spot_scene();
    let scene = fixture.scene();
    let bdpt = Bdpt::new(&scene, BdptSettings::default(), effects(&scene));
    assert_eq!(bdpt.name(), "bdpt");
    assert_eq!(bdpt.pass_samples(), 256);
    assert_eq!(bdpt.image_scale(0), 0.0);
    // The film is relative to the lights' power (10 W), as the path tracer's.
    assert_eq!(bdpt.image_scale(512), 10.0 * 0.5);
    let s: BdptSettings = serde_json::from_str(r#"{"max_depth": 3, "rr_depth": 1}"#).unwrap();
    assert_eq!(s, BdptSettings { max_depth: 3, rr_depth: 1, only_strategy: None });
    assert!(serde_json::from_str::<BdptSettings>(r#"{"max_depth": 3, "rr": 1}"#).is_err());
}
