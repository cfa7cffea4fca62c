//! [`Mixture`]: a weighted sum of spectra (a lamp with a phosphor continuum and lines, an LED with
//! two emitters, ...).
//!
//! | type | JSON |
//! |---|---|
//! | `Mixture` | `{"type": "Mixture", "components": [{"weight": 0.7, "spd": {"type": "Blackbody", "kelvin": 3000}}, {"weight": 0.3, "spd": {"type": "Monochromatic", "lambda_nm": 546.1}}]}` |
//!
//! `weight` is the fraction of the power in each component (relative: they need not sum to 1).
//! Each component is itself normalised, so the mixture's density is `sum(w_i value_i) / sum(w_i)`.

use std::sync::Arc;

use serde::{Deserialize, Serialize};
use spectrace_sampling::Discrete;

use crate::error::SpectrumError;
use crate::inverse::{InverseCdf, Shape};
use crate::spd::SpectralPowerDistribution;

/// One component of a [`Mixture`]: a relative power weight and a spectrum.
#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Component {
    /// Relative share of the power (non-negative).
    pub weight: f64,
    /// The component's spectrum (shared: a light set builds its mixture from its lights' SPDs).
    pub spd: Arc<dyn SpectralPowerDistribution>,
}

/// A weighted sum of spectra.
///
/// Components that share one spectrum object are merged, their weights added.
///
/// Without delta lines it is sampled by its own exact inverse CDF, tabulated by the constructor
/// (see the `inverse` module; monotone in `u`, one table lookup per sample). With a delta line,
/// with more than [`MAX_TABLE_COMPONENTS`] components, or
/// when that table would exceed [`MAX_TABLE_PANELS`] panels (components with hundreds of kinks),
/// it chooses a component in proportion to its weight and samples it with the same uniform,
/// remapped (exact in distribution, but not monotone in `u`); so it does too if some panel of the
/// table could not be interpolated to the tolerance.
#[derive(Debug, Deserialize)]
#[serde(try_from = "MixtureRepr")]
pub struct Mixture {
    components: Vec<Component>,
    choice: Discrete,
    range: (f64, f64),
    /// The mixture's inverse CDF (never serialised: deserialisation goes through
    /// [`Mixture::new`]); `None` when sampling by component.
    inverse: Option<InverseCdf>,
}

/// Largest inverse-CDF table a mixture builds (about 60 bytes a panel); beyond it the mixture
/// samples by component.
pub const MAX_TABLE_PANELS: usize = 512;

/// Most components a mixture builds its inverse-CDF table for: the table evaluates the whole
/// mixture at every component's kinks, a cost that grows as the square of the components, so a
/// mixture of more (the spectrum of a light set of many different lamps) samples by component.
pub const MAX_TABLE_COMPONENTS: usize = 64;

/// The components with those that share one spectrum object (`Arc` identity) merged into the
/// first of them, their weights added: a light set of thousands of lamps of one spectrum is a
/// mixture of one component.
fn merge_shared(components: Vec<Component>) -> Vec<Component> {
    let mut index: std::collections::HashMap<*const (), usize> = std::collections::HashMap::new();
    let mut merged: Vec<Component> = Vec::with_capacity(components.len().min(1024));
    for c in components {
        let key = Arc::as_ptr(&c.spd) as *const ();
        match index.get(&key) {
            Some(&k) => merged[k].weight += c.weight,
            None => {
                index.insert(key, merged.len());
                merged.push(c);
            }
        }
    }
    merged
}

/// Scene-file form of [`Mixture`].
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MixtureRepr {
    components: Vec<Component>,
}

impl TryFrom<MixtureRepr> for Mixture {
    type Error = SpectrumError;
    fn try_from(r: MixtureRepr) -> Result<Self, SpectrumError> {
        Self::new(r.components)
    }
}

impl Serialize for Mixture {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        let mut s = serializer.serialize_struct("Mixture", 1)?;
        s.serialize_field("components", &self.components)?;
        s.end()
    }
}

impl Mixture {
    /// Builds the mixture.
    ///
    /// # Errors
    /// [`SpectrumError::EmptyMixture`] without components; [`SpectrumError::Table`] naming
    /// `weight[i]` for a NaN, infinite or negative weight, or when all weights are zero.
    pub fn new(components: Vec<Component>) -> Result<Self, SpectrumError> {
        if components.is_empty() {
            return Err(SpectrumError::EmptyMixture);
        }
        let weights: Vec<f64> = components.iter().map(|c| c.weight).collect();
        let choice = Discrete::new(&weights)
            .map_err(|e| SpectrumError::table("Mixture", &[("weights", "components.weight")], e))?;
        // Merged only once every weight is known to be valid.
        let (components, choice) = if components.len() > 1 {
            let merged = merge_shared(components);
            let weights: Vec<f64> = merged.iter().map(|c| c.weight).collect();
            let choice = Discrete::new(&weights).map_err(|e| {
                SpectrumError::table("Mixture", &[("weights", "components.weight")], e)
            })?;
            (merged, choice)
        } else {
            (components, choice)
        };
        let range = components
            .iter()
            .zip(&weights)
            .filter(|(_, w)| **w > 0.0)
            .map(|(c, _)| c.spd.range())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), (lo, hi)| (a.min(lo), b.max(hi)));
        let mut mixture = Self { components, choice, range, inverse: None };
        mixture.inverse = mixture.build_inverse();
        Ok(mixture)
    }

    /// The mixture's inverse-CDF table, if it has no delta line, at most
    /// [`MAX_TABLE_COMPONENTS`] components and the table stays small.
    fn build_inverse(&self) -> Option<InverseCdf> {
        let (min, max) = self.range;
        let active =
            || self.components.iter().enumerate().filter(|(i, _)| self.choice.pmf(*i) > 0.0);
        if !(min < max)
            || active().count() > MAX_TABLE_COMPONENTS
            || active().any(|(_, c)| c.spd.is_delta())
        {
            return None;
        }
        // Panel edges at every component's kinks and range ends; the mode at the highest of
        // those and of a coarse grid.
        let mut extra = self.breakpoints();
        for (_, c) in active() {
            let (lo, hi) = c.spd.range();
            extra.extend([lo, hi]);
        }
        let ln_f = |l: f64| self.value(l).ln();
        let grid = (0..=64).map(|k| min + (max - min) * k as f64 / 64.0);
        let mode = grid
            .chain(extra.iter().copied())
            .filter(|x| (min..=max).contains(x))
            .max_by(|a, b| self.value(*a).total_cmp(&self.value(*b)))
            .unwrap_or(min);
        let shape = Shape {
            ln_f: &ln_f,
            min,
            max,
            mode,
            scale: (max - min) / 64.0,
            extra: &extra,
            d_ln_f: None,
        };
        InverseCdf::new(&shape).filter(|t| t.len() <= MAX_TABLE_PANELS && t.is_interpolated())
    }

    /// `true` if the mixture samples through its own inverse CDF (monotone in `u`), `false` if
    /// it samples by component (it has a delta line, or too many kinks for a small table).
    pub fn has_inverse_cdf(&self) -> bool {
        self.inverse.is_some()
    }

    /// The components.
    pub fn components(&self) -> &[Component] {
        &self.components
    }
}

#[typetag::serde]
impl SpectralPowerDistribution for Mixture {
    fn sample_lambda(&self, u: f64) -> f64 {
        if let Some(inverse) = &self.inverse {
            return inverse.sample(&|l| self.value(l).ln(), u);
        }
        let (i, v) = self.choice.sample_remapped(spectrace_sampling::clamp_uniform(u));
        self.components[i].spd.sample_lambda(v)
    }
    fn value(&self, lambda: f64) -> f64 {
        self.components
            .iter()
            .enumerate()
            .map(|(i, c)| self.choice.pmf(i) * c.spd.value(lambda))
            .sum()
    }
    fn range(&self) -> (f64, f64) {
        self.range
    }
    fn integrate(&self, f: &dyn Fn(f64) -> f64) -> f64 {
        self.components
            .iter()
            .enumerate()
            .filter(|(i, _)| self.choice.pmf(*i) > 0.0)
            .map(|(i, c)| self.choice.pmf(i) * c.spd.integrate(f))
            .sum()
    }
    fn breakpoints(&self) -> Vec<f64> {
        self.components.iter().flat_map(|c| c.spd.breakpoints()).collect()
    }
    fn is_delta(&self) -> bool {
        self.components
            .iter()
            .enumerate()
            .all(|(i, c)| self.choice.pmf(i) == 0.0 || c.spd.is_delta())
    }
    fn piecewise_constant(&self) -> Option<Box<dyn SpectralPowerDistribution>> {
        // Every tabulated component re-binned, the others kept; `None` if none is tabulated.
        let mut any = false;
        let components = self
            .components
            .iter()
            .map(|c| Component {
                weight: c.weight,
                spd: match c.spd.piecewise_constant() {
                    Some(binned) => {
                        any = true;
                        Arc::from(binned)
                    }
                    None => c.spd.clone(),
                },
            })
            .collect();
        if !any {
            return None;
        }
        Mixture::new(components).ok().map(|m| Box::new(m) as _)
    }
}
