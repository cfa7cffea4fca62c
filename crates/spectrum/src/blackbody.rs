//! [`Blackbody`]: Planck's law at a temperature, normalised over a wavelength range, sampled
//! exactly through the tabulated inverse CDF of [`crate::inverse`].
//!
//! | type | JSON | parameters (default) |
//! |---|---|---|
//! | `Blackbody` | `{"type": "Blackbody", "kelvin": 6500}` | `kelvin` (> 0), `min_nm` (360), `max_nm` (830) |
//!
//! Planck's law is evaluated in log space with `expm1`, so it neither overflows at 100 K (where
//! `exp(hc / lambda k T)` exceeds 1e170) nor loses precision at 10^6 K (where the exponent is
//! tiny); any positive finite temperature gives a finite, normalised spectrum.

use serde::{Deserialize, Serialize};

use crate::analytic::{DEFAULT_MAX_NM, DEFAULT_MIN_NM};
use crate::error::{SpectrumError, check_range};
use crate::inverse::{InverseCdf, Shape};
use crate::spd::SpectralPowerDistribution;

/// Second radiation constant `c2 = h c / k_B` in nm K (CODATA 2018: 1.438776877e-2 m K).
pub const PLANCK_C2_NM_K: f64 = 1.438_776_877e7;

/// `d/d lambda` of [`ln_planck`]: `(x / (1 - e^-x) - 5) / lambda` with `x = c2 / (lambda T)`.
fn d_ln_planck(lambda_nm: f64, kelvin: f64, c2: f64) -> f64 {
    let x = c2 / (lambda_nm * kelvin);
    // x / (1 - e^-x) -> 1 as x -> 0 (the Rayleigh-Jeans limit); -expm1(-x) keeps it accurate.
    let ratio = if x > 0.0 { x / -(-x).exp_m1() } else { 1.0 };
    (ratio - 5.0) / lambda_nm
}

/// The root of `x = 5 (1 - e^-x)`: Planck's law in wavelength peaks at `c2 / (WIEN_X T)`.
const WIEN_X: f64 = 4.965_114_231_744_276;

/// Below this `x = c2 / (lambda T)`, `expm1(x) < 10^261` is finite and `value` may evaluate
/// Planck's law directly.
const DIRECT_X_MAX: f64 = 600.0;

/// `ln` of Planck's spectral radiance up to a constant: `-5 ln(lambda) - ln(expm1(c2 / (lambda T)))`.
fn ln_planck(lambda_nm: f64, kelvin: f64, c2: f64) -> f64 {
    let x = c2 / (lambda_nm * kelvin);
    // ln(expm1(x)) = x + ln(1 - e^-x) for large x (no overflow); ln(expm1(x)) directly otherwise.
    let ln_em1 = if x > 30.0 { x + (-(-x).exp()).ln_1p() } else { x.exp_m1().ln() };
    -5.0 * lambda_nm.ln() - ln_em1
}

/// Planck's blackbody spectrum at `kelvin`, normalised over `[min_nm, max_nm]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "BlackbodyRepr", into = "BlackbodyRepr")]
pub struct Blackbody {
    kelvin: f64,
    min_nm: f64,
    max_nm: f64,
    /// `c2` in nm K: Planck's constant for a physical blackbody, 1.435e7 for CIE illuminant A.
    c2: f64,
    /// The inverse CDF, built by the constructor (never serialised: deserialisation goes through
    /// [`Blackbody::with_range`]).
    sampler: InverseCdf,
    /// The normalising factor `1 / integral of lambda^-5 / expm1(c2 / (lambda T))` when it is a
    /// normal number (then `value` is Planck's law evaluated directly); 0 otherwise (extreme
    /// temperatures, whose values go through logarithms).
    direct_scale: f64,
}

/// Scene-file form of [`Blackbody`].
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct BlackbodyRepr {
    kelvin: f64,
    #[serde(default = "default_min")]
    min_nm: f64,
    #[serde(default = "default_max")]
    max_nm: f64,
}

fn default_min() -> f64 {
    DEFAULT_MIN_NM
}
fn default_max() -> f64 {
    DEFAULT_MAX_NM
}

impl TryFrom<BlackbodyRepr> for Blackbody {
    type Error = SpectrumError;
    fn try_from(r: BlackbodyRepr) -> Result<Self, SpectrumError> {
        Self::with_range(r.kelvin, r.min_nm, r.max_nm)
    }
}

impl From<Blackbody> for BlackbodyRepr {
    fn from(b: Blackbody) -> Self {
        Self { kelvin: b.kelvin, min_nm: b.min_nm, max_nm: b.max_nm }
    }
}

impl Blackbody {
    /// A blackbody at `kelvin` over the default range 360-830 nm.
    ///
    /// # Errors
    /// As [`Blackbody::with_range`].
    pub fn new(kelvin: f64) -> Result<Self, SpectrumError> {
        Self::with_range(kelvin, DEFAULT_MIN_NM, DEFAULT_MAX_NM)
    }

    /// A blackbody at `kelvin` normalised over `[min_nm, max_nm]`.
    ///
    /// # Errors
    /// [`SpectrumError::Parameter`] for a temperature that is not positive and finite, or a bad
    /// range.
    pub fn with_range(kelvin: f64, min_nm: f64, max_nm: f64) -> Result<Self, SpectrumError> {
        Self::with_c2("Blackbody", kelvin, min_nm, max_nm, PLANCK_C2_NM_K)
    }

    /// A Planckian shape with a given second radiation constant (CIE illuminant A uses the
    /// historical 1.435e7 nm K).
    pub(crate) fn with_c2(
        spectrum: &'static str,
        kelvin: f64,
        min_nm: f64,
        max_nm: f64,
        c2: f64,
    ) -> Result<Self, SpectrumError> {
        if !(kelvin > 0.0 && kelvin.is_finite()) {
            return Err(SpectrumError::parameter(
                spectrum,
                "kelvin",
                kelvin,
                "must be positive and finite",
            ));
        }
        check_range(spectrum, min_nm, max_nm)?;
        let ln_f = |l: f64| ln_planck(l, kelvin, c2);
        // Planck's law peaks where x = c2 / (lambda T) solves x = 5 (1 - e^-x) (Wien).
        let mode = (c2 / (WIEN_X * kelvin)).clamp(min_nm, max_nm);
        // |d ln f / d lambda| <= 5 / lambda + c2 / (lambda^2 T): its inverse is the shortest
        // length over which the density can change by a factor e near the mode.
        let scale = 1.0 / (5.0 / mode + c2 / (mode * mode * kelvin));
        let d_ln_f = |l: f64| d_ln_planck(l, kelvin, c2);
        let shape = Shape {
            ln_f: &ln_f,
            min: min_nm,
            max: max_nm,
            mode,
            scale,
            extra: &[],
            d_ln_f: Some(&d_ln_f),
        };
        let sampler = InverseCdf::new(&shape).ok_or(SpectrumError::parameter(
            spectrum,
            "kelvin",
            kelvin,
            "the spectrum cannot be normalised over the range",
        ))?;
        let direct_scale = sampler.density(0.0);
        let direct_scale = if direct_scale.is_normal() { direct_scale } else { 0.0 };
        Ok(Self { kelvin, min_nm, max_nm, c2, sampler, direct_scale })
    }

    /// The temperature (K).
    pub fn kelvin(&self) -> f64 {
        self.kelvin
    }
}

#[typetag::serde]
impl SpectralPowerDistribution for Blackbody {
    fn sample_lambda(&self, u: f64) -> f64 {
        let (kelvin, c2) = (self.kelvin, self.c2);
        self.sampler.sample(&|l| ln_planck(l, kelvin, c2), u)
    }
    fn value(&self, lambda: f64) -> f64 {
        if !(self.min_nm..=self.max_nm).contains(&lambda) {
            return 0.0;
        }
        // Planck's law directly, one exponential (a quarter of the log form's transcendental
        // calls, and a few ulps instead of an error that grows with |ln f|), wherever its
        // product neither overflows nor underflows; the log form elsewhere (extreme
        // temperatures and ranges).
        let x = self.c2 / (lambda * self.kelvin);
        if x < DIRECT_X_MAX && self.direct_scale > 0.0 {
            // Above x = 1, `exp(x) - 1` loses at most a bit (e^x > 2.7 leaves no cancellation)
            // and `exp` costs a third of `expm1`.
            let em1 = if x > 1.0 { x.exp() - 1.0 } else { x.exp_m1() };
            let l2 = lambda * lambda;
            let denominator = l2 * l2 * lambda * em1;
            let value = self.direct_scale / denominator;
            if denominator.is_normal() && value.is_finite() {
                return value;
            }
        }
        self.sampler.density(ln_planck(lambda, self.kelvin, self.c2))
    }
    fn range(&self) -> (f64, f64) {
        (self.min_nm, self.max_nm)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ln_planck_matches_the_direct_formula_where_that_is_safe() {
        for (l, t) in [(500.0, 5000.0), (360.0, 1000.0), (830.0, 1e6)] {
            let x: f64 = PLANCK_C2_NM_K / (l * t);
            let direct = -5.0 * f64::ln(l) - (x.exp() - 1.0).ln();
            assert!((ln_planck(l, t, PLANCK_C2_NM_K) - direct).abs() < 1e-12);
        }
        // 100 K: exp(c2 / (360 nm * 100 K)) = exp(399.7) overflows nothing in log space.
        assert!(ln_planck(360.0, 100.0, PLANCK_C2_NM_K).is_finite());
        assert!(ln_planck(360.0, 1.0, PLANCK_C2_NM_K).is_finite());
    }

    #[test]
    fn the_direct_value_is_the_log_form_to_a_few_ulps_and_extremes_stay_finite() {
        // The log form's own error is about |ln f| ulps (|ln f| < 800 here), so 1e-12 relative
        // holds for it and the direct product alike, and a wrong exponent or factor would not.
        let mut direct = 0;
        for kelvin in [1.0, 30.0, 300.0, 1000.0, 2856.0, 6500.0, 1e5, 1e8, 1e12] {
            let b = Blackbody::new(kelvin).unwrap();
            for k in 0..=94 {
                let lambda = DEFAULT_MIN_NM + 5.0 * f64::from(k);
                let v = b.value(lambda);
                let logs = b.sampler.density(ln_planck(lambda, kelvin, b.c2));
                assert!(v.is_finite() && v >= 0.0, "{kelvin} K, {lambda} nm: {v}");
                let x = b.c2 / (lambda * kelvin);
                if x < DIRECT_X_MAX && b.direct_scale > 0.0 {
                    direct += 1;
                    let error = (v - logs).abs() / logs;
                    assert!(error < 1e-12, "{kelvin} K, {lambda} nm: {v} vs {logs}");
                } else {
                    assert_eq!(v, logs, "{kelvin} K, {lambda} nm: the log form");
                }
            }
        }
        // Both branches ran: all but the coldest bodies are direct.
        assert!(direct > 6 * 95 && direct < 9 * 95, "{direct}");
    }

    #[test]
    fn extreme_ranges_whose_direct_product_would_overflow_use_the_log_form() {
        // At 1e70 nm lambda^5 overflows while a 1e9 K body keeps x small: the direct product
        // would give 0 where the density is about 7e-71; the guard sends it to the log form.
        // The others: a range whose normalising factor is not a normal number (log form
        // throughout), and a cold body over a huge range (both branches).
        for (kelvin, min_nm, max_nm) in [(1e9, 1e70, 2e70), (1e300, 1e-70, 2e-70), (1.0, 1e-3, 1e6)]
        {
            let b = Blackbody::with_range(kelvin, min_nm, max_nm).unwrap();
            for k in 0..=100 {
                let lambda = min_nm + (max_nm - min_nm) * f64::from(k) / 100.0;
                let v = b.value(lambda);
                let logs = b.sampler.density(ln_planck(lambda, kelvin, b.c2));
                assert!(v.is_finite() && v >= 0.0, "{kelvin} K, {lambda} nm: {v}");
                assert!(
                    (v - logs).abs() <= 1e-12 * logs,
                    "{kelvin} K, {lambda} nm: {v} vs the log form's {logs}"
                );
            }
        }
        assert!(Blackbody::with_range(1e9, 1e70, 2e70).unwrap().value(1.5e70) > 0.0);
    }
}
