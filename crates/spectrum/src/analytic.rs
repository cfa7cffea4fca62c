//! Closed-form spectra: [`Uniform`], [`Gaussian`] and [`Monochromatic`].
//!
//! | type | JSON | parameters (default) |
//! |---|---|---|
//! | `Uniform` | `{"type": "Uniform", "min_nm": 400, "max_nm": 700}` | `min_nm` (360), `max_nm` (830) |
//! | `Gaussian` | `{"type": "Gaussian", "center_nm": 532, "fwhm_nm": 0.1}` | `center_nm`, `fwhm_nm` (> 0), `min_nm` (360), `max_nm` (830): truncated to and normalised over `[min_nm, max_nm]` |
//! | `Monochromatic` | `{"type": "Monochromatic", "lambda_nm": 589.3}` | one delta line |

use serde::{Deserialize, Serialize};

use crate::error::{SpectrumError, check_range};
use crate::inverse::{InverseCdf, Shape};
use crate::spd::SpectralPowerDistribution;

/// Default lower end of the analytic spectra's range (nm): where the CIE 1931 tables start.
pub const DEFAULT_MIN_NM: f64 = 360.0;
/// Default upper end of the analytic spectra's range (nm): where the CIE 1931 tables end.
pub const DEFAULT_MAX_NM: f64 = 830.0;

fn default_min() -> f64 {
    DEFAULT_MIN_NM
}
fn default_max() -> f64 {
    DEFAULT_MAX_NM
}

/// The equal-energy spectrum on `[min_nm, max_nm]`: density `1 / (max - min)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "UniformRepr", into = "UniformRepr")]
pub struct Uniform {
    min_nm: f64,
    max_nm: f64,
}

/// Scene-file form of [`Uniform`].
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct UniformRepr {
    #[serde(default = "default_min")]
    min_nm: f64,
    #[serde(default = "default_max")]
    max_nm: f64,
}

impl TryFrom<UniformRepr> for Uniform {
    type Error = SpectrumError;
    fn try_from(r: UniformRepr) -> Result<Self, SpectrumError> {
        Self::new(r.min_nm, r.max_nm)
    }
}

impl From<Uniform> for UniformRepr {
    fn from(u: Uniform) -> Self {
        Self { min_nm: u.min_nm, max_nm: u.max_nm }
    }
}

impl Uniform {
    /// The equal-energy spectrum on `[min_nm, max_nm]`.
    ///
    /// # Errors
    /// [`SpectrumError::Parameter`] unless `0 < min_nm < max_nm < inf`.
    pub fn new(min_nm: f64, max_nm: f64) -> Result<Self, SpectrumError> {
        check_range("Uniform", min_nm, max_nm)?;
        Ok(Self { min_nm, max_nm })
    }

    /// The CIE illuminant E over the CIE 1931 range, 360-830 nm.
    pub fn equal_energy() -> Self {
        Self { min_nm: DEFAULT_MIN_NM, max_nm: DEFAULT_MAX_NM }
    }
}

#[typetag::serde]
impl SpectralPowerDistribution for Uniform {
    fn sample_lambda(&self, u: f64) -> f64 {
        let u = crate::unit(u);
        (self.min_nm + u * (self.max_nm - self.min_nm)).min(self.max_nm)
    }
    fn value(&self, lambda: f64) -> f64 {
        if (self.min_nm..=self.max_nm).contains(&lambda) {
            1.0 / (self.max_nm - self.min_nm)
        } else {
            0.0
        }
    }
    fn range(&self) -> (f64, f64) {
        (self.min_nm, self.max_nm)
    }
}

/// A Gaussian line (laser lines, LEDs) truncated to `[min_nm, max_nm]` and normalised over it;
/// sampled exactly through a tabulated inverse CDF of the truncated standard normal (built by the
/// constructor, see the `inverse` module), stable down to `fwhm_nm = 1e-6` and for centres outside
/// the range (as long as some mass lies inside it).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "GaussianRepr", into = "GaussianRepr")]
pub struct Gaussian {
    center_nm: f64,
    fwhm_nm: f64,
    min_nm: f64,
    max_nm: f64,
    sigma: f64,
    /// Standardised range ends `(min - center) / sigma`, `(max - center) / sigma`.
    a: f64,
    b: f64,
    /// Mass of the standard normal inside `[a, b]`.
    mass: f64,
    /// Inverse CDF of the standard normal truncated to `[a, b]` (never serialised:
    /// deserialisation goes through [`Gaussian::with_range`]).
    sampler: InverseCdf,
}

/// `ln` of the standard normal density, up to a constant.
fn ln_standard_normal(z: f64) -> f64 {
    -0.5 * z * z
}

/// Scene-file form of [`Gaussian`].
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct GaussianRepr {
    center_nm: f64,
    fwhm_nm: f64,
    #[serde(default = "default_min")]
    min_nm: f64,
    #[serde(default = "default_max")]
    max_nm: f64,
}

impl TryFrom<GaussianRepr> for Gaussian {
    type Error = SpectrumError;
    fn try_from(r: GaussianRepr) -> Result<Self, SpectrumError> {
        Self::with_range(r.center_nm, r.fwhm_nm, r.min_nm, r.max_nm)
    }
}

impl From<Gaussian> for GaussianRepr {
    fn from(g: Gaussian) -> Self {
        Self { center_nm: g.center_nm, fwhm_nm: g.fwhm_nm, min_nm: g.min_nm, max_nm: g.max_nm }
    }
}

/// `fwhm = FWHM_PER_SIGMA * sigma` for a Gaussian: `2 sqrt(2 ln 2)`.
const FWHM_PER_SIGMA: f64 = 2.354_820_045_030_949_3;

impl Gaussian {
    /// A Gaussian line over the default range 360-830 nm.
    ///
    /// # Errors
    /// As [`Gaussian::with_range`].
    pub fn new(center_nm: f64, fwhm_nm: f64) -> Result<Self, SpectrumError> {
        Self::with_range(center_nm, fwhm_nm, DEFAULT_MIN_NM, DEFAULT_MAX_NM)
    }

    /// A Gaussian line truncated to `[min_nm, max_nm]`.
    ///
    /// # Errors
    /// [`SpectrumError::Parameter`] for a non-finite centre, a width that is not positive, finite
    /// and normal (a subnormal width is refused naming `fwhm_nm`), a bad range, or a line with no representable mass inside the range.
    pub fn with_range(
        center_nm: f64,
        fwhm_nm: f64,
        min_nm: f64,
        max_nm: f64,
    ) -> Result<Self, SpectrumError> {
        const S: &str = "Gaussian";
        if !center_nm.is_finite() {
            return Err(SpectrumError::parameter(S, "center_nm", center_nm, "must be finite"));
        }
        if !(fwhm_nm > 0.0 && fwhm_nm.is_finite()) {
            return Err(SpectrumError::parameter(
                S,
                "fwhm_nm",
                fwhm_nm,
                "must be positive and finite",
            ));
        }
        let sigma = fwhm_nm / FWHM_PER_SIGMA;
        if !sigma.is_normal() || !(1.0 / sigma).is_finite() {
            return Err(SpectrumError::parameter(
                S,
                "fwhm_nm",
                fwhm_nm,
                "too small: subnormal (below ~1e-307), the line's peak density 1/sigma overflows",
            ));
        }
        check_range(S, min_nm, max_nm)?;
        let (a, b) = ((min_nm - center_nm) / sigma, (max_nm - center_nm) / sigma);
        let mass = normal_mass(a, b);
        if !(mass > 0.0) || !(1.0 / (sigma * mass)).is_finite() {
            return Err(SpectrumError::parameter(
                S,
                "center_nm",
                center_nm,
                "the line has no representable mass inside [min_nm, max_nm]",
            ));
        }
        // The peak of the truncated normal, and its width: 1 inside, the decay length 1 / |z|
        // at a peak on a range end far in the tail.
        let mode = 0.0_f64.clamp(a, b);
        let scale = 1.0 / mode.abs().max(1.0);
        let d_ln_f = |z: f64| -z;
        let shape = Shape {
            ln_f: &ln_standard_normal,
            min: a,
            max: b,
            mode,
            scale,
            extra: &[],
            d_ln_f: Some(&d_ln_f),
        };
        let sampler = InverseCdf::new(&shape).ok_or(SpectrumError::parameter(
            S,
            "center_nm",
            center_nm,
            "the line has no representable mass inside [min_nm, max_nm]",
        ))?;
        Ok(Self { center_nm, fwhm_nm, min_nm, max_nm, sigma, a, b, mass, sampler })
    }

    /// Centre wavelength (nm).
    pub fn center_nm(&self) -> f64 {
        self.center_nm
    }

    /// Full width at half maximum (nm).
    pub fn fwhm_nm(&self) -> f64 {
        self.fwhm_nm
    }
}

#[typetag::serde]
impl SpectralPowerDistribution for Gaussian {
    fn sample_lambda(&self, u: f64) -> f64 {
        let z = self.sampler.sample(&ln_standard_normal, u);
        (self.center_nm + self.sigma * z.clamp(self.a, self.b)).clamp(self.min_nm, self.max_nm)
    }
    fn value(&self, lambda: f64) -> f64 {
        if !(self.min_nm..=self.max_nm).contains(&lambda) {
            return 0.0;
        }
        let z = (lambda - self.center_nm) / self.sigma;
        (-0.5 * z * z).exp() / (self.sigma * std::f64::consts::TAU.sqrt() * self.mass)
    }
    fn range(&self) -> (f64, f64) {
        (self.min_nm, self.max_nm)
    }
    fn breakpoints(&self) -> Vec<f64> {
        // Panels of sigma / 4 over +-10 sigma resolve any width, down to 1e-6 nm: 4-point
        // Gauss-Legendre is then accurate to ~1e-11 on the line (beyond 10 sigma lies 1.5e-23).
        (-40..=40).map(|k| self.center_nm + self.sigma * 0.25 * k as f64).collect()
    }
}

/// `P(Z < x)` for a standard normal, accurate in the lower tail.
fn lower_tail(x: f64) -> f64 {
    0.5 * libm::erfc(-x / std::f64::consts::SQRT_2)
}

/// `P(Z > x)`, accurate in the upper tail.
fn upper_tail(x: f64) -> f64 {
    0.5 * libm::erfc(x / std::f64::consts::SQRT_2)
}

/// Mass of the standard normal in `[a, b]`, computed in whichever tail avoids cancellation.
fn normal_mass(a: f64, b: f64) -> f64 {
    if a >= 0.0 {
        upper_tail(a) - upper_tail(b)
    } else if b <= 0.0 {
        lower_tail(b) - lower_tail(a)
    } else {
        1.0 - lower_tail(a) - upper_tail(b)
    }
}

/// A delta line at `lambda_nm`: all power at one wavelength.
///
/// A delta has no density, so [`SpectralPowerDistribution::value`] is 0 everywhere (also at
/// `lambda_nm`) and [`SpectralPowerDistribution::is_delta`] is `true`;
/// [`SpectralPowerDistribution::integrate`] returns `f(lambda_nm)`, so `xyz_of` and mixtures
/// handle it exactly. `sample_lambda` always returns `lambda_nm` and `range` is
/// `(lambda_nm, lambda_nm)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "MonochromaticRepr", into = "MonochromaticRepr")]
pub struct Monochromatic {
    lambda_nm: f64,
}

/// Scene-file form of [`Monochromatic`].
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct MonochromaticRepr {
    lambda_nm: f64,
}

impl TryFrom<MonochromaticRepr> for Monochromatic {
    type Error = SpectrumError;
    fn try_from(r: MonochromaticRepr) -> Result<Self, SpectrumError> {
        Self::new(r.lambda_nm)
    }
}

impl From<Monochromatic> for MonochromaticRepr {
    fn from(m: Monochromatic) -> Self {
        Self { lambda_nm: m.lambda_nm }
    }
}

impl Monochromatic {
    /// A delta line at `lambda_nm`.
    ///
    /// # Errors
    /// [`SpectrumError::Parameter`] unless `lambda_nm` is positive and finite.
    pub fn new(lambda_nm: f64) -> Result<Self, SpectrumError> {
        if !(lambda_nm > 0.0 && lambda_nm.is_finite()) {
            return Err(SpectrumError::parameter(
                "Monochromatic",
                "lambda_nm",
                lambda_nm,
                "must be positive and finite",
            ));
        }
        Ok(Self { lambda_nm })
    }

    /// The line's wavelength (nm).
    pub fn lambda_nm(&self) -> f64 {
        self.lambda_nm
    }
}

#[typetag::serde]
impl SpectralPowerDistribution for Monochromatic {
    fn sample_lambda(&self, _u: f64) -> f64 {
        self.lambda_nm
    }
    fn value(&self, _lambda: f64) -> f64 {
        0.0
    }
    fn range(&self) -> (f64, f64) {
        (self.lambda_nm, self.lambda_nm)
    }
    fn integrate(&self, f: &dyn Fn(f64) -> f64) -> f64 {
        f(self.lambda_nm)
    }
    fn is_delta(&self) -> bool {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_mass_is_accurate_in_both_tails() {
        assert!((normal_mass(-1.0, 1.0) - 0.682_689_492_137_085_9).abs() < 1e-15);
        // Far upper tail: P(10 < Z < 11) = Q(10) - Q(11).
        let m = normal_mass(10.0, 11.0);
        assert!(
            (m / (7.619_853_024_160_527e-24 - 1.910_659_574_027_8e-28) - 1.0).abs() < 1e-10,
            "{m}"
        );
    }
}
