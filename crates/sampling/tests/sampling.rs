//! Tests of the public API of `spectrace-sampling`: named hard cases, property tests over tables
//! with a wide dynamic range (10,000 cases per property), statistical goodness of fit at fixed
//! seeds, bad input, and serialisation.
#![allow(clippy::unwrap_used)]

use proptest::prelude::*;
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64;
use spectrace_sampling::stats::{chi_square, expected_counts, histogram, kolmogorov_smirnov};
use spectrace_sampling::{
    AliasTable, Discrete, ONE_MINUS_EPSILON, PiecewiseConstant, PiecewiseLinear, SamplingError,
};

/// Significance level of every statistical test in this file: a correct sampler fails one of them
/// at a random seed with probability 1e-3; the seeds are fixed, so the outcome is reproducible.
const ALPHA: f64 = 1e-3;

/// Uniforms that probe the ends of `[0, 1)` and a dense grid in between.
fn probe_uniforms() -> Vec<f64> {
    let mut us = vec![0.0, f64::from_bits(1), 1e-300, 1e-17, 1e-9, ONE_MINUS_EPSILON];
    us.extend((1..1000).map(|k| k as f64 / 1000.0));
    us.extend((1..=20).map(|k| 1.0 - k as f64 * f64::EPSILON / 2.0));
    us.sort_by(f64::total_cmp);
    us
}

/// Compensated sum, so tests of "sums to 1" measure the sampler and not the test.
fn neumaier_sum(values: impl IntoIterator<Item = f64>) -> f64 {
    let (mut sum, mut c) = (0.0_f64, 0.0_f64);
    for v in values {
        let t = sum + v;
        c += if sum.abs() >= v.abs() { (sum - t) + v } else { (v - t) + sum };
        sum = t;
    }
    sum + c
}

/// Checks everything a continuous inverse-CDF sampler promises for one table.
fn check_linear_invariants(d: &PiecewiseLinear, us: &[f64], cdf_tolerance: f64) {
    let (lo, hi) = d.range();
    let mut previous = f64::NEG_INFINITY;
    for &u in us {
        let x = d.sample(u);
        assert!(x.is_finite(), "u = {u}: sample {x} not finite");
        assert!(x >= lo && x <= hi, "u = {u}: sample {x} outside [{lo}, {hi}]");
        assert!(d.pdf(x) > 0.0, "u = {u}: sample {x} where the density is zero");
        assert!(x >= previous, "u = {u}: sample {x} below the previous {previous}");
        previous = x;
        let c = d.cdf(x);
        assert!((c - u).abs() <= cdf_tolerance, "u = {u}: cdf(sample) = {c}, off by {}", c - u);
    }
}

// ---------------------------------------------------------------------------------------------
// Named hard cases
// ---------------------------------------------------------------------------------------------

#[test]
fn nearly_flat_segments_sample_like_uniform() {
    let d = PiecewiseLinear::new(&[0.0, 1.0, 2.0], &[1.0, 1.0 + 1e-15, 1.0]).unwrap();
    check_linear_invariants(&d, &probe_uniforms(), 1e-14);
    for u in [0.1, 0.25, 0.5, 0.75, 0.9] {
        assert!((d.sample(u) - 2.0 * u).abs() < 1e-14, "u = {u}: {}", d.sample(u));
    }
}

#[test]
fn segments_starting_and_ending_at_zero() {
    // 0 -> 1 -> 0 -> 0 -> 2: a rising, a falling, a zero and a rising segment.
    let d = PiecewiseLinear::new(&[0.0, 1.0, 2.0, 3.0, 4.0], &[0.0, 1.0, 0.0, 0.0, 2.0]).unwrap();
    check_linear_invariants(&d, &probe_uniforms(), 1e-15);
    assert!(d.sample(0.0) > 0.0, "u = 0 landed on the zero end at x = 0");
    // The zero segment (2, 3) is never entered: u just past the first triangle's mass (1/2) goes
    // to the last segment.
    for u in [0.5, 0.5000001, 0.6] {
        let x = d.sample(u);
        assert!(!(x > 2.0 && x < 3.0), "u = {u} landed in the zero segment at {x}");
    }
    assert!(d.sample(ONE_MINUS_EPSILON) <= 4.0);
}

#[test]
fn single_nonzero_segment_in_a_long_table() {
    let n = 100_000;
    let xs: Vec<f64> = (0..n).map(|i| 360.0 + i as f64 * 0.01).collect();
    let mut ys = vec![0.0; n];
    ys[54_321] = 3.0;
    let (a, b) = (xs[54_320], xs[54_322]);
    let d = PiecewiseLinear::new(&xs, &ys).unwrap();
    for &u in &probe_uniforms() {
        let x = d.sample(u);
        assert!(x > a && x < b, "u = {u}: {x} outside ({a}, {b})");
        assert!(d.pdf(x) > 0.0);
    }
    let disc = Discrete::new(&ys).unwrap();
    let alias = AliasTable::new(&ys).unwrap();
    for &u in &probe_uniforms() {
        assert_eq!(disc.sample(u), 54_321);
        assert_eq!(alias.sample(u), 54_321);
    }
}

#[test]
fn spikes_of_1e300_beside_1e_minus_300() {
    let ys = [1e-300, 1e300, 1e-300, 0.0, 1e-300, 1e300, 1e-300];
    let xs: Vec<f64> = (0..ys.len()).map(|i| i as f64).collect();
    let d = PiecewiseLinear::new(&xs, &ys).unwrap();
    assert!((d.integral() - 2e300).abs() < 1e286);
    check_linear_invariants(&d, &probe_uniforms(), 1e-14);
    // Each spike holds half the mass.
    assert!((d.cdf(3.0) - 0.5).abs() < 1e-15);
    let disc = Discrete::new(&ys).unwrap();
    assert!((disc.pmf(1) - 0.5).abs() < 1e-15 && (disc.pmf(5) - 0.5).abs() < 1e-15);
    // The true probability of a 1e-300 entry, 5e-601, is below the smallest f64: it is 0, and
    // (checked below) such an entry is never returned.
    assert_eq!(disc.pmf(0), 0.0);
    assert_eq!(disc.pmf(3), 0.0);
    let total = neumaier_sum((0..ys.len()).map(|i| disc.pmf(i)));
    assert!((total - 1.0).abs() <= 1e-15);
    let alias = AliasTable::new(&ys).unwrap();
    for &u in &probe_uniforms() {
        assert!(matches!(alias.sample(u), 1 | 5), "alias returned {} for u = {u}", alias.sample(u));
        assert!(
            matches!(disc.sample(u), 1 | 5),
            "discrete returned {} for u = {u}",
            disc.sample(u)
        );
    }
}

#[test]
fn huge_values_whose_sum_fits() {
    let d = Discrete::new(&[f64::MAX / 4.0, f64::MAX / 4.0]).unwrap();
    assert_eq!(d.pmf(0), 0.5);
    assert_eq!(d.total(), f64::MAX / 2.0);
    let p = PiecewiseLinear::new(&[0.0, 1.0], &[f64::MAX, f64::MAX]).unwrap();
    assert_eq!(p.integral(), f64::MAX);
    assert_eq!(p.pdf(0.5), 1.0);
    // Widths near f64::MAX: the xs span is huge but each segment's mass still fits.
    let w =
        PiecewiseLinear::new(&[-f64::MAX / 2.0, 0.0, f64::MAX / 2.0], &[1.0, 1.0, 1.0]).unwrap();
    assert_eq!(w.sample(0.5), 0.0);
}

#[test]
fn subnormal_weights_keep_full_precision() {
    let tiny = f64::from_bits(1); // 4.9e-324, the smallest subnormal
    let d = Discrete::new(&[tiny, 2.0 * tiny, 0.0, tiny]).unwrap();
    assert_eq!([d.pmf(0), d.pmf(1), d.pmf(2), d.pmf(3)], [0.25, 0.5, 0.0, 0.25]);
    assert_eq!(d.sample(0.2), 0);
    assert_eq!(d.sample(0.5), 1);
    assert_eq!(d.sample(0.8), 3);
    let a = AliasTable::new(&[tiny, 2.0 * tiny, 0.0, tiny]).unwrap();
    assert_eq!(a.realised_pmf(), vec![0.25, 0.5, 0.0, 0.25]);
    let p = PiecewiseLinear::new(&[0.0, 1.0, 2.0], &[tiny, tiny, 3.0 * tiny]).unwrap();
    check_linear_invariants(&p, &probe_uniforms(), 1e-15);
    assert!((p.cdf(1.0) - 1.0 / 3.0).abs() < 1e-15);
    let c = PiecewiseConstant::new(&[0.0, 1.0, 3.0], &[tiny, tiny]).unwrap();
    assert!((c.cdf(1.0) - 1.0 / 3.0).abs() < 1e-15);
}

#[test]
fn million_entry_tables() {
    let n = 1_000_000;
    let mut rng = Pcg64::seed_from_u64(7);
    let weights: Vec<f64> =
        (0..n)
            .map(|i| {
                if i % 7 == 0 {
                    0.0
                } else {
                    rng.random::<f64>() * 10f64.powi((i % 40) as i32 - 20)
                }
            })
            .collect();
    let d = Discrete::new(&weights).unwrap();
    let a = AliasTable::new(&weights).unwrap();
    let total = neumaier_sum((0..n).map(|i| d.pmf(i)));
    assert!((total - 1.0).abs() <= 1e-15, "pmf sums to {total}");
    let xs: Vec<f64> = (0..n).map(|i| 360.0 + 470.0 * i as f64 / (n - 1) as f64).collect();
    let p = PiecewiseLinear::new(&xs, &weights).unwrap();
    let c = PiecewiseConstant::new(&xs, &weights[1..]).unwrap();
    let mut previous = (0, f64::NEG_INFINITY);
    for &u in &probe_uniforms() {
        let (i, j) = (d.sample(u), a.sample(u));
        assert!(weights[i] > 0.0 && weights[j] > 0.0, "u = {u}: zero weight returned");
        assert!(i >= previous.0);
        let x = p.sample(u);
        assert!(x.is_finite() && (360.0..=830.0).contains(&x) && p.pdf(x) > 0.0, "u = {u}: {x}");
        assert!(x >= previous.1);
        previous = (i, x);
        let y = c.sample(u);
        assert!(y.is_finite() && c.pdf(y) > 0.0, "u = {u}: {y}");
    }
}

#[test]
fn ends_of_the_unit_interval_never_hit_zero_density() {
    // Zero weights and zero-mass segments at both ends of every table.
    let w = [0.0, 0.0, 1.0, 0.0, 2.0, 0.0, 0.0];
    let d = Discrete::new(&w).unwrap();
    let a = AliasTable::new(&w).unwrap();
    assert_eq!(d.sample(0.0), 2);
    assert_eq!(d.sample(ONE_MINUS_EPSILON), 4);
    for u in [0.0, ONE_MINUS_EPSILON] {
        assert!(w[a.sample(u)] > 0.0);
    }
    let xs = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
    let p = PiecewiseLinear::new(&xs, &w).unwrap();
    for u in [0.0, ONE_MINUS_EPSILON] {
        let x = p.sample(u);
        assert!(p.pdf(x) > 0.0, "u = {u}: x = {x}");
        assert!(x > 1.0 && x < 5.0, "u = {u}: x = {x} in a zero-mass segment");
    }
    let c = PiecewiseConstant::new(&xs, &w[1..]).unwrap();
    for u in [0.0, ONE_MINUS_EPSILON] {
        let x = c.sample(u);
        assert!(c.pdf(x) > 0.0, "u = {u}: x = {x}");
    }
}

#[test]
fn seed_figure_two_discrete_example_as_every_generator() {
    // Seed 2.2: x = 1..4, as many 1s as 4s, half as many 3s as 1s, three times more 2s than 3s.
    let w = [2.0, 3.0, 1.0, 2.0];
    let d = Discrete::new(&w).unwrap();
    let a = AliasTable::new(&w).unwrap();
    for (i, &wi) in w.iter().enumerate() {
        assert_eq!(d.pmf(i), wi / 8.0);
        assert_eq!(a.pmf(i), wi / 8.0);
        assert!((a.realised_pmf()[i] - wi / 8.0).abs() < 1e-16);
    }
}

#[cfg(debug_assertions)]
#[test]
#[should_panic(expected = "outside [0, 1)")]
fn u_of_one_is_a_caller_bug_in_debug_builds() {
    let d = Discrete::new(&[1.0, 1.0]).unwrap();
    let _ = d.sample(1.0);
}

#[cfg(debug_assertions)]
#[test]
#[should_panic(expected = "outside [0, 1)")]
fn nan_u_is_a_caller_bug_in_debug_builds() {
    let d = PiecewiseLinear::new(&[0.0, 1.0], &[1.0, 1.0]).unwrap();
    let _ = d.sample(f64::NAN);
}

// ---------------------------------------------------------------------------------------------
// Bad input
// ---------------------------------------------------------------------------------------------

#[test]
fn bad_tables_name_the_array_and_index() {
    use SamplingError as E;
    assert_eq!(Discrete::new(&[]), Err(E::Empty { array: "weights" }));
    assert_eq!(AliasTable::new(&[]).unwrap_err(), E::Empty { array: "weights" });
    assert_eq!(Discrete::new(&[1.0, f64::NAN]), Err(E::NaN { array: "weights", index: 1 }));
    assert_eq!(
        Discrete::new(&[1.0, 2.0, f64::INFINITY]),
        Err(E::Infinite { array: "weights", index: 2, value: f64::INFINITY })
    );
    assert_eq!(
        AliasTable::new(&[1.0, -0.5]).unwrap_err(),
        E::Negative { array: "weights", index: 1, value: -0.5 }
    );
    assert_eq!(Discrete::new(&[0.0, 0.0]), Err(E::ZeroTotal { array: "weights" }));
    assert_eq!(Discrete::new(&[f64::MAX, f64::MAX]), Err(E::TotalOverflow { array: "weights" }));
    assert_eq!(
        AliasTable::new(&[f64::MAX, f64::MAX]).unwrap_err(),
        E::TotalOverflow { array: "weights" }
    );

    assert_eq!(PiecewiseLinear::new(&[], &[]).unwrap_err(), E::Empty { array: "xs" });
    assert_eq!(
        PiecewiseLinear::new(&[0.0], &[1.0]).unwrap_err(),
        E::TooFewPoints { array: "xs", len: 1 }
    );
    assert!(matches!(
        PiecewiseLinear::new(&[0.0, 1.0], &[1.0]).unwrap_err(),
        E::LengthMismatch { first_len: 2, second_len: 1, .. }
    ));
    assert_eq!(
        PiecewiseLinear::new(&[0.0, 1.0, 1.0], &[1.0; 3]).unwrap_err(),
        E::NotIncreasing { array: "xs", index: 2, value: 1.0, previous: 1.0 }
    );
    assert_eq!(
        PiecewiseLinear::new(&[0.0, f64::NAN], &[1.0; 2]).unwrap_err(),
        E::NaN { array: "xs", index: 1 }
    );
    assert_eq!(
        PiecewiseLinear::new(&[0.0, 1.0, 2.0], &[1.0, -1.0, 1.0]).unwrap_err(),
        E::Negative { array: "ys", index: 1, value: -1.0 }
    );
    assert_eq!(
        PiecewiseLinear::new(&[-f64::MAX, f64::MAX], &[1.0; 2]).unwrap_err(),
        E::SpanOverflow { array: "xs", index: 0 }
    );
    assert_eq!(
        PiecewiseLinear::new(&[0.0, 1.0], &[0.0, 0.0]).unwrap_err(),
        E::ZeroTotal { array: "ys" }
    );
    assert_eq!(
        PiecewiseLinear::new(&[0.0, 4.0, 8.0], &[f64::MAX, f64::MAX, f64::MAX]).unwrap_err(),
        E::TotalOverflow { array: "ys" }
    );
    assert_eq!(
        PiecewiseLinear::new(&[0.0, 1e-310], &[1.0, 1.0]).unwrap_err(),
        E::DensityOverflow { array: "ys", index: 0 }
    );
    assert!(matches!(
        PiecewiseConstant::new(&[0.0, 1.0], &[1.0, 1.0]).unwrap_err(),
        E::LengthMismatch { first: "edges", first_len: 2, second_len: 2, .. }
    ));
    assert_eq!(
        PiecewiseConstant::uniform(0.0, -1.0, &[1.0, 1.0]).unwrap_err(),
        E::NotIncreasing { array: "edges", index: 1, value: -1.0, previous: 0.0 }
    );
}

#[test]
fn error_messages_read_well() {
    let e = PiecewiseLinear::new(&[0.0, 2.0, 1.0], &[1.0; 3]).unwrap_err();
    assert_eq!(e.to_string(), "xs[2] = 1 is not greater than xs[1] = 2");
    assert_eq!(e.index(), Some(2));
    assert_eq!(e.array(), "xs");
    let e = Discrete::new(&[1.0, -3.0]).unwrap_err();
    assert_eq!(e.to_string(), "weights[1] is negative (-3)");
}

// ---------------------------------------------------------------------------------------------
// Serialisation and the rand traits
// ---------------------------------------------------------------------------------------------

fn bincode_round_trip<T: serde::Serialize + serde::de::DeserializeOwned>(value: &T) -> T {
    let config = bincode::config::standard();
    let bytes = bincode::serde::encode_to_vec(value, config).unwrap();
    bincode::serde::decode_from_slice(&bytes, config).unwrap().0
}

#[test]
fn serde_round_trips_preserve_samples() {
    let w = [0.5, 0.0, 2.0, 1e-200, 3.0];
    let xs = [1.0, 2.0, 4.0, 8.0, 16.0];
    let d = Discrete::new(&w).unwrap();
    let a = AliasTable::new(&w).unwrap();
    let p = PiecewiseLinear::new(&xs, &w).unwrap();
    let c = PiecewiseConstant::new(&xs, &w[..4]).unwrap();
    let d_json: Discrete = serde_json::from_str(&serde_json::to_string(&d).unwrap()).unwrap();
    let a_json: AliasTable = serde_json::from_str(&serde_json::to_string(&a).unwrap()).unwrap();
    let p_json: PiecewiseLinear =
        serde_json::from_str(&serde_json::to_string(&p).unwrap()).unwrap();
    let c_json: PiecewiseConstant =
        serde_json::from_str(&serde_json::to_string(&c).unwrap()).unwrap();
    assert_eq!((&d_json, &a_json, &p_json, &c_json), (&d, &a, &p, &c));
    assert_eq!(bincode_round_trip(&d), d);
    assert_eq!(bincode_round_trip(&a), a);
    assert_eq!(bincode_round_trip(&p), p);
    assert_eq!(bincode_round_trip(&c), c);
    for &u in &probe_uniforms() {
        assert_eq!(d_json.sample(u), d.sample(u));
        assert_eq!(a_json.sample(u), a.sample(u));
        assert_eq!(p_json.sample(u).to_bits(), p.sample(u).to_bits());
        assert_eq!(c_json.sample(u).to_bits(), c.sample(u).to_bits());
    }
    assert_eq!(serde_json::to_string(&d).unwrap(), r#"{"weights":[0.5,0.0,2.0,1e-200,3.0]}"#);
}

#[test]
fn deserialisation_validates_the_table() {
    let err = serde_json::from_str::<Discrete>(r#"{"weights":[1.0,-2.0]}"#).unwrap_err();
    assert!(err.to_string().contains("weights[1] is negative"), "{err}");
    let err =
        serde_json::from_str::<PiecewiseLinear>(r#"{"xs":[0,1,1],"ys":[1,1,1]}"#).unwrap_err();
    assert!(err.to_string().contains("xs[2]"), "{err}");
}

#[test]
fn rand_distribution_trait_draws_from_the_same_table() {
    let d = Discrete::new(&[0.0, 1.0, 0.0]).unwrap();
    let a = AliasTable::new(&[0.0, 0.0, 5.0]).unwrap();
    let p = PiecewiseLinear::new(&[10.0, 20.0], &[1.0, 0.0]).unwrap();
    let c = PiecewiseConstant::uniform(-1.0, 0.5, &[0.0, 1.0]).unwrap();
    let mut rng = Pcg64::seed_from_u64(1);
    for _ in 0..1000 {
        assert_eq!(rng.sample(&d), 1);
        assert_eq!(rng.sample(&a), 2);
        let x: f64 = rng.sample(&p);
        assert!((10.0..20.0).contains(&x));
        let y: f64 = rng.sample(&c);
        assert!((-0.5..0.0).contains(&y));
    }
}

// ---------------------------------------------------------------------------------------------
// Statistical goodness of fit (fixed seeds, alpha = ALPHA)
// ---------------------------------------------------------------------------------------------

const N_STAT: u64 = 200_000;

fn discrete_fit(weights: &[f64], mut draw: impl FnMut(&mut Pcg64) -> usize, seed: u64) -> f64 {
    let total: f64 = weights.iter().sum();
    let mut rng = Pcg64::seed_from_u64(seed);
    let mut counts = vec![0u64; weights.len()];
    for _ in 0..N_STAT {
        counts[draw(&mut rng)] += 1;
    }
    let expected: Vec<f64> = weights.iter().map(|w| w / total * N_STAT as f64).collect();
    chi_square(&counts, &expected, 5.0).p_value
}

fn discrete_shapes() -> Vec<(&'static str, Vec<f64>)> {
    vec![
        ("seed figure 2", vec![2.0, 3.0, 1.0, 2.0]),
        ("geometric", (0..30).map(|i| 0.8f64.powi(i)).collect()),
        (
            "sparse with zeros",
            (0..50).map(|i| if i % 3 == 0 { 0.0 } else { (i % 7) as f64 }).collect(),
        ),
        ("one dominant", {
            let mut v = vec![1.0; 40];
            v[17] = 500.0;
            v
        }),
    ]
}

#[test]
fn discrete_and_alias_match_their_weights() {
    for (seed, (name, w)) in discrete_shapes().into_iter().enumerate() {
        let d = Discrete::new(&w).unwrap();
        let a = AliasTable::new(&w).unwrap();
        let pd = discrete_fit(&w, |r| d.sample(r.random()), seed as u64);
        let pa = discrete_fit(&w, |r| r.sample(&a), 100 + seed as u64);
        assert!(pd > ALPHA, "Discrete, {name}: p = {pd}");
        assert!(pa > ALPHA, "AliasTable, {name}: p = {pa}");
    }
}

#[test]
fn statistical_test_has_power_against_a_wrong_sampler() {
    // The same harness must reject a sampler that is off by 2% on one entry of four.
    let w = [2.0, 3.0, 1.0, 2.0];
    let wrong = Discrete::new(&[2.0, 3.06, 1.0, 2.0]).unwrap();
    let p = discrete_fit(&w, |r| wrong.sample(r.random()), 5);
    assert!(p < ALPHA, "a 2% error went unnoticed: p = {p}");
}

fn continuous_shapes() -> Vec<(&'static str, Vec<f64>, Vec<f64>)> {
    vec![
        ("triangle", vec![0.0, 1.0, 2.0], vec![0.0, 1.0, 0.0]),
        ("ramp", vec![360.0, 830.0], vec![0.1, 5.0]),
        (
            "irregular with a zero gap",
            vec![0.0, 0.3, 1.0, 1.1, 2.5, 3.0, 4.0],
            vec![2.0, 0.5, 0.0, 0.0, 3.0, 3.0, 0.2],
        ),
        (
            "spike",
            (0..21).map(|i| i as f64).collect(),
            (0..21).map(|i| if i == 10 { 100.0 } else { 1.0 }).collect(),
        ),
    ]
}

#[test]
fn piecewise_linear_matches_its_density() {
    for (seed, (name, xs, ys)) in continuous_shapes().into_iter().enumerate() {
        let d = PiecewiseLinear::new(&xs, &ys).unwrap();
        let (lo, hi) = d.range();
        let mut rng = Pcg64::seed_from_u64(200 + seed as u64);
        let samples: Vec<f64> = (0..N_STAT).map(|_| rng.sample(&d)).collect();
        let counts = histogram(samples.iter().copied(), lo, hi, 100);
        // Expected counts from the closed-form trapezoid integral, not from `d.cdf`.
        let exact_cdf = |x: f64| trapezoid_cdf(&xs, &ys, x);
        let expected = expected_counts(exact_cdf, lo, hi, 100, N_STAT);
        let chi = chi_square(&counts, &expected, 5.0);
        assert!(chi.p_value > ALPHA, "{name}: chi-square p = {} ({:?})", chi.p_value, chi);
        let ks = kolmogorov_smirnov(samples, exact_cdf);
        assert!(ks.p_value > ALPHA, "{name}: KS p = {}", ks.p_value);
    }
}

/// CDF of a piecewise-linear density by direct integration (the test's independent reference).
fn trapezoid_cdf(xs: &[f64], ys: &[f64], x: f64) -> f64 {
    let mut total = 0.0;
    let mut below = 0.0;
    for i in 0..xs.len() - 1 {
        let (x0, x1, y0, y1) = (xs[i], xs[i + 1], ys[i], ys[i + 1]);
        let mass = (x1 - x0) * (y0 + y1) / 2.0;
        total += mass;
        if x >= x1 {
            below += mass;
        } else if x > x0 {
            let yx = y0 + (y1 - y0) * (x - x0) / (x1 - x0);
            below += (x - x0) * (y0 + yx) / 2.0;
        }
    }
    below / total
}

#[test]
fn piecewise_constant_matches_its_density() {
    let values = [1.0, 0.0, 4.0, 2.0, 0.5];
    let d = PiecewiseConstant::uniform(400.0, 20.0, &values).unwrap();
    let mut rng = Pcg64::seed_from_u64(300);
    let samples: Vec<f64> = (0..N_STAT).map(|_| rng.sample(&d)).collect();
    let counts = histogram(samples.iter().copied(), 400.0, 500.0, 50);
    let total: f64 = values.iter().sum::<f64>() * 20.0;
    let exact_cdf = |x: f64| {
        let mut below = 0.0;
        for (i, v) in values.iter().enumerate() {
            let x0 = 400.0 + 20.0 * i as f64;
            below += v * (x - x0).clamp(0.0, 20.0);
        }
        below / total
    };
    let chi = chi_square(&counts, &expected_counts(exact_cdf, 400.0, 500.0, 50, N_STAT), 5.0);
    assert!(chi.p_value > ALPHA, "chi-square p = {}", chi.p_value);
    assert!(samples.iter().all(|x| !(420.0..440.0).contains(x)), "sample in the zero bin");
}

// ---------------------------------------------------------------------------------------------
// Property tests: 10,000 cases per property over tables with a wide dynamic range
// ---------------------------------------------------------------------------------------------

/// A weight: zero with probability 1/4, else mantissa in [1, 10) times 10^k, k in [-300, 300].
fn weight() -> impl Strategy<Value = f64> {
    prop_oneof![
        1 => Just(0.0),
        1 => (1.0..10.0f64, -300i32..=300).prop_map(|(m, k)| m * 10f64.powi(k)),
        1 => (1.0..10.0f64, -5i32..=5).prop_map(|(m, k)| m * 10f64.powi(k)),
        1 => (1u64..1000).prop_map(f64::from_bits),
    ]
}

fn weights(max_len: usize) -> impl Strategy<Value = Vec<f64>> {
    prop::collection::vec(weight(), 1..max_len).prop_filter("some positive weight", |w| {
        w.iter().any(|&x| x > 0.0) && w.iter().map(|x| x / 1e10).sum::<f64>().is_finite()
    })
}

/// A grid of 2..32 points starting in [-100, 100] with gaps in [0.1, 10].
fn grid_and_values() -> impl Strategy<Value = (Vec<f64>, Vec<f64>)> {
    (2usize..32).prop_flat_map(|n| {
        (
            -100.0..100.0f64,
            prop::collection::vec(0.1..10.0f64, n - 1),
            prop::collection::vec(weight(), n),
        )
            .prop_filter_map("some positive segment", |(start, gaps, ys)| {
                let mut xs = vec![start];
                for g in gaps {
                    xs.push(xs[xs.len() - 1] + g);
                }
                ys.windows(2).any(|p| p[0] > 0.0 || p[1] > 0.0).then_some((xs, ys))
            })
    })
}

/// Whether a table refused as [`SamplingError::TotalUnderflow`] really has an integral below half
/// the least positive `f64` (so that it rounds to zero): the trapezoids (or bins, `linear` false)
/// summed with the values scaled by 2^1000, which is exact for values that small and overflows
/// for any value that is not.
fn integral_underflows(xs: &[f64], ys: &[f64], linear: bool) -> bool {
    let scale = 2f64.powi(1000);
    let scaled = neumaier_sum(xs.windows(2).zip(ys.windows(2)).map(|(x, y)| {
        let heights = if linear { (y[0] + y[1]) / 2.0 } else { y[0] };
        (x[1] - x[0]) * (heights * scale)
    }));
    scaled < 2f64.powi(-75)
}

/// The sampler of a generated table, or `None` for a table refused because its integral
/// underflows (checked to be so).
fn linear_table(xs: &[f64], ys: &[f64]) -> Option<PiecewiseLinear> {
    match PiecewiseLinear::new(xs, ys) {
        Ok(d) => Some(d),
        Err(SamplingError::TotalUnderflow { array: "ys" }) => {
            assert!(
                integral_underflows(xs, ys, true),
                "refused, but the integral is representable"
            );
            None
        }
        Err(e) => panic!("{e}"),
    }
}

#[test]
fn a_table_whose_integral_underflows_is_refused_and_one_just_above_is_not() {
    // 0.1 x 5e-324 / 2 rounds to zero: the table's integral cannot be reported.
    let tiny = f64::from_bits(1);
    assert_eq!(
        PiecewiseLinear::new(&[0.0, 0.1], &[0.0, tiny]).unwrap_err(),
        SamplingError::TotalUnderflow { array: "ys" }
    );
    assert_eq!(
        PiecewiseConstant::new(&[0.0, 0.1], &[tiny]).unwrap_err(),
        SamplingError::TotalUnderflow { array: "values" }
    );
    // Ten times wider, and its integral is the least positive f64 itself: accepted.
    let d = PiecewiseLinear::new(&[0.0, 2.0], &[tiny, tiny]).unwrap();
    assert!(d.integral() > 0.0);
    assert!(SamplingError::TotalUnderflow { array: "ys" }.to_string().contains("underflows"));
}

fn sorted_uniforms() -> impl Strategy<Value = Vec<f64>> {
    prop::collection::vec(0.0..1.0f64, 1..40).prop_map(|mut us| {
        us.extend([0.0, ONE_MINUS_EPSILON]);
        us.sort_by(f64::total_cmp);
        us
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 10_000, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn prop_discrete_never_returns_zero_weight_and_is_monotone(w in weights(300), us in sorted_uniforms()) {
        let d = Discrete::new(&w).unwrap();
        let mut previous = 0;
        for &u in &us {
            let i = d.sample(u);
            prop_assert!(w[i] > 0.0, "u = {} returned zero-weight index {}", u, i);
            prop_assert!(i >= previous);
            previous = i;
        }
        let total = neumaier_sum((0..w.len()).map(|i| d.pmf(i)));
        prop_assert!((total - 1.0).abs() <= 1e-15, "pmf sums to {}", total);
    }

    #[test]
    fn prop_alias_never_returns_zero_weight_and_realises_the_pmf(w in weights(64), us in sorted_uniforms()) {
        let a = AliasTable::new(&w).unwrap();
        for &u in &us {
            let i = a.sample(u);
            prop_assert!(w[i] > 0.0, "u = {} returned zero-weight index {}", u, i);
        }
        for (i, p) in a.realised_pmf().into_iter().enumerate() {
            prop_assert!((p - a.pmf(i)).abs() <= 1e-13, "index {}: realised {} vs pmf {}", i, p, a.pmf(i));
        }
    }

    #[test]
    fn prop_piecewise_linear_inverts_its_cdf((xs, ys) in grid_and_values(), us in sorted_uniforms()) {
        let Some(d) = linear_table(&xs, &ys) else { return Ok(()) };
        let (lo, hi) = d.range();
        let mut previous = f64::NEG_INFINITY;
        for &u in &us {
            let x = d.sample(u);
            prop_assert!(x.is_finite() && x >= lo && x <= hi, "u = {}: {} outside support", u, x);
            prop_assert!(d.pdf(x) > 0.0, "u = {}: sample {} has zero density", u, x);
            prop_assert!(x >= previous, "u = {}: {} < previous {}", u, x, previous);
            previous = x;
            let c = d.cdf(x);
            prop_assert!((c - u).abs() <= 1e-12, "u = {}: cdf(sample) = {}", u, c);
        }
    }

    #[test]
    fn prop_piecewise_linear_pdf_integrates_to_one((xs, ys) in grid_and_values()) {
        let Some(d) = linear_table(&xs, &ys) else { return Ok(()) };
        // The density is linear between nodes, so the trapezoid rule on the nodes is exact.
        let integral = neumaier_sum(xs.windows(2).map(|p| (p[1] - p[0]) * (d.pdf(p[0]) + d.pdf(p[1])) / 2.0));
        prop_assert!((integral - 1.0).abs() <= 1e-12, "pdf integrates to {}", integral);
        prop_assert!(d.integral().is_finite() && d.integral() > 0.0);
    }

    #[test]
    fn prop_piecewise_constant_inverts_its_cdf((xs, ys) in grid_and_values(), us in sorted_uniforms()) {
        prop_assume!(ys[..ys.len() - 1].iter().any(|&y| y > 0.0));
        let d = match PiecewiseConstant::new(&xs, &ys[..ys.len() - 1]) {
            Ok(d) => d,
            Err(SamplingError::TotalUnderflow { .. }) => {
                prop_assert!(integral_underflows(&xs, &ys, false), "refused, but representable");
                return Ok(());
            }
            Err(e) => panic!("{e}"),
        };
        let mut previous = f64::NEG_INFINITY;
        for &u in &us {
            let x = d.sample(u);
            prop_assert!(x.is_finite() && d.pdf(x) > 0.0, "u = {}: {}", u, x);
            prop_assert!(x >= previous);
            previous = x;
            prop_assert!((d.cdf(x) - u).abs() <= 1e-12, "u = {}: cdf = {}", u, d.cdf(x));
        }
        let integral = neumaier_sum(xs.windows(2).map(|p| (p[1] - p[0]) * d.pdf(p[0])));
        prop_assert!((integral - 1.0).abs() <= 1e-12);
    }
}
