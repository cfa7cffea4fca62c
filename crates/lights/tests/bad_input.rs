//! Bad input to `spectrace-lights` through its scene-file forms and constructors: each refusal
//! names the field and its cause, NaN and infinities are refused by the constructors, and
//! extreme finite values are accepted or refused by name, never a panic.

#![allow(clippy::unwrap_used)]

use std::sync::Arc;

use glam::DVec3;
use proptest::prelude::*;
use spectrace_lights::spectrum::CieIlluminant;
use spectrace_lights::*;

fn json_error(json: &str) -> String {
    serde_json::from_str::<Box<dyn LightSource>>(json).unwrap_err().to_string()
}

#[test]
fn bad_lights_are_rejected_with_the_field_named() {
    let spd = r#""spd": {"type": "Blackbody", "kelvin": 3000}"#;
    let cases = [
        (format!(r#"{{"type": "Torch", "power": 1, {spd}}}"#), "Torch"),
        (format!(r#"{{"type": "PointLight", "position": [0, 0, 0], "power": -1, {spd}}}"#), "PointLight.power = -1.0"),
        (format!(r#"{{"type": "Laser", "position": [0, 0, 0], "direction": [0, 0, 0], "power": 1, {spd}}}"#), "Laser.direction"),
        (format!(r#"{{"type": "Laser", "position": [0, 0, 0], "direction": [1, 0, 0], "power": 1, "beam_radius": -1, {spd}}}"#), "Laser.beam_radius"),
        (format!(r#"{{"type": "UniformSpotLight", "position": [0, 0, 0], "direction": [0, 0, 1], "cone_angle": 180, "power": 1, {spd}}}"#), "UniformSpotLight.cone_angle = 180.0"),
        (format!(r#"{{"type": "UniformSpotLight", "position": [0, 0, 0], "direction": [0, 0, 1], "cone_angle": 0, "power": 1, {spd}}}"#), "UniformSpotLight.cone_angle = 0.0"),
        (format!(r#"{{"type": "FadingSpotLight", "position": [0, 0, 0], "direction": [0, 0, 1], "cone_angle": 30, "fade_per_angle": 0, "power": 1, {spd}}}"#), "FadingSpotLight.fade_per_angle = 0.0"),
        (format!(r#"{{"type": "FadingSpotLight", "position": [0, 0, 0], "direction": [0, 0, 1], "cone_angle": 30, "fade_per_angle": 0.01, "power": 1, {spd}}}"#), "longer than the cone"),
        (format!(r#"{{"type": "Sky", "corner": [0, 0, 0], "edge_u": [1, 0, 0], "edge_v": [2, 0, 0], "direction": [0, -1, 0], "power": 1, {spd}}}"#), "degenerate"),
        (format!(r#"{{"type": "Sky", "corner": [0, 0, 0], "edge_u": [1, 0, 0], "edge_v": [0, 0, 1], "direction": [1, 0, 0], "power": 1, {spd}}}"#), "Sky.direction"),
        (format!(r#"{{"type": "RectangleLight", "corner": [0, 0, 0], "edge_u": [0, 0, 0], "edge_v": [0, 0, 1], "power": 1, {spd}}}"#), "RectangleLight.edge_u = [0.0, 0.0, 0.0]: must be non-zero"),
        (format!(r#"{{"type": "DiskLight", "center": [0, 0, 0], "normal": [0, 1, 0], "radius": 0, "power": 1, {spd}}}"#), "DiskLight.radius"),
        (r#"{"type": "PointLight", "position": [0, 0, 0], "power": 1, "spd": {"type": "Blackbody", "kelvin": -1}}"#.to_owned(), "Blackbody.kelvin"),
        (r#"{"type": "PointLight", "position": [0, 0, 0], "power": 1, "spd": {"type": "Monochromatic", "lambda_nm": 500}, "wavelength_sampling": "equal_wavelengths"}"#.to_owned(), "ok"),
        (r#"{"type": "PointLight", "position": [0, 0, 0], "power": 1, "spd": {"type": "Mixture", "components": [{"weight": 1, "spd": {"type": "Monochromatic", "lambda_nm": 500}}, {"weight": 1, "spd": {"type": "Uniform"}}]}, "wavelength_sampling": "equal_wavelengths"}"#.to_owned(), "PointLight.wavelength_sampling"),
        (format!(r#"{{"type": "PointLight", "position": [0, 0, 0], "power": 1, "colour": 3, {spd}}}"#), "colour"),
        (r#"{"type": "LightSet", "lights": []}"#.to_owned(), "LightSet.lights"),
    ];
    for (json, needle) in cases {
        if needle == "ok" {
            // A pure line with equal-wavelength sampling is allowed: it degenerates to the line.
            assert!(serde_json::from_str::<Box<dyn LightSource>>(&json).is_ok(), "{json}");
            continue;
        }
        let e = json_error(&json);
        assert!(
            e.contains(needle),
            "error for {json}\n  was: {e}\n  expected to mention: {needle}"
        );
    }
    // NaN and infinities cannot be written in JSON; the constructors reject them by name.
    for (position, power, field) in [
        (DVec3::new(f64::NAN, 0.0, 0.0), 1.0, "PointLight.position"),
        (DVec3::ZERO, f64::INFINITY, "PointLight.power"),
        (DVec3::ZERO, f64::NAN, "PointLight.power"),
    ] {
        let d65 = Arc::new(CieIlluminant::new("D65").unwrap());
        let e = PointLight::new(position, power, d65, WavelengthSampling::Importance).unwrap_err();
        assert!(e.to_string().starts_with(field), "{e}");
    }
}

// ---------------------------------------------------------------------------------------------
// Extreme finite values

#[test]
fn huge_or_tiny_directions_and_edges_are_judged_on_direction() {
    let spd = r#""spd": {"type": "Blackbody", "kelvin": 3000}"#;
    for d in ["[0, 1e300, 1e300]", "[1e-320, 0, 0]", "[-0.0, 1e200, 0]"] {
        let json = format!(
            r#"{{"type": "Laser", "position": [0, 0, 0], "direction": {d}, "power": 1, {spd}}}"#
        );
        let light: Box<dyn LightSource> =
            serde_json::from_str(&json).unwrap_or_else(|e| panic!("{d}: {e}"));
        assert!(light.power() > 0.0);
    }
    let e = json_error(&format!(
        r#"{{"type": "Laser", "position": [0, 0, 0], "direction": [0, -0.0, 0], "power": 1, {spd}}}"#
    ));
    assert!(e.contains("Laser.direction") && e.contains("non-zero"), "{e}");
    let e = json_error(&format!(
        r#"{{"type": "RectangleLight", "corner": [0, 0, 0], "edge_u": [1e200, 0, 0], "edge_v": [0, 1e200, 0], "power": 1, {spd}}}"#
    ));
    assert!(e.contains("RectangleLight.edge_") && e.contains("too large"), "{e}");
    assert!(!e.contains("parallel") && !e.contains("degenerate"), "{e}");
    let e = json_error(&format!(
        r#"{{"type": "Sky", "corner": [0, 0, 0], "edge_u": [1e200, 0, 0], "edge_v": [3e200, 0, 0], "direction": [0, 0, 1], "power": 1, {spd}}}"#
    ));
    assert!(e.contains("Sky.edge_v") && e.contains("parallel"), "{e}");
    let e = json_error(&format!(
        r#"{{"type": "DiskLight", "center": [0, 0, 0], "normal": [0, 1, 0], "radius": 1e-320, "power": 1, {spd}}}"#
    ));
    assert!(e.contains("DiskLight.radius") && e.contains("too small"), "{e}");
    let e = json_error(&format!(
        r#"{{"type": "DiskLight", "center": [0, 0, 0], "normal": [0, 1, 0], "radius": 1e200, "power": 1, {spd}}}"#
    ));
    assert!(e.contains("DiskLight.radius") && e.contains("too large"), "{e}");
}

fn extreme() -> impl Strategy<Value = f64> {
    prop::sample::select(vec![
        1e-320,
        -1e-320,
        1e200,
        -1e200,
        1e300,
        -1e300,
        -0.0,
        0.0,
        1.0,
        -1.0,
        0.5,
        30.0,
        f64::MAX,
    ])
}

fn jv(a: [f64; 3]) -> String {
    serde_json::to_string(&a).unwrap()
}

fn js(x: f64) -> String {
    serde_json::to_string(&x).unwrap()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    /// Extreme finite values never panic, and an error names a field the light has.
    #[test]
    fn extreme_finite_values_are_accepted_or_refused_naming_a_field(
        kind in 0usize..7,
        a in [extreme(), extreme(), extreme()],
        b in [extreme(), extreme(), extreme()],
        c in [extreme(), extreme(), extreme()],
        x in extreme(),
        y in extreme(),
        power in extreme(),
    ) {
        let spd = r#""spd": {"type": "Blackbody", "kelvin": 3000}"#;
        let p = js(power);
        let (json, fields): (String, &[&str]) = match kind {
            0 => (format!(r#"{{"type": "PointLight", "position": {}, "power": {p}, {spd}}}"#, jv(a)), &["position", "power"]),
            1 => (format!(r#"{{"type": "Laser", "position": {}, "direction": {}, "power": {p}, "beam_radius": {}, {spd}}}"#, jv(a), jv(b), js(x)), &["position", "direction", "power", "beam_radius"]),
            2 => (format!(r#"{{"type": "UniformSpotLight", "position": {}, "direction": {}, "cone_angle": {}, "power": {p}, {spd}}}"#, jv(a), jv(b), js(x)), &["position", "direction", "cone_angle", "power"]),
            3 => (format!(r#"{{"type": "FadingSpotLight", "position": {}, "direction": {}, "cone_angle": {}, "fade_per_angle": {}, "power": {p}, {spd}}}"#, jv(a), jv(b), js(x), js(y)), &["position", "direction", "cone_angle", "fade_per_angle", "power"]),
            4 => (format!(r#"{{"type": "RectangleLight", "corner": {}, "edge_u": {}, "edge_v": {}, "power": {p}, {spd}}}"#, jv(a), jv(b), jv(c)), &["corner", "edge_u", "edge_v", "power"]),
            5 => (format!(r#"{{"type": "DiskLight", "center": {}, "normal": {}, "radius": {}, "power": {p}, {spd}}}"#, jv(a), jv(b), js(x)), &["center", "normal", "radius", "power"]),
            _ => (format!(r#"{{"type": "Sky", "corner": {}, "edge_u": {}, "edge_v": {}, "direction": {}, "power": {p}, {spd}}}"#, jv(a), jv(b), jv(c), jv(b.map(|v| -v))), &["corner", "edge_u", "edge_v", "direction", "power"]),
        };
        if let Err(e) = serde_json::from_str::<Box<dyn LightSource>>(&json) {
            let e = e.to_string();
            let named = fields.iter().any(|f| e.contains(&format!(".{f}")));
            prop_assert!(named, "{json}: {e}");
        }
    }
}
