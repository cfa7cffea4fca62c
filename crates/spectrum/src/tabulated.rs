//! Measured spectra: [`Tabulated`] (piecewise linear) and [`Binned`] (piecewise constant).
//!
//! | type | JSON | meaning |
//! |---|---|---|
//! | `Tabulated` | `{"type": "Tabulated", "nm": [400, 500, 600], "values": [0.2, 1.0, 0.4]}` | linear between the points, zero outside `[nm[0], nm[last]]` |
//! | `Binned` | `{"type": "Binned", "edges_nm": [400, 450, 500], "values": [1.0, 3.0]}` | constant `values[i]` on `[edges_nm[i], edges_nm[i+1])` |
//!
//! Values are relative (any positive scale); both are normalised to integral 1 and sampled
//! exactly by inverting their CDF.

use serde::{Deserialize, Serialize};
use spectrace_sampling::{PiecewiseConstant, PiecewiseLinear};

use crate::error::SpectrumError;
use crate::spd::SpectralPowerDistribution;

/// A spectrum given as `(nm, value)` points, linear between them (seed 2.2.1's gap filling),
/// normalised to integral 1 and importance-sampled exactly.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "TabulatedRepr", into = "TabulatedRepr")]
pub struct Tabulated {
    table: PiecewiseLinear,
}

/// Scene-file form of [`Tabulated`].
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct TabulatedRepr {
    nm: Vec<f64>,
    values: Vec<f64>,
}

impl TryFrom<TabulatedRepr> for Tabulated {
    type Error = SpectrumError;
    fn try_from(r: TabulatedRepr) -> Result<Self, SpectrumError> {
        Self::new(&r.nm, &r.values)
    }
}

impl From<Tabulated> for TabulatedRepr {
    fn from(t: Tabulated) -> Self {
        Self { nm: t.table.xs().to_vec(), values: t.table.ys().to_vec() }
    }
}

impl Tabulated {
    /// Builds the spectrum from strictly increasing wavelengths `nm` (positive) and non-negative
    /// relative values.
    ///
    /// # Errors
    /// [`SpectrumError::Table`] naming `nm[i]` or `values[i]` (empty, lengths differ, NaN,
    /// infinite, negative, not increasing, all zero); [`SpectrumError::Parameter`] for a
    /// wavelength that is not positive.
    pub fn new(nm: &[f64], values: &[f64]) -> Result<Self, SpectrumError> {
        let table = PiecewiseLinear::new(nm, values)
            .map_err(|e| SpectrumError::table("Tabulated", &[("xs", "nm"), ("ys", "values")], e))?;
        if nm[0] <= 0.0 {
            return Err(SpectrumError::parameter(
                "Tabulated",
                "nm[0]",
                nm[0],
                "wavelengths must be positive",
            ));
        }
        Ok(Self { table })
    }

    /// Builds the spectrum from `(nm, value)` pairs.
    ///
    /// # Errors
    /// As [`Tabulated::new`].
    pub fn from_pairs(pairs: &[(f64, f64)]) -> Result<Self, SpectrumError> {
        let (nm, values): (Vec<f64>, Vec<f64>) = pairs.iter().copied().unzip();
        Self::new(&nm, &values)
    }

    /// A table sampled at a regular step from `start_nm`.
    ///
    /// # Errors
    /// As [`Tabulated::new`].
    pub fn regular(start_nm: f64, step_nm: f64, values: &[f64]) -> Result<Self, SpectrumError> {
        let nm: Vec<f64> = (0..values.len()).map(|i| start_nm + step_nm * i as f64).collect();
        Self::new(&nm, values)
    }

    /// The wavelengths of the table.
    pub fn nm(&self) -> &[f64] {
        self.table.xs()
    }

    /// The relative values of the table, as given.
    pub fn values(&self) -> &[f64] {
        self.table.ys()
    }

    /// The underlying sampler.
    pub fn sampler(&self) -> &PiecewiseLinear {
        &self.table
    }
}

#[typetag::serde]
impl SpectralPowerDistribution for Tabulated {
    fn sample_lambda(&self, u: f64) -> f64 {
        self.table.sample(u)
    }
    fn value(&self, lambda: f64) -> f64 {
        self.table.pdf(lambda)
    }
    fn range(&self) -> (f64, f64) {
        self.table.range()
    }
    fn breakpoints(&self) -> Vec<f64> {
        self.table.xs().to_vec()
    }
    fn piecewise_constant(&self) -> Option<Box<dyn SpectralPowerDistribution>> {
        Binned::centred_on_nodes(self.table.xs(), self.table.ys()).ok().map(|b| Box::new(b) as _)
    }
}

/// A spectrum given as bins of constant value (the seed's "choppy" distribution), normalised to
/// integral 1 and sampled exactly.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "BinnedRepr", into = "BinnedRepr")]
pub struct Binned {
    table: PiecewiseConstant,
}

/// Scene-file form of [`Binned`].
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct BinnedRepr {
    edges_nm: Vec<f64>,
    values: Vec<f64>,
}

impl TryFrom<BinnedRepr> for Binned {
    type Error = SpectrumError;
    fn try_from(r: BinnedRepr) -> Result<Self, SpectrumError> {
        Self::new(&r.edges_nm, &r.values)
    }
}

impl From<Binned> for BinnedRepr {
    fn from(b: Binned) -> Self {
        Self { edges_nm: b.table.edges().to_vec(), values: b.table.values().to_vec() }
    }
}

impl Binned {
    /// Bins centred on the nodes `nm` (edges half-way between neighbours, the outer bins as wide
    /// as their inner neighbour, the first edge kept positive), bin `i` with value `values[i]`:
    /// the piecewise-constant counterpart of a [`Tabulated`] with the same table.
    ///
    /// # Errors
    /// As [`Binned::new`]; fewer than two nodes also give [`SpectrumError::Table`].
    pub fn centred_on_nodes(nm: &[f64], values: &[f64]) -> Result<Self, SpectrumError> {
        let n = nm.len();
        if n < 2 || values.len() != n {
            // Binned::new reports the real problem (too few edges, or lengths that differ).
            return Self::new(nm, values);
        }
        let mut edges = Vec::with_capacity(n + 1);
        let first = nm[0] - 0.5 * (nm[1] - nm[0]);
        edges.push(if first > 0.0 { first } else { nm[0] });
        edges.extend(nm.windows(2).map(|w| 0.5 * (w[0] + w[1])));
        edges.push(nm[n - 1] + 0.5 * (nm[n - 1] - nm[n - 2]));
        Self::new(&edges, values)
    }

    /// Builds the spectrum from `n + 1` strictly increasing bin edges (nm) and `n` relative values.
    ///
    /// # Errors
    /// [`SpectrumError::Table`] naming `edges_nm[i]` or `values[i]`; [`SpectrumError::Parameter`]
    /// for a non-positive first edge.
    pub fn new(edges_nm: &[f64], values: &[f64]) -> Result<Self, SpectrumError> {
        let table = PiecewiseConstant::new(edges_nm, values)
            .map_err(|e| SpectrumError::table("Binned", &[("edges", "edges_nm")], e))?;
        if edges_nm[0] <= 0.0 {
            return Err(SpectrumError::parameter(
                "Binned",
                "edges_nm[0]",
                edges_nm[0],
                "wavelengths must be positive",
            ));
        }
        Ok(Self { table })
    }

    /// Bins of equal width `bin_width_nm` starting at `start_nm`.
    ///
    /// # Errors
    /// As [`Binned::new`].
    pub fn uniform(
        start_nm: f64,
        bin_width_nm: f64,
        values: &[f64],
    ) -> Result<Self, SpectrumError> {
        let edges: Vec<f64> =
            (0..=values.len()).map(|i| start_nm + bin_width_nm * i as f64).collect();
        Self::new(&edges, values)
    }

    /// The underlying sampler.
    pub fn sampler(&self) -> &PiecewiseConstant {
        &self.table
    }
}

#[typetag::serde]
impl SpectralPowerDistribution for Binned {
    fn sample_lambda(&self, u: f64) -> f64 {
        self.table.sample(u)
    }
    fn value(&self, lambda: f64) -> f64 {
        self.table.pdf(lambda)
    }
    fn range(&self) -> (f64, f64) {
        self.table.range()
    }
    fn breakpoints(&self) -> Vec<f64> {
        self.table.edges().to_vec()
    }
}
