//! Observers and melanopic quantities against closed forms: a point light beside an eye (every
//! quantity is `I x (its response) / r^2`), a white environment (every quantity is `pi L`), the
//! glare rating of a luminaire over a floor computed by hand from CIE 117, and the melanopic
//! EDI of sensors and observers under CIE illuminant A (its DER from the spectrum alone).

use std::f64::consts::PI;
use std::path::{Path, PathBuf};

use spectrace_renderer::{ObservedLux, ObserverReport, Scene, decide_effects, render_observers};
use spectrace_spectrum::{
    CieIlluminant, SpectralPowerDistribution, lumens_per_watt, luminous_efficacy,
    melanopic_edi_per_watt,
};

/// A folder of its own for a test's files.
fn folder(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("spectrace-observers-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The scene of `objects`, `lights` (JSON arrays' contents) and `extra` top-level keys, with
/// one observer at `[0, 1.2, 0]` looking along -z.
fn scene(dir: &Path, objects: &str, lights: &str, extra: &str) -> Scene {
    let json = format!(
        r#"{{
  "camera": {{"position": [0, 1, 5], "look_at": [0, 0, 0], "fov": 40, "width": 8, "height": 8}},
  "objects": [{objects}],
  "lights": [{lights}],
  "observers": [{{"name": "eye", "position": [0, 1.2, 0], "view": [0, 0, -1]}}],
  "settings": {{"observer_spp": 20000}}{extra}
}}"#
    );
    Scene::from_json(&json, &dir.join("scene.json")).unwrap_or_else(|e| panic!("{e}"))
}

/// A small black rectangle far away: a scene needs an object.
const SPECK: &str = r#"{"shape": {"type": "Rectangle", "corner": [50, -50, 50], "edge_u": [0, 0, 0.1],
    "edge_v": [0.1, 0, 0]}, "material": {"type": "Diffuse", "reflectance": 0}}"#;

/// The observers' figures of `scene`.
fn observe(scene: &Scene) -> Vec<ObserverReport> {
    render_observers(scene, 2, decide_effects(scene, None)).unwrap()
}

/// Asserts a quantity within four of its standard errors (and 1e-9 relative) of `want`.
fn assert_lux(what: &str, got: ObservedLux, want: f64) {
    let sigma = got.relative_error.unwrap_or(0.0) * got.lux;
    let tolerance = 4.0 * sigma + 1e-9 * want.abs();
    assert!(
        (got.lux - want).abs() <= tolerance,
        "{what}: {} lx against {want} lx (sigma {sigma})",
        got.lux
    );
}

#[test]
fn a_point_light_beside_the_eye_gives_each_quantity_its_closed_form() {
    let dir = folder("point");
    // 100 W of D65 at (0.6, 0.8, 0) from the eye (1 m away): I = P K / 4 pi, the same every way.
    let light = r#"{"type": "PointLight", "position": [0.6, 2.0, 0], "power": 100,
                    "spd": {"type": "CieIlluminant", "name": "D65"}}"#;
    let scene = scene(&dir, SPECK, light, "");
    let r = &observe(&scene)[0];
    let i = 100.0 * luminous_efficacy(&CieIlluminant::new("D65").unwrap()) / (4.0 * PI);
    // The light is 36.87 degrees above the horizontal, straight to the right of the view
    // (-z): sin theta = 0.6 from the vertical, and it lies at 90 degrees from the facing
    // direction, so it adds nothing to the vertical illuminance facing -z.
    assert_lux("horizontal", r.horizontal, i * 0.8);
    assert_lux("vertical", r.vertical, 0.0);
    assert_lux("cylindrical", r.cylindrical, i * 0.6 / PI);
    // Semi-cylindrical: sin theta (1 + cos 90) / pi.
    assert_lux("semi-cylindrical", r.semicylindrical, i * 0.6 / PI);
    assert_lux("indirect", r.vertical_indirect, 0.0);
    // The same light straight ahead, above the line of sight.
    let ahead = r#"{"type": "PointLight", "position": [0, 2.0, -0.6], "power": 100,
                    "spd": {"type": "CieIlluminant", "name": "D65"}}"#;
    let r = &observe(&self::scene(&dir, SPECK, ahead, ""))[0];
    assert_lux("vertical, ahead", r.vertical, i * 0.6);
    assert_lux("semi-cylindrical, ahead", r.semicylindrical, i * 0.6 * 2.0 / PI);
    // D65 has a melanopic DER of 1 (K_mel,v^D65 is D65's ratio; 1e-4 for the constant's digits
    // plus the wavelength sampling's noise).
    let der = r.melanopic_der.unwrap();
    let noise = 4.0 * r.vertical.relative_error.unwrap();
    assert!((der - 1.0).abs() < 1e-3 + noise, "DER {der}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_white_environment_gives_every_quantity_pi_times_its_luminance() {
    let dir = folder("env");
    let map = dir.join("white.exr");
    exr::prelude::write_rgb_file(&map, 8, 4, |_, _| (1.0f32, 1.0f32, 1.0f32)).unwrap();
    let extra = format!(r#", "environment": {{"file": {map:?}}}"#);
    let scene = scene(&dir, SPECK, "", &extra);
    let lux = crate::photometry::white_environment_lux();
    let r = &observe(&scene)[0];
    for (what, q) in [
        ("horizontal", r.horizontal),
        ("vertical", r.vertical),
        ("cylindrical", r.cylindrical),
        ("semi-cylindrical", r.semicylindrical),
        ("indirect", r.vertical_indirect),
    ] {
        assert_lux(what, q, lux);
        assert!(q.relative_error.unwrap() < 0.01, "{what}: {:?}", q.relative_error);
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// An IES file of 1000 cd everywhere below the horizon, with a flat 0.6 m x 0.6 m luminous
/// opening (metres).
const FLAT_PANEL: &str = "IESNA:LM-63-2002\n[TEST] glare\nTILT=NONE\n1 -1 1 3 1 1 2 0.6 0.6 0\n\
                          1 1 0\n0 45 90\n0\n1000 1000 1000\n";

#[test]
fn the_glare_rating_of_a_panel_over_a_floor_is_cie_117_computed_by_hand() {
    let dir = folder("ugr");
    std::fs::write(dir.join("panel.ies"), FLAT_PANEL).unwrap();
    let floor = r#"{"shape": {"type": "Rectangle", "corner": [-10, 0, -10], "edge_u": [0, 0, 20],
                    "edge_v": [20, 0, 0]}, "material": {"type": "Diffuse", "reflectance": 0.5}}"#;
    // In front of the eye: 1.6 m above it and 3 m ahead. Behind it: not in view.
    let lights = r#"{"type": "IesLight", "file": "panel.ies", "position": [0, 2.8, -3]},
                    {"type": "IesLight", "file": "panel.ies", "position": [0, 2.8, 3]}"#;
    let scene = scene(&dir, floor, lights, "");
    let r = &observe(&scene)[0];
    assert_eq!(r.glare_sources.len(), 1, "{:?}", r.glare_sources);
    let g = r.glare_sources[0];
    assert_eq!(g.light, 0);
    // By hand: r = sqrt(1.6^2 + 3^2) = 3.4 m; the eye is gamma = atan(3 / 1.6) from nadir, so
    // the flat opening shows 0.36 cos gamma = 0.36 x 1.6 / 3.4 m^2.
    let area = 0.36 * 1.6 / 3.4;
    assert!((g.luminance_cd_m2 - 1000.0 / area).abs() < 1e-9 * g.luminance_cd_m2, "{g:?}");
    assert!((g.solid_angle_sr - area / (3.4 * 3.4)).abs() < 1e-12, "{g:?}");
    // Guth: straight above the line of sight (tau = 0) at sigma = atan(1.6 / 3) = 28.07 deg:
    // p = exp(33.98e-3 sigma + 21e-5 sigma^2) = 3.063.
    let sigma = (1.6f64 / 3.0).atan().to_degrees();
    let p = (33.98e-3 * sigma + 21e-5 * sigma * sigma).exp();
    assert!((g.position_index - p).abs() < 1e-9 && (p - 3.063).abs() < 1e-3, "{g:?}");
    // The background: the floor's light on the eye's vertical plane (the luminaires' direct
    // light excluded), L_b = E_ind / pi.
    let e_ind = r.vertical_indirect.lux;
    assert!(e_ind > 0.0 && (r.background_luminance_cd_m2 - e_ind / PI).abs() < 1e-12);
    let l2w = (1000.0 / area).powi(2) * area / (3.4 * 3.4);
    let ugr = 8.0 * (0.25 / (e_ind / PI) * l2w / (p * p)).log10();
    assert!((r.ugr.unwrap() - ugr).abs() < 1e-9, "{:?} against {ugr}", r.ugr);
    // Direct light is not background: the vertical illuminance exceeds the indirect part by the
    // front panel's I cos / r^2 (1000 cd, 3 m ahead of the facing plane at 3.4 m).
    let direct = 1000.0 * (3.0 / 3.4) / (3.4 * 3.4);
    let sigma_v = r.vertical.relative_error.unwrap() * r.vertical.lux
        + r.vertical_indirect.relative_error.unwrap() * e_ind;
    assert!((r.vertical.lux - e_ind - direct).abs() < 4.0 * sigma_v, "{r:?}");
    // A wall between the eye and the panel takes it out of the rating.
    let wall = format!(
        r#"{floor}, {{"shape": {{"type": "Rectangle", "corner": [-5, 1.5, -1], "edge_u": [10, 0, 0],
              "edge_v": [0, 5, 0]}}, "material": {{"type": "Diffuse", "reflectance": 0}}}}"#
    );
    let blocked = self::scene(&dir, &wall, lights, "");
    let r = &observe(&blocked)[0];
    assert!(r.glare_sources.is_empty(), "{:?}", r.glare_sources);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The melanopic DER of a normalised spectrum: m-EDI per lux.
fn der(spd: &dyn SpectralPowerDistribution) -> f64 {
    spd.integrate(&melanopic_edi_per_watt) / spd.integrate(&lumens_per_watt)
}

#[test]
fn sensors_and_observers_under_illuminant_a_read_its_melanopic_der() {
    let dir = folder("melanopic");
    let a = CieIlluminant::new("A").unwrap();
    let want = der(&a);
    assert!((want - 0.4957).abs() < 5e-4, "A's DER {want}");
    let light = r#"{"type": "PointLight", "position": [0, 2.4, -0.5], "power": 100,
                    "spd": {"type": "CieIlluminant", "name": "A"}}"#;
    let sensor = r#", "sensors": [{"type": "IrradianceSensor", "name": "desk", "corner": [-1, 0.75, -1],
                     "edge_u": [0, 0, 2], "edge_v": [2, 0, 0], "cells": [4, 4]}]"#;
    let scene = scene(&dir, SPECK, light, sensor);
    let r = &observe(&scene)[0];
    let got = r.melanopic_der.unwrap();
    assert!((got - want).abs() < 4.0 * r.vertical.relative_error.unwrap() * want + 1e-6);
    // Each sensor cell, filled by the light tracer: m-EDI = DER x lux, to the noise of the
    // wavelengths sampled.
    let options = spectrace_renderer::RenderOptions {
        beams: Some(400_000),
        threads: Some(2),
        integrator: Some(spectrace_tracer::IntegratorChoice::Light),
        ..Default::default()
    };
    let out = spectrace_renderer::render_in_memory(&scene, &options).unwrap();
    let sums = out.output.film.sensor_sums(1.0);
    let e = spectrace_renderer::sensor_grid(
        &scene.sensors,
        0,
        &sums,
        spectrace_lights::LightSource::power(&scene.lights),
        out.output.beams,
    );
    let summary = e.grid.summary();
    assert!(
        (summary.melanopic_der - want).abs() < 0.01 * want,
        "sensor DER {} against {want}",
        summary.melanopic_der
    );
    assert!(e.grid.melanopic_edi.iter().all(|&m| m > 0.0));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_sidecar_lists_each_luminaires_lamps_and_light_output_ratio() {
    let dir = folder("lamps");
    std::fs::write(dir.join("panel.ies"), FLAT_PANEL).unwrap();
    // Two lamps of 1500 lm rated; 1000 cd below the horizon is 2 pi 1000 = 6283 lm of table,
    // so the LOR is 6283 / 3000 = 2.09 (a made-up file: the ratio is reported, not judged).
    let rated = FLAT_PANEL.replace("1 -1 1 3 1 1 2", "2 1500 1 3 1 1 2");
    std::fs::write(dir.join("rated.ies"), rated).unwrap();
    let lights = r#"{"type": "IesLight", "file": "panel.ies", "position": [0, 2.8, -3]},
                    {"type": "IesLight", "file": "rated.ies", "position": [0, 2.8, 3]},
                    {"type": "PointLight", "position": [0, 2, 0], "power": 1,
                     "spd": {"type": "CieIlluminant", "name": "A"}}"#;
    let scene = scene(&dir, SPECK, lights, "");
    let reports: Vec<_> = scene
        .lights
        .lights()
        .iter()
        .map(|l| spectrace_renderer::LightReport::of(l.as_ref()))
        .collect();
    let table = 2.0 * PI * 1000.0;
    let absolute = reports[0].luminaire.unwrap();
    assert_eq!((absolute.lamp_lumens, absolute.light_output_ratio), (None, None));
    assert!((absolute.file_lumens / table - 1.0).abs() < 1e-3, "{absolute:?}");
    let rated = reports[1].luminaire.unwrap();
    assert_eq!((rated.lamp_count, rated.lamp_lumens), (2, Some(3000.0)));
    let lor = rated.light_output_ratio.unwrap();
    assert!(
        (lor - rated.file_lumens / 3000.0).abs() < 1e-12 && (lor - table / 3000.0).abs() < 3e-3
    );
    assert_eq!(rated.stated_light_output_ratio, None, "IES files state none");
    assert!(reports[2].luminaire.is_none());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Renders `scene_path` once whole and once in three shards merged, with `integrator` and
/// `sensor_integrator`, and returns both output folders' reports.
fn whole_and_sharded(
    dir: &Path,
    scene_json: &str,
    integrator: spectrace_tracer::IntegratorChoice,
) -> [spectrace_renderer::RenderReport; 2] {
    use spectrace_renderer::{RenderOptions, merge_parts, render_scene};
    let tag = format!("{integrator:?}");
    let scene_path = dir.join(format!("{tag}.json"));
    std::fs::write(&scene_path, scene_json).unwrap();
    let scene = Scene::load(&scene_path).unwrap();
    let options = |out: &str, shard| RenderOptions {
        beams: Some(3000),
        spp: Some(2),
        threads: Some(2),
        integrator: Some(integrator),
        out_dir: dir.join(out),
        shard,
        ..RenderOptions::default()
    };
    let whole = render_scene(&scene, &options(&format!("{tag}-whole"), None)).unwrap();
    let parts: Vec<PathBuf> = (0..3)
        .map(|k| {
            let report = render_scene(&scene, &options(&format!("{tag}-parts"), Some((k, 3))));
            PathBuf::from(&report.unwrap().outputs[0])
        })
        .collect();
    let merged = merge_parts(&parts, &dir.join(format!("{tag}-merged"))).unwrap();
    [whole, merged]
}

#[test]
fn sensors_and_observers_of_sharded_renders_merge_bit_for_bit() {
    use spectrace_tracer::IntegratorChoice;
    let dir = folder("shards");
    std::fs::write(dir.join("panel.ies"), FLAT_PANEL).unwrap();
    for (integrator, sensor_integrator) in [
        (IntegratorChoice::Path, "path"),
        (IntegratorChoice::Path, "light"),
        (IntegratorChoice::Light, "auto"),
    ] {
        let json = format!(
            r#"{{
  "camera": {{"position": [0, 1.5, 4], "look_at": [0, 0.5, 0], "fov": 50, "width": 16, "height": 12}},
  "objects": [{{"shape": {{"type": "Rectangle", "corner": [-5, 0, -5], "edge_u": [0, 0, 10],
                "edge_v": [10, 0, 0]}}, "material": {{"type": "Diffuse", "reflectance": 0.5}}}}],
  "lights": [{{"type": "IesLight", "file": "panel.ies", "position": [0, 2.8, -3]}}],
  "sensors": [{{"type": "IrradianceSensor", "name": "desk", "corner": [-1, 0.75, -1],
               "edge_u": [0, 0, 2], "edge_v": [2, 0, 0], "cells": [4, 3]}}],
  "observers": [{{"name": "eye", "position": [0, 1.2, 0], "view": [0, 0, -1]}}],
  "settings": {{"observer_spp": 300, "sensor_spp": 7, "sensor_beams": 5000, "chunk_beams": 500,
               "sensor_integrator": "{sensor_integrator}"}}
}}"#
        );
        let [whole, merged] = whole_and_sharded(&dir, &json, integrator);
        let what = format!("{integrator:?} image, {sensor_integrator} sensors");
        let tag = format!("{integrator:?}");
        for file in ["desk.csv", "desk.exr"] {
            let a = std::fs::read(dir.join(format!("{tag}-whole")).join(file)).unwrap();
            let b = std::fs::read(dir.join(format!("{tag}-merged")).join(file)).unwrap();
            assert!(a == b, "{what}: {file} differs");
        }
        let (s, t) = (&whole.sensors[0], &merged.sensors[0]);
        assert_eq!((s.average_lux, s.beams, &s.filled_by), (t.average_lux, t.beams, &t.filled_by));
        assert_eq!(s.average_relative_error, t.average_relative_error, "{what}");
        let (o, p) = (&whole.observers[0], &merged.observers[0]);
        let strip = |r: &ObserverReport| ObserverReport { seconds: 0.0, ..r.clone() };
        assert_eq!(strip(o), strip(p), "{what}");
        assert!(o.ugr.is_some() && o.samples == 300, "{what}: {o:?}");
        // The image too, whatever fills the sensors.
        let a = std::fs::read(dir.join(format!("{tag}-whole/{tag}.exr"))).unwrap();
        let b = std::fs::read(dir.join(format!("{tag}-merged/{tag}.exr"))).unwrap();
        assert!(a == b, "{what}: the image differs");
    }
    // A part whose receivers were tampered with is refused, naming the field.
    let parts: Vec<PathBuf> =
        (0..3).map(|k| dir.join(format!("Path-parts/Path.part-{k}-of-3.bin"))).collect();
    let good = spectrace_renderer::PartialFilm::read(&parts[0]).unwrap();
    let forged = dir.join("forged.bin");
    let check = |part: &spectrace_renderer::PartialFilm, field: &str| {
        std::fs::write(&forged, part.encode().unwrap()).unwrap();
        let list = [forged.clone(), parts[1].clone(), parts[2].clone()];
        let e = spectrace_renderer::merge_parts(&list, &dir.join("forged")).unwrap_err();
        assert!(e.to_string().contains(field), "{field}: {e}");
    };
    let mut p = good.clone();
    p.receivers.sensor_filled_by = "magic".to_owned();
    check(&p, "receivers.sensor_filled_by");
    let mut p = good.clone();
    p.receivers.glare[0][0].luminance_cd_m2 = f64::NAN;
    check(&p, "receivers.glare");
    let mut p = good.clone();
    p.receivers.sensor_pass = None;
    check(&p, "receivers.sensor_pass");
    let mut p = good.clone();
    p.receivers.sensors[0].cells = [0, 3];
    check(&p, "receivers.sensors[0]");
    let mut p = good.clone();
    if let Some(pass) = p.receivers.observer_pass.as_mut() {
        pass.output.beams += 1;
    }
    check(&p, "receivers.observer_pass");
    // A part of another render's receivers (another floor) does not merge with these.
    let mut p = good.clone();
    p.receivers.sensor_floor_lux = 7.0;
    check(&p, "sensors or observers");
    // A missing shard leaves receiver chunks uncovered.
    let e = spectrace_renderer::merge_parts(&parts[..2], &dir.join("short")).unwrap_err();
    assert!(e.to_string().contains("chunks"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A laser of zero width is a line no eye can sample: a render with observers says their
/// figures miss its light.
#[test]
fn observers_beside_a_thin_laser_are_warned_about() {
    let dir = folder("laser");
    let floor = r#"{"shape": {"type": "Rectangle", "corner": [-5, 0, -5], "edge_u": [0, 0, 10],
                    "edge_v": [10, 0, 0]}, "material": {"type": "Diffuse", "reflectance": 0.5}}"#;
    let laser = r#"{"type": "Laser", "position": [0, 1, 0], "direction": [0, -1, 0], "power": 1,
                    "spd": {"type": "CieIlluminant", "name": "D65"}}"#;
    let scene = scene(&dir, floor, laser, "");
    let options = spectrace_renderer::RenderOptions {
        beams: Some(2000),
        spp: Some(1),
        out_dir: dir.join("out"),
        ..Default::default()
    };
    let report = spectrace_renderer::render_scene(&scene, &options).unwrap();
    let warned = report.warnings.iter().any(|w| w.starts_with("observers: lasers"));
    assert!(warned, "{:?}", report.warnings);
    std::fs::remove_dir_all(&dir).unwrap();
}
