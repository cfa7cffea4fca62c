//! Scene-file forms: documented JSON parses, JSON and bincode round trips through
//! `Box<dyn Material>`, and errors that name the field.

use glam::DVec3;
use spectrace_materials::{Incoming, Ior, Material};

fn zoo() -> Vec<(&'static str, &'static str)> {
    vec![
        ("Diffuse constant", r#"{"type": "Diffuse", "reflectance": 0.8}"#),
        (
            "Diffuse table",
            r#"{"type": "Diffuse", "reflectance": {"nm": [400, 500, 600, 700], "values": [0.05, 0.1, 0.6, 0.8]}}"#,
        ),
        ("Mirror", r#"{"type": "Mirror", "reflectance": 0.95}"#),
        ("Dielectric constant", r#"{"type": "Dielectric", "ior": 1.5}"#),
        ("Dielectric integer", r#"{"type": "Dielectric", "ior": 2}"#),
        ("Dielectric glass", r#"{"type": "Dielectric", "ior": {"glass": "BK7"}}"#),
        (
            "Dielectric sellmeier",
            r#"{"type": "Dielectric", "ior": {"sellmeier": {"b": [1.03961212, 0.231792344, 1.01046945], "c": [0.00600069867, 0.0200179144, 103.560653]}}}"#,
        ),
        (
            "Dielectric cauchy",
            r#"{"type": "Dielectric", "ior": {"cauchy": {"a": 1.5046, "b": 4200}}}"#,
        ),
        (
            "Dielectric table",
            r#"{"type": "Dielectric", "ior": {"table": {"nm": [400, 700], "n": [1.53, 1.51]}}, "transmittance": {"nm": [400, 700], "values": [0.9, 0.99]}}"#,
        ),
        ("Dielectric water", r#"{"type": "Dielectric", "ior": 1.333, "transmittance": 0.98}"#),
        (
            "Dielectric null",
            r#"{"type": "Dielectric", "ior": {"glass": "fused silica"}, "transmittance": null}"#,
        ),
    ]
}

/// A few scattered beams, to compare materials before and after a trip.
fn fingerprint(material: &dyn Material) -> Vec<(DVec3, f64)> {
    let mut out = Vec::new();
    for (k, lambda) in [420.0, 550.0, 680.0].into_iter().enumerate() {
        for u in [0.01, 0.3, 0.97] {
            let d = DVec3::new(0.3 * k as f64, -1.0, 0.2).normalize();
            if let Some(s) = material
                .scatter(&Incoming { direction: d, normal: DVec3::Y, lambda }, [u, u, 1.0 - u])
            {
                out.push((s.direction, s.weight));
            }
        }
    }
    out
}

#[test]
fn materials_round_trip_through_json_and_bincode() {
    let config = bincode::config::standard();
    for (name, json) in zoo() {
        let material: Box<dyn Material> =
            serde_json::from_str(json).unwrap_or_else(|e| panic!("{name}: {e}"));
        let written = serde_json::to_string(&material).unwrap();
        let again: Box<dyn Material> = serde_json::from_str(&written).unwrap();
        assert_eq!(serde_json::to_string(&again).unwrap(), written, "{name}: JSON changed");
        let bytes = bincode::serde::encode_to_vec(&material, config).unwrap();
        let (from_bincode, _): (Box<dyn Material>, usize) =
            bincode::serde::decode_from_slice(&bytes, config)
                .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(serde_json::to_string(&from_bincode).unwrap(), written, "{name}: bincode");
        let original = fingerprint(material.as_ref());
        assert!(!original.is_empty());
        assert_eq!(fingerprint(again.as_ref()), original, "{name}");
        assert_eq!(fingerprint(from_bincode.as_ref()), original, "{name}");
    }
}

#[test]
fn ior_forms_round_trip_alone() {
    let config = bincode::config::standard();
    for (json, canonical) in [
        ("1.5", "1.5"),
        (r#"{"glass": "bk7"}"#, r#"{"glass":"N-BK7"}"#),
        (r#"{"cauchy": {"a": 1.5}}"#, r#"{"cauchy":{"a":1.5,"b":0.0,"c":0.0}}"#),
        (r#"{"sellmeier": {"b": [1.0], "c": [0.01]}}"#, r#"{"sellmeier":{"b":[1.0],"c":[0.01]}}"#),
        (r#"{"table": {"nm": [500], "n": [1.4]}}"#, r#"{"table":{"nm":[500.0],"n":[1.4]}}"#),
    ] {
        let ior: Ior = serde_json::from_str(json).unwrap();
        assert_eq!(serde_json::to_string(&ior).unwrap(), canonical);
        let bytes = bincode::serde::encode_to_vec(&ior, config).unwrap();
        let (back, _): (Ior, usize) = bincode::serde::decode_from_slice(&bytes, config).unwrap();
        assert_eq!(back, ior);
    }
}

fn error_of(json: &str) -> String {
    serde_json::from_str::<Box<dyn Material>>(json).unwrap_err().to_string()
}

#[test]
fn a_transmittance_out_of_range_is_called_a_transmittance() {
    let message = error_of(r#"{"type": "Dielectric", "ior": 1.5, "transmittance": 1.5}"#);
    assert!(message.contains("a transmittance must lie in [0, 1]"), "{message}");
    assert!(!message.contains("reflectance"), "{message}");
    let message = error_of(
        r#"{"type": "Dielectric", "ior": 1.5, "transmittance": {"nm": [400, 400], "values": [1, 1]}}"#,
    );
    assert!(message.contains("Transmittance: ") && message.contains("nm[1]"), "{message}");
    let message = error_of(r#"{"type": "Dielectric", "ior": 1.5, "transmittance": "clear"}"#);
    assert!(message.contains("expected a transmittance: a number in [0, 1]"), "{message}");
    assert!(message.contains(r#"found a string "clear""#), "{message}");
}

#[test]
fn bad_input_errors_name_the_field() {
    let cases = [
        (
            r#"{"type": "Dielectric", "ior": {"sellmeier": {"b": [1, 0.2, 1], "c": [0.006, 0.02, 0.25]}}}"#,
            "Dielectric.ior.sellmeier.c[2]",
        ),
        (
            r#"{"type": "Dielectric", "ior": {"sellmeier": {"b": [1, 0.2], "c": [0.006]}}}"#,
            "Dielectric.ior.sellmeier.c",
        ),
        (r#"{"type": "Dielectric", "ior": 0.8}"#, "Dielectric.ior = 0.8"),
        (
            r#"{"type": "Dielectric", "ior": {"glass": "BK-7"}}"#,
            "Dielectric.ior.glass: unknown glass `BK-7`; known: N-BK7, BK7",
        ),
        (r#"{"type": "Dielectric", "ior": {"cauchy": {"a": 0.5}}}"#, "Dielectric.ior.cauchy"),
        (
            r#"{"type": "Dielectric", "ior": {"table": {"nm": [400, 500], "n": [1.5, 0.9]}}}"#,
            "Dielectric.ior.table.n[1]",
        ),
        (
            r#"{"type": "Dielectric", "ior": {"selmeier": {"b": [1], "c": [0.01]}}}"#,
            "unknown variant `selmeier`",
        ),
        (r#"{"type": "Dielectric", "ior": {"cauchy": {"a": 1.5, "d": 1}}}"#, "unknown field `d`"),
        (r#"{"type": "Dielectric", "ior": "BK7"}"#, "an index of refraction"),
        (r#"{"type": "Dielectric", "ior": 1.5, "tint": 0.5}"#, "unknown field `tint`"),
        (r#"{"type": "Dielectric"}"#, "missing field `ior`"),
        (r#"{"type": "Diffuse", "reflectance": 1.2}"#, "reflectance must lie in [0, 1]"),
        (
            r#"{"type": "Diffuse", "reflectance": "0.5"}"#,
            "expected a reflectance: a number in [0, 1] or a table {\"nm\": [...], \"values\": [...]}, found a string \"0.5\"",
        ),
        (
            r#"{"type": "Mirror", "reflectance": {"nm": [400, 700], "values": [0.5, "NaN"]}}"#,
            "values[1]: expected a number, found a string \"NaN\"",
        ),
        (r#"{"type": "Diffuse", "reflectance": 0.5, "colour": 1}"#, "unknown field `colour`"),
        (r#"{"type": "Mirror"}"#, "missing field `reflectance`"),
        (r#"{"type": "Velvet"}"#, "Velvet"),
    ];
    for (json, expected) in cases {
        let message = error_of(json);
        assert!(message.contains(expected), "{json}\n  gave: {message}\n  wanted: {expected}");
    }
}
