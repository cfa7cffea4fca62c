//! The rough dielectric: sampled directions against `pdf` (chi-square) for several roughnesses,
//! anisotropy and incidences (grazing, from inside, beyond the critical angle), `scatter`
//! weights against `eval` and `pdf` in both transports, reciprocity and its `eta^2` law for
//! transmission, energy (with the microfacet loss at high roughness measured), the smooth
//! limit, bundles, scene-file forms and errors, and finiteness for any input.

use glam::DVec3;
use proptest::prelude::*;
use rand::SeedableRng;
use rand_pcg::Pcg64;
use spectrace_materials::spectrum::Transmittance;
use spectrace_materials::{
    Dielectric, Distribution, Incoming, Ior, Material, RoughDielectric, ScatterKind, Transport,
    scatter_each,
};
use spectrace_sampling::ONE_MINUS_EPSILON;

use crate::harness::{
    Grid, albedo, axis_across, chi2_directions, chi2_directions_around, integrate_sphere,
};
use crate::{ALPHA, random_unit, sphere, uniform};

fn rough(n: f64, au: f64, av: f64) -> RoughDielectric {
    RoughDielectric::new(Ior::constant(n).unwrap(), au, av, None).unwrap()
}

/// A tilted normal and a first tangent-ish direction, to test away from the axes.
fn normal() -> DVec3 {
    DVec3::new(0.2, 0.9, -0.3).normalize()
}

/// The direction pointing away from the surface at `degrees` from the normal, outside
/// (`inside = false`) or inside, azimuth `phi` around the normal.
fn away(degrees: f64, inside: bool, phi: f64) -> DVec3 {
    let n = normal();
    let frame = spectrace_sampling::Frame::from_normal(n);
    let t = degrees.to_radians();
    let z = if inside { -t.cos() } else { t.cos() };
    frame.to_world(DVec3::new(t.sin() * phi.cos(), t.sin() * phi.sin(), z)).normalize()
}

/// (degrees, inside) incidences: normal, oblique, grazing, from inside below and beyond the
/// critical angle (41.8 degrees for 1.5).
const INCIDENCES: [(f64, bool); 6] =
    [(0.0, false), (45.0, false), (85.0, false), (20.0, true), (41.0, true), (60.0, true)];

#[test]
fn sampled_directions_follow_pdf_for_each_roughness_and_incidence() {
    let (ggx, beckmann) = (Distribution::Ggx, Distribution::Beckmann);
    let cases: [(f64, f64, Grid, Distribution); 6] = [
        (0.05, 0.05, Grid { cos_bins: 400, phi_bins: 400, sub: 4 }, ggx),
        (0.3, 0.3, Grid { cos_bins: 600, phi_bins: 150, sub: 6 }, ggx),
        // Fine rings around the normal for the refracted lobe, which at normal incidence is
        // narrower than the reflected one by about (n - 1) / n.
        (0.7, 0.7, Grid { cos_bins: 600, phi_bins: 150, sub: 6 }, ggx),
        (0.1, 0.5, Grid { cos_bins: 600, phi_bins: 150, sub: 6 }, ggx),
        (0.3, 0.3, Grid { cos_bins: 600, phi_bins: 150, sub: 6 }, beckmann),
        (0.1, 0.5, Grid { cos_bins: 600, phi_bins: 150, sub: 6 }, beckmann),
    ];
    let mut seed = 100;
    for (au, av, grid, kind) in cases {
        let material = rough(1.5, au, av).with_distribution(kind);
        for (degrees, inside) in INCIDENCES {
            seed += 1;
            let wi = away(degrees, inside, 0.7);
            // Near normal incidence the grid's pole goes across the plane of incidence (both
            // lobes on its equator, see `chi2_directions_around`); elsewhere the normal is the
            // better pole, since then the horizon, where the pdf jumps, is a bin boundary.
            let (axis, grid) = if degrees < 30.0 && au.max(av) < 0.1 {
                (
                    axis_across(normal(), wi),
                    Grid {
                        cos_bins: 200.max(grid.cos_bins),
                        phi_bins: 200.max(grid.phi_bins),
                        sub: 6.max(grid.sub),
                    },
                )
            } else {
                (normal(), grid)
            };
            let r =
                chi2_directions_around(&material, wi, normal(), axis, 550.0, 200_000, seed, grid);
            assert!(
                r.p_value > ALPHA,
                "{kind:?} alpha ({au}, {av}) {degrees} deg inside {inside}: {r:?}"
            );
            assert_eq!(r.delta_fraction, 0.0);
            // The pdf integrates to the fraction not absorbed (the chi-square compares the counts
            // with n times the integral, so this is tested there); at most 1.
            assert!(r.pdf_integral <= 1.0 + 1e-3 && r.pdf_integral > 0.5, "{r:?}");
        }
    }
}

#[test]
fn a_dispersive_rough_glass_samples_each_wavelength_by_its_own_pdf() {
    let material = RoughDielectric::isotropic(Ior::glass("SF11").unwrap(), 0.2, None).unwrap();
    for (k, lambda) in [420.0, 650.0].into_iter().enumerate() {
        let wi = away(30.0, k == 1, 0.3);
        let r = chi2_directions(
            &material,
            wi,
            normal(),
            lambda,
            200_000,
            7 + k as u64,
            Grid::default(),
        );
        assert!(r.p_value > ALPHA, "{lambda}: {r:?}");
    }
    assert!(material.is_dispersive() && !material.is_specular());
}

#[test]
fn scatter_weights_and_pdfs_match_eval_in_both_transports() {
    let material = RoughDielectric::new(
        Ior::constant(1.5).unwrap(),
        0.2,
        0.4,
        Some(Transmittance::constant(0.8).unwrap()),
    )
    .unwrap();
    let n = normal();
    let mut rng = Pcg64::seed_from_u64(5);
    let mut refracted = 0;
    for _ in 0..20_000 {
        let wi = random_unit(&mut rng);
        let u = [uniform(&mut rng), uniform(&mut rng), uniform(&mut rng)];
        let incoming = Incoming { direction: -wi, normal: n, lambda: 550.0 };
        let (Some(a), Some(b)) = (
            material.scatter_with(&incoming, u, Transport::Importance),
            material.scatter_with(&incoming, u, Transport::Radiance),
        ) else {
            continue;
        };
        assert_eq!((a.direction, a.pdf, a.kind), (b.direction, b.pdf, b.kind));
        let wo = a.direction;
        let cos = wo.dot(n).abs();
        let pdf = material.pdf(wi, wo, n, 550.0);
        assert!((a.pdf - pdf).abs() <= 1e-9 * pdf, "{} vs {pdf}", a.pdf);
        // Importance (the beam carries light from wi): f(wi -> wo) |cos| / pdf.
        let f = material.eval_with(wi, wo, n, 550.0, Transport::Importance);
        assert!((a.weight - f * cos / pdf).abs() <= 1e-8 * a.weight, "{a:?} {f}");
        // Radiance (light flows back along the path, from wo to wi): f(wo -> wi) |cos| / pdf.
        let f_back = material.eval_with(wo, wi, n, 550.0, Transport::Radiance);
        assert!((b.weight - f_back * cos / pdf).abs() <= 1e-8 * b.weight, "{b:?} {f_back}");
        // Both transports' eval take light order, so they agree.
        assert_eq!(f, material.eval_with(wi, wo, n, 550.0, Transport::Radiance));
        if a.transmission {
            refracted += 1;
            let (ni, nt) = if wi.dot(n) > 0.0 { (1.0, 1.5) } else { (1.5, 1.0) };
            assert!((b.weight / a.weight - (ni / nt) * (ni / nt)).abs() < 1e-12);
            assert_eq!(a.eta, nt / ni);
        } else {
            assert_eq!(a.weight, b.weight);
        }
    }
    assert!(refracted > 5000, "{refracted}");
}

#[test]
fn reflection_is_reciprocal_and_transmission_obeys_the_eta_squared_law() {
    // Law tested: f(a -> b) / n_b^2 = f(b -> a) / n_a^2, with n the index on each direction's
    // side (for reflection n_a = n_b: plain symmetry).
    for material in [rough(1.5, 0.3, 0.3), rough(1.33, 0.1, 0.6), rough(2.4, 0.8, 0.8)] {
        let eta = material.ior().n(550.0);
        let n = normal();
        let mut rng = Pcg64::seed_from_u64(9);
        let (mut reflections, mut transmissions) = (0, 0);
        for _ in 0..20_000 {
            let (a, b) = (random_unit(&mut rng), random_unit(&mut rng));
            let index = |d: DVec3| if d.dot(n) > 0.0 { 1.0 } else { eta };
            for transport in [Transport::Radiance, Transport::Importance] {
                let fab = material.eval_with(a, b, n, 550.0, transport) / index(b).powi(2);
                let fba = material.eval_with(b, a, n, 550.0, transport) / index(a).powi(2);
                let m = fab.max(fba);
                // Relative rounding of the half vector's normalisation: 1e-7.
                if m > 1e-6 {
                    assert!((fab - fba).abs() <= 1e-7 * m, "{material:?} {a} {b}: {fab} {fba}");
                }
            }
            if material.eval(a, b, n, 550.0) > 1e-9 {
                if a.dot(n) * b.dot(n) > 0.0 { reflections += 1 } else { transmissions += 1 }
            }
        }
        assert!(reflections > 1000 && transmissions > 1000, "{reflections} {transmissions}");
    }
}

#[test]
fn the_radiance_bsdf_integrates_to_the_eta_squared_ratio_over_incoming_directions() {
    // Light entering glass at low roughness: integral f(wi -> wo) |cos wi| dwi over the
    // outside is close to (n_o / n_i)^2 (1 - F), the radiance gain of the smooth boundary
    // (2.25 x 0.96 for normal incidence in glass of 1.5, plus 0.04 reflected inside), while integral f(wi -> wo) |cos wo| dwo
    // (power) stays <= 1: the BSDF is the radiance one, in light order.
    let material = rough(1.5, 0.05, 0.05);
    let n = normal();
    let wo_inside = away(0.0, true, 0.0);
    let grid = Grid { cos_bins: 400, phi_bins: 400, sub: 4 };
    let gain = integrate_sphere(axis_across(n, wo_inside), grid, |wi| {
        material.eval(wi, wo_inside, n, 550.0) * wi.dot(n).abs()
    });
    // Plus the internal reflection seen from inside (F = 0.04 at normal incidence, gain 1).
    let expected = 2.25 * (1.0 - 0.04) + 0.04;
    assert!((gain / expected - 1.0).abs() < 0.02, "{gain} vs {expected}");
    let wi_outside = away(0.0, false, 0.0);
    let power = integrate_sphere(axis_across(n, wi_outside), grid, |wo| {
        material.eval(wi_outside, wo, n, 550.0) * wo.dot(n).abs()
    });
    assert!(power <= 1.0 && power > 0.97, "{power}");
}

#[test]
fn energy_is_never_created_and_the_high_roughness_loss_is_as_measured() {
    // White furnace of one scattering (flux, Importance): albedo <= 1 everywhere, close to 1
    // at low roughness, and the Monte Carlo mean equals the quadrature of eval.
    let n = normal();
    for (alpha, low_out, low_in) in
        [(0.05, 0.998, 0.99), (0.3, 0.97, 0.78), (0.7, 0.88, 0.58), (1.0, 0.80, 0.43)]
    {
        let material = rough(1.5, alpha, alpha);
        for (k, (degrees, inside)) in INCIDENCES.into_iter().enumerate() {
            let wi = away(degrees, inside, 1.1);
            let (mc, se) =
                albedo(&material, wi, n, 550.0, Transport::Importance, 200_000, 20 + k as u64);
            assert!(mc <= 1.0 + 4.0 * se, "alpha {alpha} {degrees} {inside}: {mc} +- {se}");
            let grid = if alpha < 0.1 {
                Grid { cos_bins: 400, phi_bins: 400, sub: 4 }
            } else {
                Grid { cos_bins: 100, phi_bins: 100, sub: 4 }
            };
            let (axis, grid) = if degrees < 30.0 {
                (axis_across(n, wi), Grid { cos_bins: 400, phi_bins: 400, sub: 4 })
            } else {
                (n, grid)
            };
            let quad = integrate_sphere(axis, grid, |wo| {
                material.eval(wi, wo, n, 550.0) * wo.dot(n).abs()
            });
            assert!(
                (mc - quad).abs() < 4.0 * se + 2e-3,
                "alpha {alpha} {degrees} {inside}: {mc} +- {se} vs {quad}"
            );
            // The radiance path: the same samples scaled by (n_i/n_t)^2 on refraction, against the
            // path-ordered quadrature.
            let (mc_r, se_r) =
                albedo(&material, wi, n, 550.0, Transport::Radiance, 200_000, 40 + k as u64);
            let quad_r = integrate_sphere(axis, grid, |wo| {
                material.eval(wo, wi, n, 550.0) * wo.dot(n).abs()
            });
            assert!(
                (mc_r - quad_r).abs() < 4.0 * se_r + 3e-3,
                "radiance {alpha} {degrees}: {mc_r} vs {quad_r}"
            );
            println!("alpha {alpha} {degrees} deg inside {inside}: albedo {mc:.4} +- {se:.4}");
            if degrees < 80.0 {
                // The measured single-scattering albedo (the loss is the light that Smith's G
                // drops instead of letting it scatter again between microfacets), ior 1.5,
                // non-grazing: from outside >= 0.998 / 0.97 / 0.88 / 0.80 at alpha 0.05 / 0.3 /
                // 0.7 / 1; from inside the glass >= 0.99 / 0.78 / 0.58 / 0.43.
                let low = if inside { low_in } else { low_out };
                assert!(mc > low, "alpha {alpha} {degrees} {inside}: {mc}");
            }
        }
    }
}

#[test]
fn roughness_zero_is_exactly_the_smooth_dielectric() {
    for ior in [Ior::constant(1.5).unwrap(), Ior::glass("SF11").unwrap()] {
        let t = Some(Transmittance::constant(0.9).unwrap());
        let smooth = Dielectric::new(ior.clone(), t.clone());
        let r0 = RoughDielectric::isotropic(ior.clone(), 0.0, t.clone()).unwrap();
        let tiny = RoughDielectric::new(ior, 1e-4, 5e-4, t).unwrap();
        assert!(r0.is_specular() && tiny.is_specular());
        let mut rng = Pcg64::seed_from_u64(3);
        for _ in 0..5000 {
            let incoming = Incoming {
                direction: random_unit(&mut rng),
                normal: random_unit(&mut rng),
                lambda: 380.0 + 400.0 * uniform(&mut rng),
            };
            let u = [uniform(&mut rng), uniform(&mut rng), uniform(&mut rng)];
            for transport in [Transport::Importance, Transport::Radiance] {
                let expected = smooth.scatter_with(&incoming, u, transport);
                assert_eq!(r0.scatter_with(&incoming, u, transport), expected);
                assert_eq!(tiny.scatter_with(&incoming, u, transport), expected);
            }
            assert_eq!(
                r0.eval(-incoming.direction, incoming.direction, incoming.normal, 500.0),
                0.0
            );
        }
    }
}

#[test]
fn an_index_of_one_passes_straight_through() {
    let material = rough(1.0, 0.3, 0.3);
    let incoming = Incoming { direction: -away(30.0, false, 0.0), normal: normal(), lambda: 500.0 };
    let s = material.scatter(&incoming, [0.3, 0.4, 0.5]).unwrap();
    assert!((s.direction - incoming.direction).length() < 1e-12);
    assert_eq!((s.kind, s.pdf, s.weight, s.transmission), (ScatterKind::Specular, 0.0, 1.0, true));
}

#[test]
fn bundles_match_scattering_each_wavelength() {
    let t = Transmittance::from_table(&[400.0, 550.0, 700.0], &[0.0, 0.5, 1.0]).unwrap();
    let materials = [
        RoughDielectric::isotropic(Ior::constant(1.5).unwrap(), 0.3, Some(t.clone())).unwrap(),
        RoughDielectric::new(Ior::glass("BK7").unwrap(), 0.1, 0.4, Some(t)).unwrap(),
    ];
    let mut rng = Pcg64::seed_from_u64(8);
    for m in &materials {
        for trial in 0..3000 {
            let (direction, normal) = (random_unit(&mut rng), random_unit(&mut rng));
            let lambdas: Vec<f64> = (0..4).map(|_| 380.0 + 400.0 * uniform(&mut rng)).collect();
            let weights: Vec<f64> =
                (0..4).map(|j| if (trial + j) % 5 == 0 { 0.0 } else { 0.25 }).collect();
            let u = [uniform(&mut rng), uniform(&mut rng), uniform(&mut rng)];
            for transport in [Transport::Importance, Transport::Radiance] {
                let (mut a, mut b) = (weights.clone(), weights.clone());
                let fast = m.scatter_bundle(direction, normal, &lambdas, &mut a, u, transport);
                let each = scatter_each(m, direction, normal, &lambdas, &mut b, u, transport);
                assert_eq!(fast, each, "{m:?}");
                assert_eq!(a, b);
            }
        }
    }
}

#[test]
fn scene_forms_round_trip_and_errors_name_the_field() {
    let config = bincode::config::standard();
    for json in [
        r#"{"type": "RoughDielectric", "ior": {"glass": "SF11"}, "roughness": 0.1}"#,
        r#"{"type": "RoughDielectric", "ior": 1.5, "roughness_u": 0.05, "roughness_v": 0.3, "transmittance": 0.95}"#,
        r#"{"type": "RoughDielectric", "ior": 1.33, "roughness": 0}"#,
        r#"{"type": "RoughDielectric", "ior": 1.5, "roughness": 0.3, "distribution": "beckmann"}"#,
    ] {
        let m: Box<dyn Material> = serde_json::from_str(json).unwrap();
        let written = serde_json::to_string(&m).unwrap();
        let again: Box<dyn Material> = serde_json::from_str(&written).unwrap();
        assert_eq!(serde_json::to_string(&again).unwrap(), written);
        let bytes = bincode::serde::encode_to_vec(&m, config).unwrap();
        let (back, _): (Box<dyn Material>, usize) =
            bincode::serde::decode_from_slice(&bytes, config).unwrap();
        assert_eq!(serde_json::to_string(&back).unwrap(), written);
        let incoming =
            Incoming { direction: -away(30.0, false, 0.2), normal: normal(), lambda: 500.0 };
        assert_eq!(back.scatter(&incoming, [0.5, 0.3, 0.7]), m.scatter(&incoming, [0.5, 0.3, 0.7]));
    }
    let cases = [
        (
            r#"{"type": "RoughDielectric", "ior": 1.5, "roughness": -0.1}"#,
            "RoughDielectric.roughness = -0.1: a roughness (GGX alpha) must be finite and >= 0",
        ),
        (
            r#"{"type": "RoughDielectric", "ior": 1.5, "roughness_u": 0.1, "roughness_v": -1}"#,
            "RoughDielectric.roughness_v = -1.0",
        ),
        (
            r#"{"type": "RoughDielectric", "ior": 1.5, "roughness_u": 0.1}"#,
            "RoughDielectric.roughness_v",
        ),
        (
            r#"{"type": "RoughDielectric", "ior": 1.5, "roughness": 0.1, "roughness_u": 0.1}"#,
            "not both",
        ),
        (r#"{"type": "RoughDielectric", "ior": 1.5}"#, "RoughDielectric.roughness"),
        (
            r#"{"type": "RoughDielectric", "ior": 0.5, "roughness": 0.1}"#,
            "RoughDielectric.ior = 0.5",
        ),
        (
            r#"{"type": "RoughDielectric", "ior": {"glass": "XX"}, "roughness": 0.1}"#,
            "RoughDielectric.ior.glass: unknown glass `XX`",
        ),
        (
            r#"{"type": "RoughDielectric", "ior": 1.5, "roughness": 0.1, "transmittance": 2}"#,
            "transmittance must lie in [0, 1]",
        ),
        (r#"{"type": "RoughDielectric", "ior": 1.5, "alpha": 0.1}"#, "unknown field `alpha`"),
    ];
    for (json, expected) in cases {
        let message = serde_json::from_str::<Box<dyn Material>>(json).unwrap_err().to_string();
        assert!(message.contains(expected), "{json}\n  gave: {message}\n  wanted: {expected}");
    }
    let e = RoughDielectric::isotropic(Ior::constant(1.5).unwrap(), f64::NAN, None).unwrap_err();
    assert_eq!(e.field_path(), "RoughDielectric.roughness");
    let e =
        RoughDielectric::new(Ior::constant(1.5).unwrap(), 0.1, f64::INFINITY, None).unwrap_err();
    assert_eq!(e.field_path(), "RoughDielectric.roughness_v");
}

fn uniform01() -> impl Strategy<Value = f64> {
    prop_oneof![1 => Just(0.0), 1 => Just(ONE_MINUS_EPSILON), 1 => Just(-0.5), 1 => Just(f64::NAN), 1 => Just(2.0), 6 => 0.0..1.0]
}

/// Directions including ones grazing the normal to within 1e-9.
fn direction_near(normal: DVec3) -> impl Strategy<Value = DVec3> {
    (0.0..1.0f64, 0.0..1.0f64, prop_oneof![3 => Just(None), 1 => (-1e-9..1e-9f64).prop_map(Some)])
        .prop_map(move |(u, v, graze)| {
            let d = sphere(u, v);
            match graze {
                None => d,
                Some(z) => {
                    let t = (d - d.dot(normal) * normal).normalize_or(DVec3::X);
                    (t + z * normal).normalize()
                }
            }
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(3000))]

    #[test]
    fn scatter_eval_and_pdf_are_finite_for_any_input(
        d in direction_near(DVec3::new(0.0, 0.6, 0.8)),
        wo in direction_near(DVec3::new(0.0, 0.6, 0.8)),
        lambda in prop_oneof![360.0..830.0f64, Just(100.0), Just(5000.0)],
        u in [uniform01(), uniform01(), uniform01()],
        alpha in prop_oneof![Just(0.0), Just(1e-3), 0.0..2.0f64, Just(10.0)],
        radiance in any::<bool>(),
    ) {
        let normal = DVec3::new(0.0, 0.6, 0.8);
        let transport = if radiance { Transport::Radiance } else { Transport::Importance };
        for ior in [Ior::constant(1.5).unwrap(), Ior::glass("SF11").unwrap(), Ior::constant(1.0).unwrap()] {
            let m = RoughDielectric::new(ior, alpha, 0.5 * alpha, None).unwrap();
            let incoming = Incoming { direction: d, normal, lambda };
            if let Some(s) = m.scatter_with(&incoming, u, transport) {
                prop_assert!(s.weight.is_finite() && s.weight > 0.0, "{m:?} {s:?}");
                prop_assert!((s.direction.length() - 1.0).abs() < 1e-12, "{s:?}");
                prop_assert!(s.pdf.is_finite() && s.pdf >= 0.0);
                prop_assert_eq!(s.kind == ScatterKind::Specular, s.pdf == 0.0);
                // Reflection stays on the beam's side, refraction crosses.
                let side = s.direction.dot(normal) * d.dot(normal);
                prop_assert!(if s.transmission { side >= 0.0 } else { side <= 0.0 }, "{s:?}");
            }
            let f = m.eval(-d, wo, normal, lambda);
            let p = m.pdf(-d, wo, normal, lambda);
            prop_assert!(f.is_finite() && f >= 0.0 && p.is_finite() && p >= 0.0, "{f} {p}");
        }
    }
}
