//! `Fluorescent`: energy per wavelength band, the distributions of re-emitted and excitation
//! wavelengths (chi-square against the spectra), the adjoint against the forward kernel, the
//! elastic lobe, and validation naming the field.

use glam::DVec3;
use rand::SeedableRng;
use rand_pcg::Pcg64;
use spectrace_materials::{Fluorescent, Material, Reemission, Transport, reemission_lobe};
use spectrace_sampling::stats::{chi_square, expected_counts, histogram};
use spectrace_spectrum::{Reflectance, SpectralPowerDistribution, Tabulated};

use crate::harness::{Grid, albedo, chi2_directions, reciprocity_error};
use crate::{ALPHA, uniform};

/// Absorption `a`: 0.8 at 380 nm falling to 0.6 at 450 nm, zero beyond 300-500 nm.
const ABS_NM: [f64; 4] = [300.0, 380.0, 450.0, 500.0];
const ABS_VALUES: [f64; 4] = [0.0, 0.8, 0.6, 0.0];

fn emission() -> Box<dyn SpectralPowerDistribution> {
    Box::new(Tabulated::new(&[480.0, 530.0, 600.0], &[0.0, 1.0, 0.0]).unwrap())
}

fn material(base: f64, yield_: f64) -> Fluorescent {
    Fluorescent::new(Reflectance::constant(base).unwrap(), &ABS_NM, &ABS_VALUES, emission(), yield_)
        .unwrap()
}

#[test]
fn re_emitted_power_never_exceeds_yield_times_absorbed_power_in_any_band() {
    // Per band of incident wavelengths: beams at wavelengths spread over the band, the mean
    // re-emitted weight (Monte Carlo over the branch choice) against Y * mean a(lambda) (the
    // absorbed power times the yield), and elastic + re-emitted <= 1. The mean of 40 000
    // branch choices has a relative standard error below 0.5%: 4 standard errors is 2%.
    let m = material(0.7, 0.9);
    let mut rng = Pcg64::seed_from_u64(5);
    for band in [(300.0, 340.0), (340.0, 400.0), (400.0, 450.0), (450.0, 500.0), (500.0, 700.0)] {
        let (mut reemitted, mut absorbed, mut elastic, mut n) = (0.0, 0.0, 0.0, 0.0);
        let mut sum2 = 0.0;
        for i in 0..40_000 {
            let lambda = band.0 + (band.1 - band.0) * (i as f64 + 0.5) / 40_000.0;
            let mut lambdas = [lambda];
            let mut weights = [1.0];
            absorbed += m.absorbed(lambda);
            let w = match m.choose_forward(&mut lambdas, &mut weights, uniform(&mut rng), 0.5) {
                Reemission::Reemitted { .. } => weights[0],
                Reemission::Elastic => {
                    elastic += weights[0] * m.elastic_albedo(lambda);
                    0.0
                }
                Reemission::Absorbed => 0.0,
            };
            reemitted += w;
            sum2 += w * w;
            n += 1.0;
        }
        let (mean, absorbed, elastic) = (reemitted / n, absorbed / n, elastic / n);
        let se = ((sum2 / n - mean * mean).max(0.0) / n).sqrt();
        let expected = 0.9 * absorbed;
        assert!(mean <= expected + 4.0 * se + 1e-12, "{band:?}: {mean} > Y a = {expected}");
        assert!((mean - expected).abs() <= 4.0 * se + 1e-12, "{band:?}: {mean} vs {expected}");
        assert!(mean + elastic <= 1.0 + 4.0 * se, "{band:?}: energy {mean} + {elastic}");
        assert!(m.elastic_albedo(band.0) + m.reemitted(band.0) <= 1.0);
    }
}

#[test]
fn re_emitted_wavelengths_follow_the_emission_spectrum() {
    let m = material(0.0, 1.0);
    let e = emission();
    let mut rng = Pcg64::seed_from_u64(6);
    let n = 100_000u64;
    let samples = (0..n).map(|_| m.sample_emission(uniform(&mut rng)));
    let counts = histogram(samples, 470.0, 610.0, 70);
    let cdf = |x: f64| e.integrate(&|l| if l <= x { 1.0 } else { 0.0 });
    let expected = expected_counts(cdf, 470.0, 610.0, 70, n);
    let chi = chi_square(&counts, &expected, 5.0);
    assert!(chi.p_value > ALPHA, "{chi:?}");
}

#[test]
fn excitation_wavelengths_follow_the_absorption_and_the_adjoint_matches_the_kernel() {
    // Camera paths draw lambda_i with density a / A: a chi-square against the table; and the
    // adjoint weight Y e(lambda_o) A / p times p (its branch probability) integrates the kernel
    // Y a(lambda_i) e(lambda_o) over lambda_i.
    let m = material(0.3, 0.8);
    let mut rng = Pcg64::seed_from_u64(7);
    let n = 100_000u64;
    let samples = (0..n).map(|_| m.sample_excitation(uniform(&mut rng)));
    let counts = histogram(samples, 300.0, 500.0, 80);
    let a = Tabulated::new(&ABS_NM, &ABS_VALUES).unwrap();
    let cdf = |x: f64| a.integrate(&|l| if l <= x { 1.0 } else { 0.0 });
    let chi = chi_square(&counts, &expected_counts(cdf, 300.0, 500.0, 80, n), 5.0);
    assert!(chi.p_value > ALPHA, "{chi:?}");
    // A = integral a = 80 * 0.8 / 2 + 70 * 0.7 + 50 * 0.6 / 2 = 32 + 49 + 15 = 96 nm.
    assert!((m.absorption_integral() - 96.0).abs() < 1e-9, "{}", m.absorption_integral());
    // The guided sampler (absorption times a light spectrum peaking at 380 nm, mixed with the
    // absorption alone) must give the same expected weight.
    let guide = m.excitation_sampler(&|l: f64| (-(l - 380.0).powi(2) / 800.0).exp());
    for (lambda_o, sampler) in
        [(490.0, None), (530.0, None), (570.0, None), (490.0, Some(&guide)), (530.0, Some(&guide))]
    {
        let quadrature: f64 = (0..2000)
            .map(|i| {
                let l = 300.0 + 200.0 * (i as f64 + 0.5) / 2000.0;
                m.kernel(l, lambda_o) * 0.1
            })
            .sum();
        let adjoint = m.adjoint_reemitted(lambda_o);
        assert!(
            (adjoint - quadrature).abs() < 1e-4 * adjoint,
            "{lambda_o}: {adjoint} {quadrature}"
        );
        // The branch's expected weight is the adjoint albedo (MC, 4 standard errors).
        let (mut sum, mut sum2) = (0.0, 0.0);
        let k = 40_000;
        for _ in 0..k {
            let (mut l, mut w) = ([lambda_o], [1.0]);
            let v = match m.choose_adjoint(
                &mut l,
                &mut w,
                uniform(&mut rng),
                uniform(&mut rng),
                sampler,
            ) {
                Reemission::Reemitted { lambda } => {
                    assert_eq!(l[0], lambda);
                    assert!(m.absorbed(lambda) > 0.0, "excited where nothing absorbs: {lambda}");
                    w[0]
                }
                _ => 0.0,
            };
            sum += v;
            sum2 += v * v;
        }
        let mean = sum / k as f64;
        let se = ((sum2 / k as f64 - mean * mean) / k as f64).sqrt();
        assert!((mean - adjoint).abs() < 4.0 * se, "{lambda_o}: {mean} vs {adjoint} ({se})");
    }
}

#[test]
fn a_bundle_collapses_to_one_wavelength_carrying_the_whole_re_emission() {
    let m = material(0.5, 0.9);
    let mut lambdas = [380.0, 420.0, 600.0, 450.0];
    let mut weights = [1.0, 0.5, 2.0, 0.0];
    let reemit: f64 =
        [380.0, 420.0, 600.0].iter().zip([1.0, 0.5, 2.0]).map(|(&l, w)| w * m.reemitted(l)).sum();
    let elastic: f64 = [380.0, 420.0, 600.0]
        .iter()
        .zip([1.0, 0.5, 2.0])
        .map(|(&l, w)| w * m.elastic_albedo(l))
        .sum();
    let p = reemit / (reemit + elastic);
    // u_choice below p: re-emission.
    match m.choose_forward(&mut lambdas, &mut weights, 0.5 * p, 0.5) {
        Reemission::Reemitted { lambda } => {
            assert_eq!(lambdas[0], lambda);
            assert!((480.0..=600.0).contains(&lambda));
            assert!((weights[0] - reemit / p).abs() < 1e-12 * weights[0]);
            assert_eq!(&weights[1..], &[0.0, 0.0, 0.0]);
        }
        other => panic!("{other:?}"),
    }
    // u_choice above p: every live weight divided by 1 - p, the wavelengths kept.
    let mut lambdas = [380.0, 420.0, 600.0, 450.0];
    let mut weights = [1.0, 0.5, 2.0, 0.0];
    assert_eq!(
        m.choose_forward(&mut lambdas, &mut weights, 0.5 + 0.5 * p, 0.5),
        Reemission::Elastic
    );
    assert_eq!(lambdas, [380.0, 420.0, 600.0, 450.0]);
    for (w, w0) in weights.iter().zip([1.0, 0.5, 2.0, 0.0]) {
        assert!((w - w0 / (1.0 - p)).abs() < 1e-12);
    }
}

#[test]
fn the_elastic_part_is_a_lambertian_of_the_unabsorbed_light() {
    let m = material(0.6, 0.9);
    let n = DVec3::new(0.2, 0.9, -0.1).normalize();
    let wi = (n + DVec3::new(0.4, 0.0, 0.3)).normalize();
    for lambda in [350.0, 420.0, 550.0] {
        let expected = (1.0 - m.absorbed(lambda)) * 0.6;
        // Every sample carries exactly the albedo (cosine sampling of a Lambertian).
        let (a, _) = albedo(&m, wi, n, lambda, Transport::Importance, 2000, 3);
        assert!((a - expected).abs() < 1e-12, "{lambda}: {a} vs {expected}");
    }
    let chi = chi2_directions(&m, wi, n, 420.0, 200_000, 4, Grid::default());
    assert!(chi.p_value > ALPHA && (chi.pdf_integral - 1.0).abs() < 1e-3, "{chi:?}");
    assert!(reciprocity_error(&m, n, 420.0, Transport::Radiance, 1000, 5) < 1e-12);
    assert!(m.fluorescence().is_some() && !m.is_specular() && !m.is_dispersive());
    // The re-emission lobe is the white Lambertian.
    let lobe = reemission_lobe();
    let (a, _) = albedo(lobe, wi, n, 420.0, Transport::Radiance, 100, 6);
    assert_eq!(a, 1.0);
    assert!(lobe.fluorescence().is_none());
}

#[test]
fn bad_fluorescent_parameters_are_refused_naming_the_field() {
    let load =
        |json: &str| serde_json::from_str::<Box<dyn Material>>(json).unwrap_err().to_string();
    let base = |abs: &str, emission: &str, y: &str| {
        format!(
            r#"{{"type": "Fluorescent", "reflectance": 0.5, "absorption": {abs}, "emission": {emission}, "quantum_yield": {y}}}"#
        )
    };
    let abs = r#"{"nm": [300, 400], "values": [0.5, 0.5]}"#;
    let em = r#"{"type": "Tabulated", "nm": [500, 600], "values": [1, 1]}"#;
    assert!(serde_json::from_str::<Box<dyn Material>>(&base(abs, em, "0.5")).is_ok());
    let e = load(&base(abs, em, "1.5"));
    assert!(e.contains("Fluorescent.quantum_yield") && e.contains("[0, 1]"), "{e}");
    let e = load(&base(r#"{"nm": [300, 400], "values": [0.5, 1.2]}"#, em, "0.5"));
    assert!(e.contains("Fluorescent.absorption.values[1]"), "{e}");
    let e = load(&base(r#"{"nm": [300, 400], "values": [0, 0]}"#, em, "0.5"));
    assert!(e.contains("Fluorescent.absorption"), "{e}");
    let e = load(&base(r#"{"nm": [400, 300], "values": [0.5, 0.5]}"#, em, "0.5"));
    assert!(e.contains("Fluorescent.absorption"), "{e}");
    let e = load(&base(r#"{"nm": [-5, 300], "values": [0.5, 0.5]}"#, em, "0.5"));
    assert!(e.contains("Fluorescent.absorption.nm[0]"), "{e}");
    let e = load(&base(abs, r#"{"type": "Monochromatic", "lambda_nm": 520}"#, "0.5"));
    assert!(e.contains("Fluorescent.emission") && e.contains("line"), "{e}");
    let e = load(&base(abs, em, "NaN").replace("NaN", "-0.1"));
    assert!(e.contains("Fluorescent.quantum_yield"), "{e}");
    // A round trip keeps every parameter.
    let m: Box<dyn Material> = serde_json::from_str(&base(abs, em, "0.5")).unwrap();
    let again: Box<dyn Material> =
        serde_json::from_str(&serde_json::to_string(&m).unwrap()).unwrap();
    let (f, g) = (m.fluorescence().unwrap(), again.fluorescence().unwrap());
    for l in [290.0, 350.0, 550.0] {
        assert_eq!(f.kernel(350.0, l), g.kernel(350.0, l));
        assert_eq!(f.elastic_albedo(l), g.elastic_albedo(l));
    }
}
