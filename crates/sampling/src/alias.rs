//! [`AliasTable`]: Walker's alias method, built with Vose's stable algorithm; `O(1)` per sample.

use rand::{Rng, distr::Distribution};
use serde::{Deserialize, Serialize};

use crate::SamplingError;
use crate::table::{Cdf, ldexp, unit, validate_nonnegative};

/// One column of the alias table: keep the column's own index when the 64-bit fraction is below
/// `threshold` (a probability times 2^64), otherwise return `alias`. Kept together so one cache
/// line serves both reads. Columns that always keep themselves have `alias` equal to their own
/// index, so the comparison does not matter for them.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Column {
    threshold: u64,
    alias: u32,
}

/// 2^64 as an `f64`.
const TWO_POW_64: f64 = 18_446_744_073_709_551_616.0;

impl Column {
    fn new(probability: f64, alias: usize) -> Self {
        // `as` saturates: probability 1 becomes u64::MAX (and such columns alias themselves).
        Self { threshold: (probability * TWO_POW_64) as u64, alias: alias as u32 }
    }
}

/// A discrete distribution over `0..len()` with probabilities proportional to the given weights,
/// sampled in constant time with the alias method.
///
/// One uniform `u` picks the column (`floor(u * n)`) and its fractional part decides between the
/// column and its alias; both come from one 64-bit integer (`u * 2^64`) multiplied by `n` in 128
/// bits, whose high word is the column and low word the fraction, so a sample costs one
/// multiplication, one load and one comparison. Zero-weight entries have threshold 0 and an alias with positive weight,
/// so they are never returned. Unlike [`crate::Discrete`], `sample` is not monotone in `u`.
///
/// # Example
/// ```
/// use spectrace_sampling::AliasTable;
/// let t = AliasTable::new(&[1.0, 0.0, 3.0]).unwrap();
/// assert!((t.pmf(2) - 0.75).abs() < 1e-15);
/// assert_ne!(t.sample(0.4), 1);
/// ```
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "AliasRepr", into = "AliasRepr")]
pub struct AliasTable {
    columns: Vec<Column>,
    weights: Vec<f64>,
    cdf: Cdf,
}

/// The serialised form of an [`AliasTable`]: its weights (the table is rebuilt and re-validated).
#[derive(Serialize, Deserialize)]
struct AliasRepr {
    weights: Vec<f64>,
}

impl TryFrom<AliasRepr> for AliasTable {
    type Error = SamplingError;
    fn try_from(repr: AliasRepr) -> Result<Self, SamplingError> {
        Self::new(&repr.weights)
    }
}

impl From<AliasTable> for AliasRepr {
    fn from(t: AliasTable) -> Self {
        Self { weights: t.weights }
    }
}

impl AliasTable {
    /// Builds the table from non-negative weights in `O(n)`.
    ///
    /// # Errors
    /// As [`crate::Discrete::new`]; also [`SamplingError::TooFewPoints`] is never returned, but a
    /// table of more than `u32::MAX` entries is reported as [`SamplingError::TotalOverflow`].
    pub fn new(weights: &[f64]) -> Result<Self, SamplingError> {
        const ARRAY: &str = "weights";
        if weights.is_empty() {
            return Err(SamplingError::Empty { array: ARRAY });
        }
        if weights.len() > u32::MAX as usize {
            return Err(SamplingError::TotalOverflow { array: ARRAY });
        }
        let max = validate_nonnegative(ARRAY, weights)?;
        // The cumulative table validates the total and gives exact probabilities for `pmf`.
        let cdf = Cdf::new(ARRAY, weights, max)?;
        let n = weights.len();
        let e = crate::table::exponent(max);
        let scaled: Vec<f64> = weights.iter().map(|&w| ldexp(w, -e)).collect();
        let total: f64 = ldexp(cdf.total(), -e);
        // Column heights in units of the mean: `p[i] = w[i] * n / total`, mean 1.
        let mut height: Vec<f64> = scaled.iter().map(|&w| w / total * n as f64).collect();
        let mut columns: Vec<Column> = (0..n).map(|i| Column::new(1.0, i)).collect();
        let mut small = Vec::with_capacity(n);
        let mut large = Vec::with_capacity(n);
        for (i, &h) in height.iter().enumerate() {
            if h < 1.0 { small.push(i) } else { large.push(i) }
        }
        while let (Some(&s), Some(&l)) = (small.last(), large.last()) {
            small.pop();
            columns[s] = Column::new(height[s], l);
            // The large column donates what the small one lacks. Written as (h_l + h_s) - 1
            // rather than h_l - (1 - h_s) to lose less when h_s is tiny.
            height[l] = ((height[l] + height[s]) - 1.0).max(0.0);
            if height[l] < 1.0 {
                large.pop();
                small.push(l);
            }
        }
        // Leftovers have height 1 up to rounding. A leftover with zero weight (only possible
        // through rounding) must never be returned: give it threshold 0 and a positive alias.
        let positive = weights.iter().rposition(|&w| w > 0.0).unwrap_or(0) as u32;
        for i in large.into_iter().chain(small) {
            columns[i] = if weights[i] > 0.0 {
                Column::new(1.0, i)
            } else {
                Column::new(0.0, positive as usize)
            };
        }
        Ok(Self { columns, weights: weights.to_vec(), cdf })
    }

    /// Maps a uniform `u` in `[0, 1)` to an index in constant time.
    ///
    /// `u` outside `[0, 1)` or NaN is a caller bug: it panics in debug builds and is clamped in
    /// release builds.
    #[inline]
    pub fn sample(&self, u: f64) -> usize {
        self.lookup(unit(u))
    }

    #[inline(always)]
    fn lookup(&self, u: f64) -> usize {
        // u in [0, 1) becomes a 64-bit fixed-point fraction (exact: u has 53 significant bits).
        self.lookup_bits((u * TWO_POW_64) as u64)
    }

    /// Samples from 64 uniform bits: `bits * n` in 128 bits has the column in its high word and
    /// the position inside the column in its low word.
    #[inline(always)]
    fn lookup_bits(&self, bits: u64) -> usize {
        let wide = u128::from(bits) * self.columns.len() as u128;
        let i = (wide >> 64) as usize;
        let column = self.columns[i];
        if (wide as u64) < column.threshold { i } else { column.alias as usize }
    }

    /// Probability of index `i` (0 for indices outside the table).
    #[inline]
    pub fn pmf(&self, i: usize) -> f64 {
        self.weights.get(i).map_or(0.0, |&w| self.cdf.probability_of_mass(w))
    }

    /// Number of entries (including zero-weight ones).
    #[inline]
    pub fn len(&self) -> usize {
        self.columns.len()
    }

    /// Always `false`: construction rejects empty tables.
    #[inline]
    pub fn is_empty(&self) -> bool {
        false
    }

    /// Sum of the weights.
    #[inline]
    pub fn total(&self) -> f64 {
        self.cdf.total()
    }

    /// The weights this table was built from.
    #[inline]
    pub fn weights(&self) -> &[f64] {
        &self.weights
    }

    /// The probability of each index as realised by the table itself (threshold and alias
    /// contributions summed), for checking the construction against [`AliasTable::pmf`].
    pub fn realised_pmf(&self) -> Vec<f64> {
        let n = self.columns.len();
        let mut p = vec![0.0; n];
        for (i, c) in self.columns.iter().enumerate() {
            // Columns aliasing themselves keep their whole width.
            let keep = if c.alias as usize == i { 1.0 } else { c.threshold as f64 / TWO_POW_64 };
            p[i] += keep / n as f64;
            p[c.alias as usize] += (1.0 - keep) / n as f64;
        }
        p
    }
}

impl Distribution<usize> for AliasTable {
    #[inline]
    fn sample<R: Rng + ?Sized>(&self, rng: &mut R) -> usize {
        self.lookup_bits(rng.next_u64())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn realised_probabilities_match_weights() {
        let w = [0.5, 0.0, 2.0, 1e-9, 7.0, 0.0, 3.0];
        let t = AliasTable::new(&w).unwrap();
        let total: f64 = w.iter().sum();
        for (i, p) in t.realised_pmf().into_iter().enumerate() {
            assert!((p - w[i] / total).abs() < 1e-15, "index {i}: {p} vs {}", w[i] / total);
        }
    }

    #[test]
    fn zero_weight_columns_are_never_returned() {
        let t = AliasTable::new(&[0.0, 1.0, 0.0, 0.0, 1.0, 0.0]).unwrap();
        for k in 0..6000 {
            let i = t.sample(k as f64 / 6000.0);
            assert!(i == 1 || i == 4, "u = {} gave {i}", k as f64 / 6000.0);
        }
        let last = t.sample(crate::ONE_MINUS_EPSILON);
        assert!(last == 1 || last == 4);
    }
}
