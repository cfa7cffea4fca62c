//! [`PiecewiseConstant`]: the seed's "choppy" continuous distribution (section 2.2), kept for
//! comparison with [`crate::PiecewiseLinear`].

use rand::{Rng, RngExt, distr::Distribution};
use serde::{Deserialize, Serialize};

use crate::SamplingError;
use crate::table::{Cdf, exponent, ldexp, unit, validate_grid, validate_nonnegative};

/// A continuous distribution whose density is constant on each bin `[edges[i], edges[i+1])`,
/// proportional to `values[i]`; sampled exactly (bin by bisection, then linearly inside it).
///
/// This is what the seed's cumulative-sum generator becomes when each discrete sample stands for a
/// bin of width `dx`: the density jumps at every edge (the seed's "choppiness").
///
/// # Example
/// ```
/// use spectrace_sampling::PiecewiseConstant;
/// let d = PiecewiseConstant::uniform(0.0, 1.0, &[1.0, 3.0]).unwrap();
/// assert_eq!(d.range(), (0.0, 2.0));
/// assert_eq!(d.sample(0.25), 1.0);
/// assert_eq!(d.pdf(1.5), 0.75);
/// ```
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "PiecewiseConstantRepr", into = "PiecewiseConstantRepr")]
pub struct PiecewiseConstant {
    edges: Vec<f64>,
    values: Vec<f64>,
    cdf: Cdf,
    integral: f64,
    /// `pdf = values_scaled[i] * pdf_factor`.
    pdf_factor: f64,
    values_scaled: Vec<f64>,
}

/// The serialised form of a [`PiecewiseConstant`]: its bin edges and values.
#[derive(Serialize, Deserialize)]
struct PiecewiseConstantRepr {
    edges: Vec<f64>,
    values: Vec<f64>,
}

impl TryFrom<PiecewiseConstantRepr> for PiecewiseConstant {
    type Error = SamplingError;
    fn try_from(repr: PiecewiseConstantRepr) -> Result<Self, SamplingError> {
        Self::new(&repr.edges, &repr.values)
    }
}

impl From<PiecewiseConstant> for PiecewiseConstantRepr {
    fn from(d: PiecewiseConstant) -> Self {
        Self { edges: d.edges, values: d.values }
    }
}

impl PiecewiseConstant {
    /// Builds the generator from `n + 1` strictly increasing bin edges and `n` non-negative values.
    ///
    /// # Errors
    /// As [`crate::PiecewiseLinear::new`], with the arrays named `"edges"` and `"values"`;
    /// [`SamplingError::LengthMismatch`] unless `edges.len() == values.len() + 1`.
    pub fn new(edges: &[f64], values: &[f64]) -> Result<Self, SamplingError> {
        if values.is_empty() {
            return Err(SamplingError::Empty { array: "values" });
        }
        if edges.len() != values.len() + 1 {
            return Err(SamplingError::LengthMismatch {
                first: "edges",
                first_len: edges.len(),
                second: "values",
                second_len: values.len(),
                expected: "one more edge than values",
            });
        }
        validate_grid("edges", edges)?;
        let max_v = validate_nonnegative("values", values)?;
        if max_v <= 0.0 {
            return Err(SamplingError::ZeroTotal { array: "values" });
        }
        let ev = exponent(max_v);
        let max_width = edges.windows(2).map(|p| p[1] - p[0]).fold(0.0_f64, f64::max);
        let ew = if max_width > f64::MAX / 4.0 { 2 } else { 0 };
        let values_scaled: Vec<f64> = values.iter().map(|&v| ldexp(v, -ev)).collect();
        let masses: Vec<f64> = edges
            .windows(2)
            .zip(&values_scaled)
            .map(|(e, &v)| ldexp(e[1] - e[0], -ew) * v)
            .collect();
        let mut masses = masses;
        let max_mass = masses.iter().copied().fold(0.0_f64, f64::max);
        let mut cdf = Cdf::new("values", &masses, max_mass)?;
        let mut pdf_factor = ldexp(1.0 / cdf.total(), -ew);
        if let Some(index) = values_scaled.iter().position(|&v| !(v * pdf_factor).is_finite()) {
            return Err(SamplingError::DensityOverflow { array: "values", index });
        }
        // A bin whose normalised density underflows to zero carries no representable probability.
        let mut dropped = false;
        for (mass, &v) in masses.iter_mut().zip(&values_scaled) {
            if *mass > 0.0 && v * pdf_factor == 0.0 {
                *mass = 0.0;
                dropped = true;
            }
        }
        if dropped {
            cdf = Cdf::new("values", &masses, max_mass)?;
            pdf_factor = ldexp(1.0 / cdf.total(), -ew);
        }
        let integral = ldexp(cdf.total(), ev + ew);
        if !integral.is_finite() {
            return Err(SamplingError::TotalOverflow { array: "values" });
        }
        if integral == 0.0 {
            return Err(SamplingError::TotalUnderflow { array: "values" });
        }
        Ok(Self {
            edges: edges.to_vec(),
            values: values.to_vec(),
            cdf,
            integral,
            pdf_factor,
            values_scaled,
        })
    }

    /// Builds the generator from `values.len()` bins of equal width `dx` starting at `start`.
    ///
    /// # Errors
    /// As [`PiecewiseConstant::new`]; a non-finite or non-positive `dx` is reported as
    /// [`SamplingError::NotIncreasing`] on `"edges"` at index 1.
    pub fn uniform(start: f64, dx: f64, values: &[f64]) -> Result<Self, SamplingError> {
        let edges: Vec<f64> = (0..=values.len()).map(|i| start + dx * i as f64).collect();
        Self::new(&edges, values)
    }

    /// Maps a uniform `u` in `[0, 1)` to a point of the support; non-decreasing in `u`.
    ///
    /// `u` outside `[0, 1)` or NaN is a caller bug: it panics in debug builds and is clamped in
    /// release builds.
    #[inline]
    pub fn sample(&self, u: f64) -> f64 {
        self.invert(unit(u))
    }

    #[inline(always)]
    fn invert(&self, u: f64) -> f64 {
        let (i, s) = self.cdf.find_with_fraction(u);
        let (x0, x1) = (self.edges[i], self.edges[i + 1]);
        // Stay inside the bin, and off its right edge (which belongs to the next bin).
        (x0 + s * (x1 - x0)).min(x1.next_down())
    }

    /// The normalised density at `x` (0 outside the support; bins are closed on the left).
    #[inline]
    pub fn pdf(&self, x: f64) -> f64 {
        match self.locate(x) {
            Some(i) => self.values_scaled[i] * self.pdf_factor,
            None => 0.0,
        }
    }

    /// The cumulative distribution function at `x`.
    #[inline]
    pub fn cdf(&self, x: f64) -> f64 {
        if x.is_nan() {
            return f64::NAN;
        }
        let n = self.edges.len();
        if x <= self.edges[0] {
            return 0.0;
        }
        if x >= self.edges[n - 1] {
            return 1.0;
        }
        match self.locate(x) {
            Some(i) => {
                let (x0, x1) = (self.edges[i], self.edges[i + 1]);
                self.cdf.cdf_at(i, ((x - x0) / (x1 - x0)).clamp(0.0, 1.0))
            }
            None => 0.0,
        }
    }

    #[inline]
    fn locate(&self, x: f64) -> Option<usize> {
        let n = self.edges.len();
        if !(x >= self.edges[0] && x < self.edges[n - 1]) {
            return None;
        }
        Some(self.edges.partition_point(|&e| e <= x) - 1)
    }

    /// The integral of the unnormalised density: `sum(values[i] * (edges[i+1] - edges[i]))`.
    #[inline]
    pub fn integral(&self) -> f64 {
        self.integral
    }

    /// The support `(edges[0], edges[last])`.
    #[inline]
    pub fn range(&self) -> (f64, f64) {
        (self.edges[0], self.edges[self.edges.len() - 1])
    }

    /// The bin edges.
    #[inline]
    pub fn edges(&self) -> &[f64] {
        &self.edges
    }

    /// The unnormalised bin values.
    #[inline]
    pub fn values(&self) -> &[f64] {
        &self.values
    }
}

impl Distribution<f64> for PiecewiseConstant {
    #[inline]
    fn sample<R: Rng + ?Sized>(&self, rng: &mut R) -> f64 {
        self.invert(rng.random::<f64>())
    }
}
