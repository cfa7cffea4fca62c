//! A small goodness-of-fit harness shared by the tests of every Spectrace crate: Pearson's
//! chi-square test (with pooling of sparse bins) and the Kolmogorov-Smirnov test, with exact-enough
//! p-values from the regularised incomplete gamma function and the Kolmogorov series.
//!
//! Statistical tests in Spectrace run at a fixed seed and compare the p-value with a stated alpha;
//! the alpha is the probability that a *correct* sampler would fail the test at a random seed.

/// Result of a chi-square goodness-of-fit test.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChiSquare {
    /// Pearson's statistic, sum over pooled bins of `(observed - expected)^2 / expected`.
    pub statistic: f64,
    /// Degrees of freedom: pooled bins minus one.
    pub dof: usize,
    /// Probability of a statistic at least this large if the sampler is correct.
    pub p_value: f64,
}

/// Pearson's chi-square test of observed counts against expected counts (same total).
///
/// Adjacent bins are pooled until each pooled bin expects at least `min_expected` samples (5 is the
/// usual rule), so the chi-square approximation holds. A bin with zero expectation but a non-zero
/// count makes the p-value 0: the sampler produced an impossible value.
pub fn chi_square(observed: &[u64], expected: &[f64], min_expected: f64) -> ChiSquare {
    assert_eq!(observed.len(), expected.len(), "observed and expected differ in length");
    let mut statistic = 0.0;
    let mut bins = 0usize;
    let (mut obs, mut exp) = (0.0_f64, 0.0_f64);
    for (&o, &e) in observed.iter().zip(expected) {
        if e <= 0.0 && o > 0 {
            return ChiSquare { statistic: f64::INFINITY, dof: 0, p_value: 0.0 };
        }
        obs += o as f64;
        exp += e;
        if exp >= min_expected {
            statistic += (obs - exp) * (obs - exp) / exp;
            bins += 1;
            obs = 0.0;
            exp = 0.0;
        }
    }
    if exp > 0.0 || obs > 0.0 {
        // Fold the sparse tail into the statistic as one more bin (or into the last bin).
        if exp > 0.0 {
            statistic += (obs - exp) * (obs - exp) / exp;
            bins += 1;
        } else {
            return ChiSquare { statistic: f64::INFINITY, dof: 0, p_value: 0.0 };
        }
    }
    let dof = bins.saturating_sub(1).max(1);
    ChiSquare { statistic, dof, p_value: chi_square_sf(statistic, dof as f64) }
}

/// Upper tail `P(X >= x)` of the chi-square distribution with `k` degrees of freedom.
pub fn chi_square_sf(x: f64, k: f64) -> f64 {
    if x <= 0.0 {
        return 1.0;
    }
    gamma_q(k / 2.0, x / 2.0)
}

/// Histogram of `samples` over `bins` equal bins of `[lo, hi)`; values outside are not counted.
pub fn histogram(
    samples: impl IntoIterator<Item = f64>,
    lo: f64,
    hi: f64,
    bins: usize,
) -> Vec<u64> {
    let mut counts = vec![0u64; bins];
    let width = (hi - lo) / bins as f64;
    for x in samples {
        if x >= lo && x < hi {
            let i = (((x - lo) / width) as usize).min(bins - 1);
            counts[i] += 1;
        }
    }
    counts
}

/// Expected counts for `n` samples in `bins` equal bins of `[lo, hi)` of a distribution with the
/// given CDF.
pub fn expected_counts(
    cdf: impl Fn(f64) -> f64,
    lo: f64,
    hi: f64,
    bins: usize,
    n: u64,
) -> Vec<f64> {
    let width = (hi - lo) / bins as f64;
    (0..bins)
        .map(|i| {
            let a = lo + width * i as f64;
            let b = if i + 1 == bins { hi } else { lo + width * (i + 1) as f64 };
            (cdf(b) - cdf(a)).max(0.0) * n as f64
        })
        .collect()
}

/// Result of a one-sample Kolmogorov-Smirnov test.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KolmogorovSmirnov {
    /// The largest distance between the empirical and the reference CDF.
    pub statistic: f64,
    /// Asymptotic probability of a distance at least this large if the sampler is correct.
    pub p_value: f64,
}

/// One-sample Kolmogorov-Smirnov test of `samples` against a continuous CDF.
pub fn kolmogorov_smirnov(mut samples: Vec<f64>, cdf: impl Fn(f64) -> f64) -> KolmogorovSmirnov {
    samples.sort_by(f64::total_cmp);
    let n = samples.len() as f64;
    let mut d = 0.0_f64;
    for (i, &x) in samples.iter().enumerate() {
        let f = cdf(x);
        d = d.max(f - i as f64 / n).max((i + 1) as f64 / n - f);
    }
    // Stephens' small-sample correction of the asymptotic Kolmogorov distribution.
    let lambda = (n.sqrt() + 0.12 + 0.11 / n.sqrt()) * d;
    KolmogorovSmirnov { statistic: d, p_value: kolmogorov_sf(lambda) }
}

/// `P(K > lambda)` for the Kolmogorov distribution: `2 sum (-1)^(k-1) exp(-2 k^2 lambda^2)`.
fn kolmogorov_sf(lambda: f64) -> f64 {
    if lambda < 0.2 {
        return 1.0;
    }
    let mut sum = 0.0;
    for k in 1..=100 {
        let k = k as f64;
        let term = (-2.0 * k * k * lambda * lambda).exp();
        sum += if k as u64 % 2 == 1 { term } else { -term };
        if term < 1e-17 {
            break;
        }
    }
    (2.0 * sum).clamp(0.0, 1.0)
}

/// Regularised upper incomplete gamma function `Q(a, x) = Gamma(a, x) / Gamma(a)`.
fn gamma_q(a: f64, x: f64) -> f64 {
    if x < a + 1.0 { 1.0 - gamma_p_series(a, x) } else { gamma_q_continued_fraction(a, x) }
}

/// Series for the regularised lower incomplete gamma function, for `x < a + 1`.
fn gamma_p_series(a: f64, x: f64) -> f64 {
    let mut term = 1.0 / a;
    let mut sum = term;
    let mut ap = a;
    for _ in 0..10_000 {
        ap += 1.0;
        term *= x / ap;
        sum += term;
        if term.abs() < sum.abs() * 1e-16 {
            break;
        }
    }
    (sum.ln() - x + a * x.ln() - ln_gamma(a)).exp()
}

/// Continued fraction (modified Lentz) for `Q(a, x)`, for `x >= a + 1`.
fn gamma_q_continued_fraction(a: f64, x: f64) -> f64 {
    const TINY: f64 = 1e-300;
    let mut b = x + 1.0 - a;
    let mut c = 1.0 / TINY;
    let mut d = 1.0 / b;
    let mut h = d;
    for i in 1..10_000 {
        let an = -(i as f64) * (i as f64 - a);
        b += 2.0;
        d = an * d + b;
        if d.abs() < TINY {
            d = TINY;
        }
        c = b + an / c;
        if c.abs() < TINY {
            c = TINY;
        }
        d = 1.0 / d;
        let delta = d * c;
        h *= delta;
        if (delta - 1.0).abs() < 1e-16 {
            break;
        }
    }
    (-x + a * x.ln() - ln_gamma(a)).exp() * h
}

/// `ln Gamma(x)` for `x > 0` (Lanczos approximation, g = 7, n = 9; relative error ~1e-15).
fn ln_gamma(x: f64) -> f64 {
    const G: f64 = 7.0;
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        // Reflection: Gamma(x) Gamma(1 - x) = pi / sin(pi x).
        return (std::f64::consts::PI / (std::f64::consts::PI * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut sum = C[0];
    for (i, &c) in C.iter().enumerate().skip(1) {
        sum += c / (x + i as f64);
    }
    let t = x + G + 0.5;
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + sum.ln()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ln_gamma_matches_factorials() {
        for (n, fact) in [(1.0, 1.0), (2.0, 1.0), (5.0, 24.0), (11.0, 3_628_800.0_f64)] {
            assert!((ln_gamma(n) - fact.ln()).abs() < 1e-12, "n = {n}");
        }
        assert!((ln_gamma(0.5) - std::f64::consts::PI.sqrt().ln()).abs() < 1e-13);
    }

    #[test]
    fn chi_square_critical_values_from_tables() {
        // Published 5% and 0.1% critical values (e.g. NIST/SEMATECH e-Handbook, table 1.3.6.7.4).
        for (x, k, p) in [
            (3.841, 1.0, 0.05),
            (18.307, 10.0, 0.05),
            (124.342, 100.0, 0.05),
            (10.828, 1.0, 0.001),
            (29.588, 10.0, 0.001),
            (149.449, 100.0, 0.001),
        ] {
            let sf = chi_square_sf(x, k);
            assert!((sf - p).abs() < p * 2e-3, "chi2 sf({x}, {k}) = {sf}, expected {p}");
        }
    }

    #[test]
    fn chi_square_detects_a_wrong_distribution_and_accepts_the_right_one() {
        let expected = vec![1000.0; 10];
        let good: Vec<u64> = vec![1010, 990, 1003, 970, 1025, 1000, 995, 1012, 987, 1008];
        let bad: Vec<u64> = vec![1200, 990, 1003, 970, 1025, 1000, 995, 1012, 987, 818];
        assert!(chi_square(&good, &expected, 5.0).p_value > 0.5);
        assert!(chi_square(&bad, &expected, 5.0).p_value < 1e-6);
        // A count where nothing is expected is an immediate failure.
        let impossible = chi_square(&[5, 10], &[0.0, 15.0], 5.0);
        assert_eq!(impossible.p_value, 0.0);
    }

    #[test]
    fn sparse_bins_are_pooled() {
        let r = chi_square(&[1, 0, 2, 100], &[1.0, 1.0, 1.0, 100.0], 5.0);
        assert_eq!(r.dof, 1);
    }

    #[test]
    fn kolmogorov_tail_values() {
        // Kolmogorov distribution: P(K > 1.358) = 0.05, P(K > 1.628) = 0.01.
        assert!((kolmogorov_sf(1.358) - 0.05).abs() < 1e-3);
        assert!((kolmogorov_sf(1.628) - 0.01).abs() < 2e-4);
    }
}
