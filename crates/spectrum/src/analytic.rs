//! Closed-form spectra: [`Uniform`], [`Gaussian`] and [`Monochromatic`].
//!
//! | type | JSON | parameters (default) |
//! |---|---|---|
//! | `Uniform` | `{"type": "Uniform", "min_nm": 400, "max_nm": 700}` | `min_nm` (360), `max_nm` (830) |
//! | `Gaussian` | `{"type": "Gaussian", "center_nm": 532, "fwhm_nm": 0.1}` | `center_nm`, `fwhm_nm` (> 0), `min_nm` (360), `max_nm` (830): truncated to and normalised over `[min_nm, max_nm]` |
//! | `Monochromatic` | `{"type": "Monochromatic", "lambda_nm": 589.3}` | one delta line |

use serde::{Deserialize, Serialize};

use crate::error::{SpectrumError, check_range};
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
/// sampled exactly through the inverse normal CDF, stable down to `fwhm_nm = 1e-6` and for
/// centres outside the range (as long as some mass lies inside it).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
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
        Ok(Self { center_nm, fwhm_nm, min_nm, max_nm, sigma, a, b, mass })
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
        let u = crate::unit(u);
        // Work in the tail that keeps precision: for the lower half of the mass measure from
        // the lower end, for the upper half from the upper end.
        let z = if u < 0.5 {
            let p = lower_tail(self.a) + u * self.mass;
            normal_quantile(p.max(f64::MIN_POSITIVE))
        } else {
            let q = upper_tail(self.b) + (1.0 - u) * self.mass;
            -normal_quantile(q.max(f64::MIN_POSITIVE))
        };
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

/// The standard normal quantile `z` with `P(Z < z) = p`, for `p` in `(0, 1)`: Acklam's rational
/// approximation (relative error 1.2e-9) refined by one Halley step on `erfc`, which brings it to
/// full double precision.
pub(crate) fn normal_quantile(p: f64) -> f64 {
    const A: [f64; 6] = [
        -3.969_683_028_665_376e1,
        2.209_460_984_245_205e2,
        -2.759_285_104_469_687e2,
        1.383_577_518_672_69e2,
        -3.066_479_806_614_716e1,
        2.506_628_277_459_239,
    ];
    const B: [f64; 5] = [
        -5.447_609_879_822_406e1,
        1.615_858_368_580_409e2,
        -1.556_989_798_598_866e2,
        6.680_131_188_771_972e1,
        -1.328_068_155_288_572e1,
    ];
    const C: [f64; 6] = [
        -7.784_894_002_430_293e-3,
        -3.223_964_580_411_365e-1,
        -2.400_758_277_161_838,
        -2.549_732_539_343_734,
        4.374_664_141_464_968,
        2.938_163_982_698_783,
    ];
    const D: [f64; 4] = [
        7.784_695_709_041_462e-3,
        3.224_671_290_700_398e-1,
        2.445_134_137_142_996,
        3.754_408_661_907_416,
    ];
    const P_LOW: f64 = 0.024_25;
    if !(p > 0.0) {
        return f64::NEG_INFINITY;
    }
    if !(p < 1.0) {
        return f64::INFINITY;
    }
    let x = if p < P_LOW {
        let q = (-2.0 * p.ln()).sqrt();
        (((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    } else if p <= 1.0 - P_LOW {
        let q = p - 0.5;
        let r = q * q;
        (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
            / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
    } else {
        let q = (-2.0 * (1.0 - p).ln()).sqrt();
        -(((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    };
    // One Halley step on f(x) = Phi(x) - p, with Phi from erfc (accurate in the lower tail; for
    // the upper tail measure the error from 1 - p instead).
    let e = if x <= 0.0 { lower_tail(x) - p } else { (1.0 - p) - upper_tail(x) };
    let density = (-0.5 * x * x).exp() / std::f64::consts::TAU.sqrt();
    if density > 0.0 && e.is_finite() {
        let u = e / density;
        x - u / (1.0 + 0.5 * x * u)
    } else {
        x
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
    fn normal_quantile_inverts_the_cdf_to_full_precision() {
        for p in [1e-300, 1e-20, 1e-5, 0.01, 0.2, 0.5, 0.7, 0.975, 0.999_999] {
            let z = normal_quantile(p);
            let back = lower_tail(z);
            assert!(((back - p) / p).abs() < 1e-13, "p = {p}: z = {z}, Phi(z) = {back}");
        }
        assert!((normal_quantile(0.975) - 1.959_963_984_540_054).abs() < 1e-14);
        assert_eq!(normal_quantile(0.5), 0.0);
    }

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
