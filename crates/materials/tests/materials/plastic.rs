//! Plastic (a dielectric coating over a Lambertian base): sampled directions against `pdf`,
//! the delta/diffuse split against Fresnel, reciprocity, energy (a white base reflects at most
//! 1), `ior` 1 = Lambertian, roughness 0 = smooth, two-sidedness, bundles, scene-file forms
//! and errors, finiteness for any input.

use std::f64::consts::FRAC_1_PI;

use glam::DVec3;
use proptest::prelude::*;
use rand::SeedableRng;
use rand_pcg::Pcg64;
use spectrace_materials::spectrum::Reflectance;
use spectrace_materials::{
    Distribution, Incoming, Ior, Material, Plastic, ScatterKind, Transport, fresnel_dielectric,
    scatter_each,
};
use spectrace_sampling::ONE_MINUS_EPSILON;

use crate::harness::{
    Grid, albedo, albedo_from_eval, axis_across, chi2_directions_around, integrate_sphere,
    reciprocity_error,
};
use crate::{ALPHA, random_unit, sphere, uniform};

fn plastic(r: f64, n: f64, alpha: f64) -> Plastic {
    Plastic::new(Reflectance::constant(r).unwrap(), Ior::constant(n).unwrap(), alpha).unwrap()
}

fn normal() -> DVec3 {
    DVec3::new(-0.3, 0.2, 0.9).normalize()
}

/// A direction away from the surface at `degrees` from the normal, in front (or `behind`).
fn away(degrees: f64, behind: bool) -> DVec3 {
    let n = normal();
    let frame = spectrace_sampling::Frame::from_normal(n);
    let t = degrees.to_radians();
    let z = if behind { -t.cos() } else { t.cos() };
    frame.to_world(DVec3::new(t.sin() * 0.6, t.sin() * 0.8, z)).normalize()
}

const INCIDENCES: [(f64, bool); 5] =
    [(0.0, false), (45.0, false), (70.0, false), (87.0, false), (30.0, true)];

/// Mean weight of the samples of each kind (zero where absorbed), over `n` samples.
fn split(m: &dyn Material, wi: DVec3, n: u64, seed: u64) -> (f64, f64, f64, f64) {
    let mut rng = Pcg64::seed_from_u64(seed);
    let incoming = Incoming { direction: -wi, normal: normal(), lambda: 550.0 };
    let (mut spec, mut spec2, mut diff, mut diff2) = (0.0, 0.0, 0.0, 0.0);
    for _ in 0..n {
        let u = [uniform(&mut rng), uniform(&mut rng), uniform(&mut rng)];
        if let Some(s) = m.scatter(&incoming, u) {
            if s.kind == ScatterKind::Specular {
                spec += s.weight;
                spec2 += s.weight * s.weight;
            } else {
                diff += s.weight;
                diff2 += s.weight * s.weight;
            }
        }
    }
    let nf = n as f64;
    let se = |s: f64, s2: f64| ((s2 / nf - (s / nf).powi(2)).max(0.0) / nf).sqrt();
    (spec / nf, se(spec, spec2), diff / nf, se(diff, diff2))
}

#[test]
fn sampled_directions_follow_pdf_smooth_and_rough() {
    let cases = [
        (0.0, Grid::default()),
        (0.05, Grid { cos_bins: 400, phi_bins: 400, sub: 4 }),
        (0.3, Grid::default()),
        (0.7, Grid::default()),
    ];
    let mut seed = 300;
    for (alpha, grid) in cases {
        let material = plastic(0.6, 1.5, alpha);
        for (degrees, behind) in INCIDENCES {
            seed += 1;
            let wi = away(degrees, behind);
            // A sharp lobe near the normal needs the grid's pole away from it (see
            // `chi2_directions_around`); elsewhere the normal is the better pole, since then the
            // horizon, where the rough lobe's pdf jumps to 0, is a bin boundary.
            let axis =
                if alpha == 0.05 && degrees < 30.0 { axis_across(normal(), wi) } else { normal() };
            let r =
                chi2_directions_around(&material, wi, normal(), axis, 550.0, 200_000, seed, grid);
            assert!(r.p_value > ALPHA, "alpha {alpha} {degrees} behind {behind}: {r:?}");
            if alpha == 0.0 {
                // The pdf integrates to the diffuse share: 1 - the fraction of delta samples
                // (binomial standard error).
                let se = (r.delta_fraction * (1.0 - r.delta_fraction) / 200_000.0).sqrt();
                assert!(
                    (r.pdf_integral - (1.0 - r.delta_fraction)).abs() < 4.0 * se + 1e-3,
                    "{r:?}"
                );
                assert!(r.delta_fraction > 0.0);
            } else {
                assert_eq!(r.delta_fraction, 0.0);
                assert!(r.pdf_integral <= 1.0 + 1e-3, "{r:?}");
            }
        }
    }
}

#[test]
fn the_smooth_coating_reflects_fresnel_and_the_diffuse_part_matches_eval() {
    for (r, n) in [(0.5, 1.5), (0.9, 1.33), (0.1, 2.0)] {
        let material = plastic(r, n, 0.0);
        for (k, (degrees, behind)) in INCIDENCES.into_iter().enumerate() {
            let wi = away(degrees, behind);
            let cos = degrees.to_radians().cos();
            let (spec, spec_se, diff, diff_se) = split(&material, wi, 200_000, 500 + k as u64);
            let f = fresnel_dielectric(cos, n);
            // Delta lobe: expected weight F(cos_i).
            assert!((spec - f).abs() < 4.0 * spec_se + 1e-9, "{r} {n} {degrees}: {spec} vs {f}");
            // Diffuse: the quadrature of eval (the non-delta part).
            let quad = albedo_from_eval(&material, wi, normal(), 550.0, Grid::default());
            assert!(
                (diff - quad).abs() < 4.0 * diff_se + 1e-3,
                "{r} {n} {degrees}: {diff} vs {quad}"
            );
            // Closed form of the diffuse albedo: (1 - F_i) R T / (eta^2 (1 - R) + R T),
            // with T = eta^2 (1 - F_dr) in [0, 1].
            assert!(quad < (1.0 - f) * r + 1e-3, "{quad}");
        }
    }
}

#[test]
fn a_white_base_reflects_at_most_everything() {
    // Smooth coating: exactly 1 (F + (1 - F) T / T) to quadrature accuracy; rough: <= 1,
    // less by the microfacet loss.
    let n = normal();
    for alpha in [0.0, 0.05, 0.1, 0.3, 0.7, 1.0] {
        let material = plastic(1.0, 1.5, alpha);
        for (k, (degrees, behind)) in INCIDENCES.into_iter().enumerate() {
            let wi = away(degrees, behind);
            let (mc, se) =
                albedo(&material, wi, n, 550.0, Transport::Importance, 100_000, 40 + k as u64);
            assert!(mc <= 1.0 + 4.0 * se + 1e-9, "alpha {alpha} {degrees}: {mc} +- {se}");
            if alpha == 0.0 {
                assert!((mc - 1.0).abs() < 4.0 * se + 1e-9, "smooth white {degrees}: {mc} +- {se}");
            } else if degrees < 80.0 {
                assert!(mc > 0.9, "alpha {alpha} {degrees}: {mc}");
            }
        }
    }
}

#[test]
fn rough_albedo_matches_the_quadrature_of_eval() {
    let n = normal();
    for (alpha, grid) in [
        (0.05, Grid { cos_bins: 400, phi_bins: 400, sub: 4 }),
        (0.3, Grid { cos_bins: 100, phi_bins: 100, sub: 4 }),
        (0.7, Grid { cos_bins: 100, phi_bins: 100, sub: 4 }),
    ] {
        let material = plastic(0.7, 1.6, alpha);
        for (k, (degrees, behind)) in INCIDENCES.into_iter().enumerate() {
            let wi = away(degrees, behind);
            let (mc, se) =
                albedo(&material, wi, n, 550.0, Transport::Radiance, 100_000, 60 + k as u64);
            // A sharp lobe near the normal is integrated with the grid's pole across it.
            let axis = if alpha < 0.1 && degrees < 30.0 { axis_across(n, wi) } else { n };
            let quad = integrate_sphere(axis, grid, |wo| {
                material.eval(wi, wo, n, 550.0) * wo.dot(n).abs()
            });
            assert!(
                (mc - quad).abs() < 4.0 * se + 2e-3,
                "alpha {alpha} {degrees}: {mc} +- {se} vs {quad}"
            );
            assert!(mc <= 1.0);
        }
    }
}

#[test]
fn plastic_is_reciprocal_on_both_sides() {
    for alpha in [0.0, 0.2, 0.8] {
        let material = Plastic::new(
            Reflectance::from_table(&[400.0, 700.0], &[0.2, 0.9]).unwrap(),
            Ior::glass("BK7").unwrap(),
            alpha,
        )
        .unwrap();
        for transport in [Transport::Importance, Transport::Radiance] {
            let e = reciprocity_error(&material, normal(), 480.0, transport, 20_000, 12);
            assert!(e < 1e-12, "alpha {alpha}: {e}");
        }
    }
}

#[test]
fn an_index_of_one_is_the_lambertian_base() {
    // No coating: F = 0, so eval = R / pi exactly, nothing is specular, every weight is R.
    for alpha in [0.0, 0.3] {
        let material = plastic(0.6, 1.0, alpha);
        let mut rng = Pcg64::seed_from_u64(4);
        for _ in 0..2000 {
            let (a, b) = (random_unit(&mut rng), random_unit(&mut rng));
            let f = material.eval(a, b, normal(), 550.0);
            let expected =
                if a.dot(normal()) * b.dot(normal()) > 0.0 { 0.6 * FRAC_1_PI } else { 0.0 };
            assert!((f - expected).abs() < 1e-12, "{f} {expected}");
            let incoming = Incoming { direction: -a, normal: normal(), lambda: 550.0 };
            let u = [uniform(&mut rng), uniform(&mut rng), uniform(&mut rng)];
            let s = material.scatter(&incoming, u).unwrap();
            assert_eq!(s.kind, ScatterKind::Diffuse);
            assert!((s.weight - 0.6).abs() < 1e-12, "{s:?}");
        }
    }
}

#[test]
fn rough_at_roughness_zero_is_the_smooth_plastic_and_the_back_mirrors_the_front() {
    let smooth = plastic(0.4, 1.5, 0.0);
    let tiny = plastic(0.4, 1.5, 5e-4);
    let mut rng = Pcg64::seed_from_u64(6);
    for _ in 0..5000 {
        let incoming = Incoming {
            direction: random_unit(&mut rng),
            normal: random_unit(&mut rng),
            lambda: 400.0 + 300.0 * uniform(&mut rng),
        };
        let u = [uniform(&mut rng), uniform(&mut rng), uniform(&mut rng)];
        assert_eq!(tiny.scatter(&incoming, u), smooth.scatter(&incoming, u));
        // Two-sided: the same beam onto the flipped normal gives the same outcome.
        let front = smooth.scatter(&incoming, u);
        let back = smooth.scatter(&Incoming { normal: -incoming.normal, ..incoming }, u);
        match (front, back) {
            (Some(a), Some(b)) => {
                assert!((a.weight - b.weight).abs() < 1e-12 && (a.pdf - b.pdf).abs() < 1e-9);
                assert_eq!(a.kind, b.kind);
            }
            (a, b) => assert_eq!(a.is_some(), b.is_some()),
        }
    }
    assert!(!smooth.is_specular() && !smooth.is_dispersive());
}

#[test]
fn bundles_match_scattering_each_wavelength() {
    let ramp = Reflectance::from_table(&[400.0, 550.0, 700.0], &[0.0, 0.3, 0.9]).unwrap();
    let materials = [
        Plastic::new(ramp.clone(), Ior::constant(1.5).unwrap(), 0.0).unwrap(),
        Plastic::new(ramp, Ior::constant(1.4).unwrap(), 0.25).unwrap(),
    ];
    let mut rng = Pcg64::seed_from_u64(18);
    for m in &materials {
        for trial in 0..3000 {
            let (direction, normal) = (random_unit(&mut rng), random_unit(&mut rng));
            let lambdas: Vec<f64> = (0..4).map(|_| 380.0 + 400.0 * uniform(&mut rng)).collect();
            let weights: Vec<f64> =
                (0..4).map(|j| if (trial + j) % 5 == 0 { 0.0 } else { 0.25 }).collect();
            let u = [uniform(&mut rng), uniform(&mut rng), uniform(&mut rng)];
            let (mut a, mut b) = (weights.clone(), weights.clone());
            let fast =
                m.scatter_bundle(direction, normal, &lambdas, &mut a, u, Transport::Radiance);
            let each = scatter_each(m, direction, normal, &lambdas, &mut b, u, Transport::Radiance);
            assert_eq!(fast, each, "{m:?}");
            assert_eq!(a, b);
        }
    }
}

#[test]
fn a_dispersive_coating_keeps_energy_and_one_direction_per_bundle() {
    let material =
        Plastic::new(Reflectance::constant(1.0).unwrap(), Ior::glass("SF11").unwrap(), 0.2)
            .unwrap();
    assert!(!material.is_dispersive());
    for (k, lambda) in [380.0, 455.0, 700.0].into_iter().enumerate() {
        let wi = away(40.0, false);
        let (mc, se) =
            albedo(&material, wi, normal(), lambda, Transport::Importance, 100_000, 90 + k as u64);
        assert!(mc <= 1.0 + 4.0 * se && mc > 0.9, "{lambda}: {mc} +- {se}");
    }
}

#[test]
fn scene_forms_round_trip_and_errors_name_the_field() {
    let config = bincode::config::standard();
    for json in [
        r#"{"type": "Plastic", "reflectance": 0.5}"#,
        r#"{"type": "Plastic", "reflectance": {"nm": [400, 500, 600, 700], "values": [0.05, 0.1, 0.6, 0.8]}, "ior": {"glass": "BK7"}}"#,
        r#"{"type": "Plastic", "reflectance": 0.3, "ior": 1.49, "roughness": 0.2}"#,
    ] {
        let m: Box<dyn Material> = serde_json::from_str(json).unwrap();
        let written = serde_json::to_string(&m).unwrap();
        let again: Box<dyn Material> = serde_json::from_str(&written).unwrap();
        assert_eq!(serde_json::to_string(&again).unwrap(), written);
        let bytes = bincode::serde::encode_to_vec(&m, config).unwrap();
        let (back, _): (Box<dyn Material>, usize) =
            bincode::serde::decode_from_slice(&bytes, config).unwrap();
        assert_eq!(serde_json::to_string(&back).unwrap(), written);
        let incoming = Incoming { direction: -away(30.0, false), normal: normal(), lambda: 500.0 };
        for u0 in [0.01, 0.5, 0.99] {
            assert_eq!(
                back.scatter(&incoming, [u0, 0.3, 0.7]),
                m.scatter(&incoming, [u0, 0.3, 0.7])
            );
        }
    }
    let default: Box<dyn Material> =
        serde_json::from_str(r#"{"type": "Plastic", "reflectance": 0.5}"#).unwrap();
    assert!(serde_json::to_string(&default).unwrap().contains(r#""ior":1.5,"roughness":0.0"#));
    let cases = [
        (
            r#"{"type": "Plastic", "reflectance": 0.5, "roughness": -1}"#,
            "Plastic.roughness = -1.0: a roughness (GGX alpha) must be finite and >= 0",
        ),
        (
            r#"{"type": "Plastic", "reflectance": 0.5, "ior": 0}"#,
            "Plastic.ior = 0.0: an index of refraction must be finite and >= 1",
        ),
        (r#"{"type": "Plastic", "reflectance": 0.5, "ior": -1.5}"#, "Plastic.ior = -1.5"),
        (
            r#"{"type": "Plastic", "reflectance": 0.5, "ior": {"glass": "nope"}}"#,
            "Plastic.ior.glass: unknown glass `nope`",
        ),
        (r#"{"type": "Plastic", "reflectance": 1.5}"#, "reflectance must lie in [0, 1]"),
        (r#"{"type": "Plastic", "ior": 1.5}"#, "missing field `reflectance`"),
        (
            r#"{"type": "Plastic", "reflectance": 0.5, "roughness_u": 0.1}"#,
            "unknown field `roughness_u`",
        ),
    ];
    for (json, expected) in cases {
        let message = serde_json::from_str::<Box<dyn Material>>(json).unwrap_err().to_string();
        assert!(message.contains(expected), "{json}\n  gave: {message}\n  wanted: {expected}");
    }
    let e =
        Plastic::new(Reflectance::constant(0.5).unwrap(), Ior::constant(1.5).unwrap(), f64::NAN)
            .unwrap_err();
    assert_eq!(e.field_path(), "Plastic.roughness");
}

fn uniform01() -> impl Strategy<Value = f64> {
    prop_oneof![1 => Just(0.0), 1 => Just(ONE_MINUS_EPSILON), 1 => Just(-1.0), 1 => Just(f64::NAN), 6 => 0.0..1.0]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(3000))]

    #[test]
    fn scatter_eval_and_pdf_are_finite_for_any_input(
        (du, dv) in (0.0..1.0f64, 0.0..1.0f64),
        (ou, ov) in (0.0..1.0f64, 0.0..1.0f64),
        graze in prop_oneof![3 => Just(None), 1 => (-1e-9..1e-9f64).prop_map(Some)],
        lambda in prop_oneof![360.0..830.0f64, Just(100.0), Just(5000.0)],
        u in [uniform01(), uniform01(), uniform01()],
        alpha in prop_oneof![Just(0.0), Just(1e-3), 0.0..2.0f64],
        r in prop_oneof![Just(0.0), Just(1.0), 0.0..1.0f64],
    ) {
        let normal = DVec3::new(0.0, 0.6, 0.8);
        let mut d = sphere(du, dv);
        if let Some(z) = graze {
            d = ((d - d.dot(normal) * normal).normalize_or(DVec3::X) + z * normal).normalize();
        }
        let wo = sphere(ou, ov);
        let m = plastic(r, 1.5, alpha);
        if let Some(s) = m.scatter(&Incoming { direction: d, normal, lambda }, u) {
            prop_assert!(s.weight.is_finite() && s.weight > 0.0, "{s:?}");
            prop_assert!((s.direction.length() - 1.0).abs() < 1e-12);
            prop_assert!(s.direction.dot(normal) * d.dot(normal) <= 0.0, "two-sided: {s:?}");
            prop_assert!(s.pdf.is_finite() && s.pdf >= 0.0);
        }
        let f = m.eval(-d, wo, normal, lambda);
        let p = m.pdf(-d, wo, normal, lambda);
        prop_assert!(f.is_finite() && f >= 0.0 && p.is_finite() && p >= 0.0, "{f} {p}");
    }
}

/// A Beckmann coating (`"distribution": "beckmann"`, Mitsuba's `roughplastic` default): sampled
/// directions follow the pdf (chi-square), the albedo of the samples matches the quadrature of
/// `eval` (4 standard errors + 2e-3, as for GGX), it stays reciprocal, and the scene form keeps
/// the distribution.
#[test]
fn a_beckmann_coating_samples_its_pdf_and_keeps_its_albedo_and_reciprocity() {
    let n = normal();
    let mut seed = 900;
    for alpha in [0.3, 0.7] {
        let material = Plastic::with_facets(
            Reflectance::constant(0.6).unwrap(),
            Ior::constant(1.5).unwrap(),
            alpha,
            Distribution::Beckmann,
        )
        .unwrap();
        assert_eq!(material.distribution(), Distribution::Beckmann);
        for (k, (degrees, behind)) in INCIDENCES.into_iter().enumerate() {
            seed += 1;
            let wi = away(degrees, behind);
            let r =
                chi2_directions_around(&material, wi, n, n, 550.0, 200_000, seed, Grid::default());
            assert!(r.p_value > ALPHA, "alpha {alpha} {degrees} behind {behind}: {r:?}");
            let (mc, se) =
                albedo(&material, wi, n, 550.0, Transport::Radiance, 100_000, 70 + k as u64);
            let grid = Grid { cos_bins: 100, phi_bins: 100, sub: 4 };
            let quad =
                integrate_sphere(n, grid, |wo| material.eval(wi, wo, n, 550.0) * wo.dot(n).abs());
            assert!(
                (mc - quad).abs() < 4.0 * se + 2e-3,
                "alpha {alpha} {degrees}: {mc} +- {se} vs {quad}"
            );
        }
        for transport in [Transport::Importance, Transport::Radiance] {
            let e = reciprocity_error(&material, n, 480.0, transport, 20_000, 13);
            assert!(e < 1e-12, "alpha {alpha}: {e}");
        }
    }
    let m: Box<dyn Material> = serde_json::from_str(
        r#"{"type": "Plastic", "reflectance": 0.3, "roughness": 0.2, "distribution": "beckmann"}"#,
    )
    .unwrap();
    let json = serde_json::to_string(&m).unwrap();
    assert!(json.contains(r#""distribution":"beckmann""#), "{json}");
}
