//! Photometric units in scene files: `lumens` and `candela` instead of `power`, converted to watts
//! exactly through the luminous efficacy of the light's SPD, and the errors for missing,
//! conflicting or meaningless outputs.
#![allow(clippy::unwrap_used)]

use std::f64::consts::PI;

use glam::DVec3;
use rand::SeedableRng;
use rand_pcg::Pcg64;
use spectrace_lights::spectrum::{
    Blackbody, Monochromatic, PEAK_LUMINOUS_EFFICACY, SpectralPowerDistribution, lumens_per_watt,
    luminous_efficacy,
};
use spectrace_lights::*;

fn light(json: &str) -> Box<dyn LightSource> {
    serde_json::from_str(json).unwrap_or_else(|e| panic!("{json}: {e}"))
}

fn json_error(json: &str) -> String {
    match serde_json::from_str::<Box<dyn LightSource>>(json) {
        Ok(l) => panic!("{json} was accepted: {l:?}"),
        Err(e) => e.to_string(),
    }
}

/// A light of a known type from a template (without its `"type"`).
fn concrete<T: serde::de::DeserializeOwned>(json: &str) -> T {
    let untyped = json.split_once(", ").unwrap().1;
    serde_json::from_str(&format!("{{{untyped}")).unwrap_or_else(|e| panic!("{json}: {e}"))
}

fn efficacy(spd_json: &str) -> f64 {
    let spd: Box<dyn SpectralPowerDistribution> = serde_json::from_str(spd_json).unwrap();
    luminous_efficacy(spd.as_ref())
}

/// Relative difference.
fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

const BLACKBODY: &str = r#"{"type": "Blackbody", "kelvin": 3200}"#;
const LINE_555: &str = r#"{"type": "Monochromatic", "lambda_nm": 555}"#;

/// Every light with an output key, with `{out}` for the key and `{spd}` for the spectrum.
const TEMPLATES: [&str; 7] = [
    r#"{"type": "Laser", "position": [0, 1, 0], "direction": [1, 0, 0], {out}, "spd": {spd}}"#,
    r#"{"type": "Sky", "corner": [-1, 2, -1], "edge_u": [2, 0, 0], "edge_v": [0, 0, 2], "direction": [0, -1, 0], {out}, "spd": {spd}}"#,
    r#"{"type": "UniformSpotLight", "position": [0, 2, 0], "direction": [0, -1, 0], "cone_angle": 30, {out}, "spd": {spd}}"#,
    r#"{"type": "FadingSpotLight", "position": [0, 2, 0], "direction": [0, -1, 0], "cone_angle": 30, "fade_per_angle": 0.1, {out}, "spd": {spd}}"#,
    r#"{"type": "PointLight", "position": [0, 2, 0], {out}, "spd": {spd}}"#,
    r#"{"type": "RectangleLight", "corner": [0, 2, 0], "edge_u": [0.5, 0, 0], "edge_v": [0, 0, 0.5], {out}, "spd": {spd}}"#,
    r#"{"type": "DiskLight", "center": [0, 2, 0], "normal": [0, -1, 0], "radius": 0.2, {out}, "spd": {spd}}"#,
];

fn fill(template: &str, out: &str, spd: &str) -> String {
    template.replace("{out}", out).replace("{spd}", spd)
}

#[test]
fn lumens_become_watts_through_the_luminous_efficacy_of_the_spd() {
    let k_blackbody = efficacy(BLACKBODY);
    // Below the 683 lm/W of a line at 555 nm (the SPD is normalised over 360-830 nm).
    assert!(k_blackbody > 0.0 && k_blackbody < 683.0, "{k_blackbody}");
    for template in TEMPLATES {
        let json = fill(template, r#""lumens": 1000"#, BLACKBODY);
        // W = lm / K, computed exactly so.
        assert_eq!(light(&json).power(), 1000.0 / k_blackbody, "{json}");
        // A line at 555 nm: 683 lm/W exactly.
        let json = fill(template, r#""lumens": 683"#, LINE_555);
        assert!(rel(light(&json).power(), 1.0) < 1e-12, "{json}");
        // The same light given in watts has the same power.
        let json = fill(template, r#""power": 2.5"#, BLACKBODY);
        assert_eq!(light(&json).power(), 2.5);
        // Zero lumens is zero watts.
        let json = fill(template, r#""lumens": 0"#, BLACKBODY);
        assert_eq!(light(&json).power(), 0.0);
    }
    assert_eq!(PEAK_LUMINOUS_EFFICACY, 683.0);
}

#[test]
fn candela_sets_the_peak_luminous_intensity() {
    let k = efficacy(BLACKBODY);
    let cd = 5000.0;
    let out = format!(r#""candela": {cd}"#);
    // Uniform spot: flux = cd * 2 pi (1 - cos 30 deg).
    let json = fill(TEMPLATES[2], &out, BLACKBODY);
    let spot: UniformSpotLight = concrete(&json);
    let omega = 2.0 * PI * (1.0 - 30f64.to_radians().cos());
    assert!(rel(UniformSpotLight::solid_angle_of(30.0), omega) < 1e-14);
    assert!(rel(spot.power(), cd * omega / k) < 1e-14);
    assert!(rel(spot.intensity() * k, cd) < 1e-14);
    // Fading spot: flux = cd * (its profile's solid angle), the peak intensity is the candela.
    let json = fill(TEMPLATES[3], &out, BLACKBODY);
    let fading: FadingSpotLight = concrete(&json);
    let omega_fading = FadingSpotLight::solid_angle_of(30.0, 0.1).unwrap();
    // Between the solid angles of the core (20 deg) and of the whole cone.
    assert!(omega_fading > UniformSpotLight::solid_angle_of(20.0) && omega_fading < omega);
    assert!(rel(fading.power(), cd * omega_fading / k) < 1e-14);
    assert!(rel(fading.peak_intensity() * k, cd) < 1e-14);
    // The profile integral is the one the beams are drawn from: the tabulated polar density
    // integrates to the same, to its stated accuracy.
    let table = fading.polar_sampler().integral() * 2.0 * PI;
    assert!(rel(table, omega_fading) < 1e-6, "{table} vs {omega_fading}");
    // Point light: flux = cd * 4 pi, everywhere.
    let json = fill(TEMPLATES[4], &out, BLACKBODY);
    let point: PointLight = concrete(&json);
    assert!(rel(point.power(), cd * 4.0 * PI / k) < 1e-14);
    assert!(rel(point.intensity() * k, cd) < 1e-14);
}

/// Luminous intensity (cd) of `light`'s beams averaged over the cone of half-angle `alpha_deg`
/// around `axis`, from `n` beams at a fixed seed: the luminous power of the beams inside the cone
/// over its solid angle. Returns the estimate and its standard error.
fn axial_candela(light: &dyn LightSource, axis: DVec3, alpha_deg: f64, n: usize) -> (f64, f64) {
    let mut rng = Pcg64::seed_from_u64(20);
    let cos_alpha = alpha_deg.to_radians().cos();
    let omega = 2.0 * PI * (1.0 - cos_alpha);
    let (mut sum, mut sum2) = (0.0, 0.0);
    for _ in 0..n {
        let beam = light.next_beam(&mut rng);
        if beam.direction.dot(axis) >= cos_alpha {
            // Each beam carries power / n watts (times its scale) at its wavelength.
            let x = light.power() * beam.scale * lumens_per_watt(beam.lambda) / omega;
            sum += x;
            sum2 += x * x;
        }
    }
    let mean = sum / n as f64;
    let variance = (sum2 / n as f64 - mean * mean).max(0.0);
    (mean, (variance / n as f64).sqrt())
}

#[test]
fn spots_given_in_candela_send_that_intensity_along_their_axis() {
    // Beams inside 10 degrees of the axis, where both profiles are at their peak (the fading
    // spot's core reaches 20 degrees). A correct light lies within 4.5 standard errors with
    // probability 1 - 7e-6; the standard error is below 1% of the candela, so a flux off by a
    // factor (e.g. a missing 2 pi, or the peak taken per polar angle) fails.
    let spd = r#"{"type": "CieIlluminant", "name": "A"}"#;
    let cd = 1200.0;
    let out = format!(r#""candela": {cd}"#);
    for template in [TEMPLATES[2], TEMPLATES[3]] {
        let spot = light(&fill(template, &out, spd));
        let (estimate, se) = axial_candela(spot.as_ref(), DVec3::NEG_Y, 10.0, 800_000);
        assert!(se < 0.01 * cd, "{template}: standard error {se}");
        assert!(
            (estimate - cd).abs() < 4.5 * se,
            "{template}: {estimate} cd on the axis, expected {cd} (standard error {se})"
        );
    }
}

#[test]
fn output_keys_must_be_exactly_one_and_meaningful() {
    let bb = BLACKBODY;
    let cases = [
        // Two keys.
        (
            fill(TEMPLATES[0], r#""power": 1, "lumens": 100"#, bb),
            "Laser.lumens = 100.0: `power` is given too: give exactly one of `power` (W) or `lumens` (lm)",
        ),
        (
            fill(TEMPLATES[2], r#""power": 1, "candela": 100"#, bb),
            "UniformSpotLight.candela = 100.0: `power` is given too",
        ),
        (
            fill(TEMPLATES[4], r#""lumens": 1, "candela": 100"#, bb),
            "PointLight.candela = 100.0: `lumens` is given too",
        ),
        (
            fill(TEMPLATES[3], r#""power": 1, "lumens": 1, "candela": 100"#, bb),
            "FadingSpotLight.candela = 100.0: `power` and `lumens` are given too",
        ),
        (
            fill(TEMPLATES[5], r#""power": 1, "lumens": 100"#, bb),
            "RectangleLight.lumens = 100.0: `power` is given too",
        ),
        // None.
        (
            fill(TEMPLATES[1], r#""two": 2"#, bb).replace(r#""two": 2, "#, ""),
            "Sky.power = missing: the light's output is missing: give exactly one of `power` (W) or `lumens` (lm)",
        ),
        (
            fill(TEMPLATES[2], r#""two": 2"#, bb).replace(r#""two": 2, "#, ""),
            "UniformSpotLight.power = missing: the light's output is missing: give exactly one of `power` (W), `lumens` (lm) or `candela` (cd)",
        ),
        // Negative.
        (
            fill(TEMPLATES[6], r#""lumens": -1"#, bb),
            "DiskLight.lumens = -1.0: must be finite and >= 0 (lumens)",
        ),
        (
            fill(TEMPLATES[3], r#""candela": -5"#, bb),
            "FadingSpotLight.candela = -5.0: must be finite and >= 0 (candela)",
        ),
        (
            fill(TEMPLATES[4], r#""power": -2"#, bb),
            "PointLight.power = -2.0: must be finite and >= 0 (watts)",
        ),
        // Invisible light: no power gives any lumens.
        (
            fill(TEMPLATES[0], r#""lumens": 5"#, r#"{"type": "Monochromatic", "lambda_nm": 300}"#),
            "Laser.lumens = 5.0: the spectrum has no visible light",
        ),
        (
            fill(
                TEMPLATES[2],
                r#""candela": 5"#,
                r#"{"type": "Uniform", "min_nm": 900, "max_nm": 1000}"#,
            ),
            "UniformSpotLight.candela = 5.0: the spectrum has no visible light",
        ),
        // Too much: the flux overflows.
        (fill(TEMPLATES[4], r#""candela": 1e308"#, bb), "PointLight.candela = 1e308: too large"),
        // Candela only where an intensity profile defines it.
        (fill(TEMPLATES[0], r#""candela": 5"#, bb), "unknown field `candela`"),
        (fill(TEMPLATES[6], r#""candela": 5"#, bb), "unknown field `candela`"),
        // The cone is checked before it turns candela into lumens.
        (
            fill(TEMPLATES[2], r#""candela": 5"#, bb)
                .replace(r#""cone_angle": 30"#, r#""cone_angle": 0"#),
            "UniformSpotLight.cone_angle = 0.0",
        ),
        (
            fill(TEMPLATES[3], r#""candela": 5"#, bb)
                .replace(r#""fade_per_angle": 0.1"#, r#""fade_per_angle": 0.01"#),
            "FadingSpotLight.fade_per_angle = 0.01: the fade",
        ),
    ];
    for (json, needle) in cases {
        let e = json_error(&json);
        assert!(
            e.contains(needle),
            "error for {json}\n  was: {e}\n  expected to mention: {needle}"
        );
    }
}

/// `power`, `lumens` and `candela` with its solid angle, as `power_from_keys` takes them.
type Keys = (Option<f64>, Option<f64>, Option<(f64, f64)>);

#[test]
fn nan_and_infinite_outputs_are_rejected_by_name() {
    // JSON cannot write them; the helper rejects them for any caller.
    let spd = Blackbody::new(3200.0).unwrap();
    let cases: [(Keys, &str); 6] = [
        ((Some(f64::NAN), None, None), "Test.power = NaN"),
        ((Some(f64::INFINITY), None, None), "Test.power = inf"),
        ((None, Some(f64::NAN), None), "Test.lumens = NaN"),
        ((None, Some(f64::INFINITY), None), "Test.lumens = inf"),
        ((None, None, Some((f64::NAN, 1.0))), "Test.candela = NaN"),
        ((None, None, Some((f64::INFINITY, 1.0))), "Test.candela = inf"),
    ];
    for ((power, lumens, candela), needle) in cases {
        let e = power_from_keys("Test", power, lumens, candela, true, &spd).unwrap_err();
        assert!(e.to_string().starts_with(needle), "{e}");
    }
    // A solid angle that no profile has is refused rather than giving 0 or infinite watts.
    for omega in [0.0, -1.0, f64::NAN, 13.0] {
        let e = power_from_keys("Test", None, None, Some((1.0, omega)), true, &spd).unwrap_err();
        assert!(e.to_string().starts_with("Test.candela = 1.0"), "{e}");
    }
    // An invisible spectrum never gives infinite power, even for 0 lumens.
    let uv = Monochromatic::new(300.0).unwrap();
    let e = power_from_keys("Test", None, Some(0.0), None, false, &uv).unwrap_err();
    assert!(e.to_string().contains("no visible light"), "{e}");
    // In watts it is fine.
    assert_eq!(power_from_keys("Test", Some(3.0), None, None, false, &uv).unwrap(), 3.0);
}

#[test]
fn a_round_trip_writes_watts() {
    for (template, out) in [(TEMPLATES[3], r#""candela": 800"#), (TEMPLATES[6], r#""lumens": 800"#)]
    {
        let original = light(&fill(template, out, BLACKBODY));
        let json = serde_json::to_string(&original).unwrap();
        assert!(json.contains(r#""power":"#), "{json}");
        assert!(!json.contains("lumens") && !json.contains("candela"), "{json}");
        let again = light(&json);
        assert_eq!(again.power(), original.power());
    }
}
