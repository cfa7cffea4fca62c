//! [`Discrete`]: the seed's cumulative-sum generator (section 2.2), searched by bisection.

use rand::{Rng, RngExt, distr::Distribution};
use serde::{Deserialize, Serialize};

use crate::SamplingError;
use crate::table::{Cdf, unit, validate_nonnegative};

/// A discrete distribution over `0..len()` with probabilities proportional to the given weights,
/// sampled by inverting its cumulative sums with a binary search (`O(log n)` per sample).
///
/// Zero-weight entries are never returned, for any `u` in `[0, 1)`. Weights may span the whole
/// `f64` range (1e300 beside 1e-300, subnormals): the table is kept rescaled by an exact power of
/// two and summed with compensation.
///
/// # Example
/// ```
/// use spectrace_sampling::Discrete;
/// let d = Discrete::new(&[1.0, 3.0, 0.0, 4.0]).unwrap();
/// assert_eq!(d.sample(0.0), 0);
/// assert_eq!(d.sample(0.2), 1);
/// assert_eq!(d.sample(0.999), 3);
/// assert!((d.pmf(3) - 0.5).abs() < 1e-15);
/// ```
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "DiscreteRepr", into = "DiscreteRepr")]
pub struct Discrete {
    weights: Vec<f64>,
    cdf: Cdf,
}

/// The serialised form of a [`Discrete`]: just its weights (the table is rebuilt and re-validated).
#[derive(Serialize, Deserialize)]
struct DiscreteRepr {
    weights: Vec<f64>,
}

impl TryFrom<DiscreteRepr> for Discrete {
    type Error = SamplingError;
    fn try_from(repr: DiscreteRepr) -> Result<Self, SamplingError> {
        Self::new(&repr.weights)
    }
}

impl From<Discrete> for DiscreteRepr {
    fn from(d: Discrete) -> Self {
        Self { weights: d.weights }
    }
}

impl Discrete {
    /// Builds the generator from non-negative weights.
    ///
    /// # Errors
    /// [`SamplingError::Empty`] for no weights; [`SamplingError::NaN`], [`SamplingError::Infinite`]
    /// or [`SamplingError::Negative`] naming the first bad index; [`SamplingError::ZeroTotal`] when
    /// every weight is zero; [`SamplingError::TotalOverflow`] when the sum exceeds `f64::MAX`.
    pub fn new(weights: &[f64]) -> Result<Self, SamplingError> {
        const ARRAY: &str = "weights";
        if weights.is_empty() {
            return Err(SamplingError::Empty { array: ARRAY });
        }
        let max = validate_nonnegative(ARRAY, weights)?;
        let cdf = Cdf::new(ARRAY, weights, max)?;
        Ok(Self { weights: weights.to_vec(), cdf })
    }

    /// Maps a uniform `u` in `[0, 1)` to an index; non-decreasing in `u`.
    ///
    /// `u` outside `[0, 1)` or NaN is a caller bug: it panics in debug builds and is clamped in
    /// release builds.
    #[inline]
    pub fn sample(&self, u: f64) -> usize {
        self.cdf.find(unit(u))
    }

    /// Like [`Discrete::sample`], also returning `u` remapped to `[0, 1)` within the chosen entry,
    /// so one uniform can drive a second, nested choice (e.g. a mixture component, then a
    /// wavelength inside it).
    #[inline]
    pub fn sample_remapped(&self, u: f64) -> (usize, f64) {
        let (i, fraction) = self.cdf.find_with_fraction(unit(u));
        (i, fraction.min(crate::ONE_MINUS_EPSILON))
    }

    /// Probability of index `i` (0 for indices outside the table).
    #[inline]
    pub fn pmf(&self, i: usize) -> f64 {
        self.weights.get(i).map_or(0.0, |&w| self.cdf.probability_of_mass(w))
    }

    /// Probability of drawing an index below `i`.
    #[inline]
    pub fn cdf(&self, i: usize) -> f64 {
        self.cdf.before(i.min(self.len()))
    }

    /// Number of entries (including zero-weight ones).
    #[inline]
    pub fn len(&self) -> usize {
        self.cdf.len()
    }

    /// Always `false`: construction rejects empty tables. Present for API symmetry with `len`.
    #[inline]
    pub fn is_empty(&self) -> bool {
        false
    }

    /// Sum of the weights.
    #[inline]
    pub fn total(&self) -> f64 {
        self.cdf.total()
    }

    /// The weights this generator was built from.
    #[inline]
    pub fn weights(&self) -> &[f64] {
        &self.weights
    }
}

impl Distribution<usize> for Discrete {
    #[inline]
    fn sample<R: Rng + ?Sized>(&self, rng: &mut R) -> usize {
        self.cdf.find(rng.random::<f64>())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seed_example_weights_one_two_three_four() {
        // The seed's figure 2: x = 1..4 with weights so that 1 and 4 are equally likely, 3 half
        // as likely as 1, and 2 three times as likely as 3 (weights 2, 3, 1, 2; total 8).
        let d = Discrete::new(&[2.0, 3.0, 1.0, 2.0]).unwrap();
        assert_eq!(d.total(), 8.0);
        assert_eq!([d.pmf(0), d.pmf(1), d.pmf(2), d.pmf(3)], [0.25, 0.375, 0.125, 0.25]);
        assert_eq!(d.sample(0.0), 0);
        assert_eq!(d.sample(0.2499), 0);
        assert_eq!(d.sample(0.25), 1);
        assert_eq!(d.sample(0.625), 2);
        assert_eq!(d.sample(0.75), 3);
        assert_eq!(d.cdf(2), 0.625);
    }

    #[test]
    fn remapped_uniform_spans_the_chosen_entry() {
        let d = Discrete::new(&[1.0, 1.0]).unwrap();
        assert_eq!(d.sample_remapped(0.25), (0, 0.5));
        assert_eq!(d.sample_remapped(0.75), (1, 0.5));
        let (i, v) = d.sample_remapped(crate::ONE_MINUS_EPSILON);
        assert_eq!(i, 1);
        assert!(v < 1.0);
    }

    #[test]
    fn out_of_range_index_has_zero_probability() {
        let d = Discrete::new(&[1.0]).unwrap();
        assert_eq!(d.pmf(0), 1.0);
        assert_eq!(d.pmf(1), 0.0);
        assert_eq!(d.cdf(5), 1.0);
    }
}
