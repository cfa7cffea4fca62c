//! Shared machinery: input validation, exact power-of-two rescaling, and the cumulative table
//! that every generator in this crate searches.

use crate::SamplingError;

/// The largest `f64` below 1, i.e. `1 - 2^-53`: where an out-of-range `u` is clamped to.
pub const ONE_MINUS_EPSILON: f64 = 1.0 - f64::EPSILON / 2.0;

/// Clamps a uniform variate into `[0, 1)`. `u` outside that range or NaN is a caller bug: debug
/// builds panic, release builds clamp (NaN goes to 0).
#[inline(always)]
pub(crate) fn unit(u: f64) -> f64 {
    debug_assert!((0.0..1.0).contains(&u), "uniform variate u = {u} is outside [0, 1)");
    crate::clamp_uniform(u)
}

/// Multiplies `x` by `2^e` exactly (unless the result leaves the normal range), for any `e`.
#[inline]
pub(crate) fn ldexp(mut x: f64, mut e: i32) -> f64 {
    // 2^1000 and 2^-1000 are normal numbers; multiplying by them is exact.
    const UP: f64 = 1.0715086071862673e301; // 2^1000
    const DOWN: f64 = 9.332636185032189e-302; // 2^-1000
    while e > 1000 {
        x *= UP;
        e -= 1000;
    }
    while e < -1000 {
        x *= DOWN;
        e += 1000;
    }
    x * f64::from_bits(((e + 1023) as u64) << 52)
}

/// Maps a finite `f64` to an integer key with the same order (so bisection can walk floats).
fn ordered_key(x: f64) -> i64 {
    let bits = x.to_bits() as i64;
    if bits < 0 { -(bits & i64::MAX) } else { bits }
}

/// Inverse of [`ordered_key`].
fn from_ordered_key(k: i64) -> f64 {
    if k < 0 { f64::from_bits((-k) as u64 | (1 << 63)) } else { f64::from_bits(k as u64) }
}

/// The first float `x` in `[lo, hi]` with `pred(x)`, where `pred` is false then true along the
/// floats (monotone) and `pred(hi)` holds.
pub(crate) fn first_float_where(lo: f64, hi: f64, pred: impl Fn(f64) -> bool) -> f64 {
    let (mut a, mut b) = (i128::from(ordered_key(lo)), i128::from(ordered_key(hi)));
    if pred(lo) {
        return lo;
    }
    // Invariant: pred(a) is false, pred(b) is true.
    while b - a > 1 {
        let m = a + (b - a) / 2;
        if pred(from_ordered_key(m as i64)) { b = m } else { a = m }
    }
    from_ordered_key(b as i64)
}

/// The last float `x` in `[lo, hi]` with `pred(x)`, where `pred` is true then false along the
/// floats (monotone) and `pred(lo)` holds.
pub(crate) fn last_float_where(lo: f64, hi: f64, pred: impl Fn(f64) -> bool) -> f64 {
    let (mut a, mut b) = (i128::from(ordered_key(lo)), i128::from(ordered_key(hi)));
    if pred(hi) {
        return hi;
    }
    // Invariant: pred(a) is true, pred(b) is false.
    while b - a > 1 {
        let m = a + (b - a) / 2;
        if pred(from_ordered_key(m as i64)) { a = m } else { b = m }
    }
    from_ordered_key(a as i64)
}

/// The binary exponent of a positive finite `x`: `x = m * 2^e` with `m` in `[1, 2)`.
pub(crate) fn exponent(x: f64) -> i32 {
    debug_assert!(x > 0.0 && x.is_finite());
    let bits = x.to_bits();
    let biased = ((bits >> 52) & 0x7ff) as i32;
    if biased == 0 {
        // Subnormal: the leading one is inside the mantissa.
        let mantissa = bits & ((1u64 << 52) - 1);
        -1022 - (mantissa.leading_zeros() as i32 - 11)
    } else {
        biased - 1023
    }
}

/// Checks that every entry is finite and not negative; returns the largest entry.
pub(crate) fn validate_nonnegative(
    array: &'static str,
    values: &[f64],
) -> Result<f64, SamplingError> {
    let mut max = 0.0_f64;
    for (index, &value) in values.iter().enumerate() {
        if value.is_nan() {
            return Err(SamplingError::NaN { array, index });
        }
        if value.is_infinite() {
            return Err(SamplingError::Infinite { array, index, value });
        }
        if value < 0.0 {
            return Err(SamplingError::Negative { array, index, value });
        }
        max = max.max(value);
    }
    Ok(max)
}

/// Checks that a grid is finite and strictly increasing and that no gap overflows.
pub(crate) fn validate_grid(array: &'static str, xs: &[f64]) -> Result<(), SamplingError> {
    for (index, &value) in xs.iter().enumerate() {
        if value.is_nan() {
            return Err(SamplingError::NaN { array, index });
        }
        if value.is_infinite() {
            return Err(SamplingError::Infinite { array, index, value });
        }
        if index > 0 {
            let previous = xs[index - 1];
            if value <= previous {
                return Err(SamplingError::NotIncreasing { array, index, value, previous });
            }
            if !(value - previous).is_finite() {
                return Err(SamplingError::SpanOverflow { array, index: index - 1 });
            }
        }
    }
    Ok(())
}

/// A cumulative table over non-negative masses, stored rescaled by an exact power of two so that
/// the largest mass lies in `[1, 2)`: subnormal inputs keep their full precision and huge inputs
/// cannot overflow the running sum.
///
/// Entry `i` owns the half-open mass interval `[edges[i], edges[i + 1])`. Finding the entry for a
/// target mass is a bisection, narrowed first by a guide table (Chen and Asau's cutpoint method):
/// `guide[k]` is the entry that holds mass `k / m` of the total, so a search only bisects the
/// few entries between two cutpoints. The guide only narrows the range; the answer is always the
/// one the full bisection gives, so `find` stays exact and monotone.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Cdf {
    /// `edges[0] = 0`, `edges[i + 1]` = rescaled mass of entries `0..=i`; non-decreasing.
    edges: Vec<f64>,
    /// Cutpoints: `guide[k]` = the entry holding rescaled mass `k / m * total`, `k` in `0..=m`.
    /// Empty for small tables, where a plain bisection is faster.
    guide: Vec<u32>,
    /// Sum of all rescaled masses (`edges.last()`).
    total_scaled: f64,
    /// The exponent `e` with `raw mass = scaled mass * 2^e`.
    scale_exponent: i32,
    /// Total raw mass (finite).
    total: f64,
    /// Index of the last entry with positive mass, returned when `u * total` rounds to the total.
    last_positive: usize,
}

/// Tables with at least this many entries get a guide table.
const GUIDE_MIN_LEN: usize = 16;

impl Cdf {
    /// Builds the table. `masses` must already be validated (finite, non-negative, not empty).
    pub(crate) fn new(
        array: &'static str,
        masses: &[f64],
        max: f64,
    ) -> Result<Self, SamplingError> {
        if max <= 0.0 {
            return Err(SamplingError::ZeroTotal { array });
        }
        let scale_exponent = exponent(max);
        let mut edges = Vec::with_capacity(masses.len() + 1);
        edges.push(0.0);
        // Neumaier's compensated sum: the running total is accurate to about one ulp even for
        // 10^6 entries, so `pmf` sums to 1 and the CDF is exact where it matters. A zero mass
        // leaves sum and compensation untouched, so zero-mass entries have equal edges on both
        // sides and can never be found by the search below.
        let (mut sum, mut compensation) = (0.0_f64, 0.0_f64);
        let mut previous = 0.0_f64;
        let mut last_positive = 0;
        for (i, &m) in masses.iter().enumerate() {
            let m = ldexp(m, -scale_exponent);
            if m > 0.0 {
                let t = sum + m;
                if sum.abs() >= m {
                    compensation += (sum - t) + m;
                } else {
                    compensation += (m - t) + sum;
                }
                sum = t;
            }
            // Keep the table monotone even where the compensation term moves the rounded value.
            let value = (sum + compensation).max(previous);
            if value > previous {
                last_positive = i;
            }
            edges.push(value);
            previous = value;
        }
        let total_scaled = previous;
        if total_scaled <= 0.0 {
            return Err(SamplingError::ZeroTotal { array });
        }
        let total = ldexp(total_scaled, scale_exponent);
        if !total.is_finite() {
            return Err(SamplingError::TotalOverflow { array });
        }
        let mut cdf =
            Self { edges, guide: Vec::new(), total_scaled, scale_exponent, total, last_positive };
        let n = masses.len();
        if n >= GUIDE_MIN_LEN && n < u32::MAX as usize {
            let m = n;
            cdf.guide = (0..=m)
                .map(|k| {
                    let u = (k as f64 / m as f64).min(ONE_MINUS_EPSILON);
                    cdf.search(u * total_scaled) as u32
                })
                .collect();
        }
        Ok(cdf)
    }

    /// Total raw mass.
    #[inline]
    pub(crate) fn total(&self) -> f64 {
        self.total
    }

    /// Number of entries.
    #[inline]
    pub(crate) fn len(&self) -> usize {
        self.edges.len() - 1
    }

    /// Probability of entry `i` from the cumulative table (0 outside the table).
    #[cfg(test)]
    pub(crate) fn probability(&self, i: usize) -> f64 {
        if i >= self.len() {
            return 0.0;
        }
        (self.edges[i + 1] - self.edges[i]) / self.total_scaled
    }

    /// Probability of an entry whose raw mass is `mass`: `mass / total`, computed in the rescaled
    /// units so that neither a subnormal nor a huge mass loses precision.
    #[inline]
    pub(crate) fn probability_of_mass(&self, mass: f64) -> f64 {
        ldexp(mass, -self.scale_exponent) / self.total_scaled
    }

    /// Fraction of the total mass in entries `0..i` (i.e. before entry `i`).
    #[inline]
    pub(crate) fn before(&self, i: usize) -> f64 {
        self.edges[i.min(self.len())] / self.total_scaled
    }

    /// The rescaled mass bounds `(lo, hi)` of entry `i`.
    #[inline(always)]
    pub(crate) fn bounds(&self, i: usize) -> (f64, f64) {
        (self.edges[i], self.edges[i + 1])
    }

    /// Fraction of the total mass below entry `i` plus `fraction` of entry `i`'s own mass.
    #[inline]
    pub(crate) fn cdf_at(&self, i: usize, fraction: f64) -> f64 {
        let (lo, hi) = self.bounds(i);
        ((lo + (hi - lo) * fraction) / self.total_scaled).min(1.0)
    }

    /// The entry owning rescaled mass `target` by full bisection: the `i` with
    /// `edges[i] <= target < edges[i + 1]`, or the last positive entry if `target` reaches the
    /// total. Such an `i` always has positive mass.
    #[inline]
    fn search(&self, target: f64) -> usize {
        // The last edge is the total and needs no comparison: landing on the last entry means
        // either that entry (target below the total) or a target rounded up to the total.
        let n = self.len();
        let j = self.edges[1..n].partition_point(|&c| c <= target);
        if j + 1 < n || target < self.total_scaled { j } else { self.last_positive }
    }

    /// Finds the entry that `u` (already in `[0, 1)`) falls into, with its rescaled target mass.
    #[inline(always)]
    pub(crate) fn locate(&self, u: f64) -> (usize, f64) {
        let target = u * self.total_scaled;
        if self.guide.is_empty() {
            return (self.search(target), target);
        }
        let m = self.guide.len() - 1;
        let k = crate::cell_index(u * m as f64, m - 1);
        let (lo, hi) = (self.guide[k] as usize, self.guide[k + 1] as usize);
        // The answer lies in lo..=hi when edges[lo] <= target < edges[hi + 1]; otherwise (rounding
        // at a cutpoint, or target at the very top) fall back to the full search.
        if self.edges[lo] <= target && target < self.edges[hi + 1] {
            (lo + self.edges[lo + 1..=hi].partition_point(|&c| c <= target), target)
        } else {
            (self.search(target), target)
        }
    }

    /// Finds the entry that `u` (already in `[0, 1)`) falls into: the unique `i` with positive
    /// mass such that `edges[i] <= u * total < edges[i + 1]`.
    #[inline]
    pub(crate) fn find(&self, u: f64) -> usize {
        self.locate(u).0
    }

    /// Like [`Cdf::find`], also returning where in the entry's mass `u` fell, as a fraction in
    /// `[0, 1]` that is non-decreasing in `u`.
    #[inline]
    pub(crate) fn find_with_fraction(&self, u: f64) -> (usize, f64) {
        let (i, target) = self.locate(u);
        let (lo, hi) = self.bounds(i);
        (i, ((target - lo) / (hi - lo)).min(1.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ldexp_is_exact_across_the_whole_range() {
        assert_eq!(ldexp(1.0, 0), 1.0);
        assert_eq!(ldexp(1.0, 1023), 2f64.powi(1023));
        assert_eq!(ldexp(1.0, -1074), f64::from_bits(1));
        assert_eq!(ldexp(f64::from_bits(1), 1074), 1.0);
        assert_eq!(ldexp(3.0, -2), 0.75);
        assert_eq!(ldexp(f64::MAX, -1023), f64::MAX / 2f64.powi(1023));
    }

    #[test]
    fn exponent_of_normal_and_subnormal_numbers() {
        assert_eq!(exponent(1.0), 0);
        assert_eq!(exponent(1.999), 0);
        assert_eq!(exponent(2.0), 1);
        assert_eq!(exponent(0.75), -1);
        assert_eq!(exponent(f64::MIN_POSITIVE), -1022);
        assert_eq!(exponent(f64::from_bits(1)), -1074);
        assert_eq!(exponent(f64::from_bits(3)), -1073);
        assert_eq!(exponent(f64::MAX), 1023);
    }

    #[test]
    fn float_bisection_finds_the_threshold() {
        assert_eq!(first_float_where(0.0, 1.0, |x| x > 0.0), f64::from_bits(1));
        assert_eq!(first_float_where(-1.0, 1.0, |x| x >= 0.25), 0.25);
        assert_eq!(last_float_where(-2.0, 1.0, |x| x < -1.0), (-1.0f64).next_down());
        assert_eq!(last_float_where(0.0, 3.0, |x| x <= 3.0), 3.0);
        assert_eq!(ordered_key(-0.0), ordered_key(0.0));
        for x in [-3.5, 0.0, 1e-310, 2.0, f64::MAX, -f64::MAX] {
            assert_eq!(from_ordered_key(ordered_key(x)).to_bits(), x.to_bits());
        }
        assert!(ordered_key(-1.0) < ordered_key(-0.5) && ordered_key(-0.5) < ordered_key(1e-300));
    }

    #[test]
    fn unit_clamps_in_release_semantics() {
        assert_eq!(unit(0.0), 0.0);
        assert_eq!(unit(0.5), 0.5);
        assert_eq!(unit(ONE_MINUS_EPSILON), ONE_MINUS_EPSILON);
        assert!(ONE_MINUS_EPSILON < 1.0 && ONE_MINUS_EPSILON.next_up() == 1.0);
    }

    #[test]
    fn guide_table_gives_the_same_answer_as_bisection() {
        // Many zero and tiny entries around a few large ones: cutpoints land in long runs.
        let masses: Vec<f64> = (0..1000)
            .map(|i| match i % 10 {
                0 => 0.0,
                3 => 1e-12,
                7 => 5.0 + (i % 13) as f64,
                _ => 0.001,
            })
            .collect();
        let cdf = Cdf::new("w", &masses, 17.0).unwrap();
        assert_eq!(cdf.guide.len(), 1001);
        for k in 0..200_000 {
            let u = k as f64 / 200_000.0;
            assert_eq!(cdf.find(u), cdf.search(u * cdf.total_scaled), "u = {u}");
        }
        assert_eq!(cdf.find(ONE_MINUS_EPSILON), cdf.search(ONE_MINUS_EPSILON * cdf.total_scaled));
    }

    #[test]
    fn zero_mass_entries_share_cumulative_values() {
        let cdf = Cdf::new("w", &[0.0, 1.0, 0.0, 0.0, 2.0, 0.0], 2.0).unwrap();
        assert_eq!(cdf.find(0.0), 1);
        assert_eq!(cdf.find(ONE_MINUS_EPSILON), 4);
        assert_eq!(cdf.last_positive, 4);
        assert!(cdf.guide.is_empty());
        assert_eq!(cdf.probability(0), 0.0);
        assert_eq!(cdf.probability(2), 0.0);
        assert!((cdf.probability(4) - 2.0 / 3.0).abs() < 1e-16);
    }
}
