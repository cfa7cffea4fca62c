//! CIE 1931 colorimetry: the 2-degree colour matching functions, XYZ of a spectrum (by
//! integration, or estimated from sampled wavelengths), chromaticity, and XYZ -> sRGB.

use std::ops::{Add, AddAssign, Mul};
use std::sync::LazyLock;

use serde::{Deserialize, Serialize};

use crate::SpectralPowerDistribution;
use crate::data::cie1931::{CIE_1931_2DEG, CMF_END_NM, CMF_LEN, CMF_START_NM};

/// CIE 1931 tristimulus values.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Xyz {
    /// X.
    pub x: f64,
    /// Y (luminance-like).
    pub y: f64,
    /// Z.
    pub z: f64,
}

impl Xyz {
    /// Builds a tristimulus triple.
    pub const fn new(x: f64, y: f64, z: f64) -> Self {
        Self { x, y, z }
    }

    /// Chromaticity coordinates `(x, y) = (X, Y) / (X + Y + Z)`; `None` when the sum is zero.
    pub fn chromaticity(self) -> Option<(f64, f64)> {
        let s = self.x + self.y + self.z;
        (s != 0.0 && s.is_finite()).then(|| (self.x / s, self.y / s))
    }

    /// Linear sRGB (Rec. 709 primaries, D65 white): `XYZ` of the D65 white with `Y = 1` maps to
    /// `(1, 1, 1)`. Out-of-gamut colours give negative components (not clamped).
    pub fn to_linear_srgb(self) -> [f64; 3] {
        let m = &*XYZ_TO_SRGB;
        [0, 1, 2].map(|r| m[r][0] * self.x + m[r][1] * self.y + m[r][2] * self.z)
    }

    /// `true` if every component is finite.
    pub fn is_finite(self) -> bool {
        self.x.is_finite() && self.y.is_finite() && self.z.is_finite()
    }
}

impl Add for Xyz {
    type Output = Xyz;
    fn add(self, o: Xyz) -> Xyz {
        Xyz::new(self.x + o.x, self.y + o.y, self.z + o.z)
    }
}

impl AddAssign for Xyz {
    fn add_assign(&mut self, o: Xyz) {
        *self = *self + o;
    }
}

impl Mul<f64> for Xyz {
    type Output = Xyz;
    fn mul(self, k: f64) -> Xyz {
        Xyz::new(self.x * k, self.y * k, self.z * k)
    }
}

/// The CIE 1931 2-degree colour matching functions `(xbar, ybar, zbar)` at `lambda` (nm), linearly
/// interpolated in the official 1 nm table (360-830 nm); zero outside it and for NaN.
#[inline]
pub fn cmf(lambda: f64) -> Xyz {
    if !(CMF_START_NM..=CMF_END_NM).contains(&lambda) {
        return Xyz::default();
    }
    let p = lambda - CMF_START_NM;
    let i = spectrace_sampling::cell_index(p, CMF_LEN - 2);
    let t = p - i as f64;
    let (a, b) = (CIE_1931_2DEG[i], CIE_1931_2DEG[i + 1]);
    Xyz::new(a[0] * (1.0 - t) + b[0] * t, a[1] * (1.0 - t) + b[1] * t, a[2] * (1.0 - t) + b[2] * t)
}

/// `integral of ybar(lambda) d lambda` over 360-830 nm (nm), exact for the linearly interpolated
/// table (the trapezoid rule on it): about 106.857. Film convention: a constant spectral radiance
/// `L` gives `Y = L` after dividing by this.
pub static CIE_Y_INTEGRAL: LazyLock<f64> = LazyLock::new(|| {
    let inner: f64 = CIE_1931_2DEG[1..CMF_LEN - 1].iter().map(|r| r[1]).sum();
    inner + (CIE_1931_2DEG[0][1] + CIE_1931_2DEG[CMF_LEN - 1][1]) / 2.0
});

/// XYZ of a spectrum: `integral of value(lambda) * cmf(lambda) d lambda`, delta lines included.
/// For a normalised SPD this is the XYZ per watt (unnormalised by the Y integral).
pub fn xyz_of(spd: &dyn SpectralPowerDistribution) -> Xyz {
    Xyz::new(
        spd.integrate(&|l| cmf(l).x),
        spd.integrate(&|l| cmf(l).y),
        spd.integrate(&|l| cmf(l).z),
    )
}

/// Estimates XYZ from sampled wavelengths: each sample adds `cmf(lambda) * weight`, where
/// `weight` is the spectral quantity at `lambda` divided by the density `lambda` was drawn with;
/// [`XyzEstimator::mean`] is then an unbiased estimate of `integral of quantity * cmf`.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct XyzEstimator {
    sum: Xyz,
    sum_sq: Xyz,
    count: u64,
    rejected: u64,
}

impl XyzEstimator {
    /// An empty estimator.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds one sample: wavelength (nm) and weight (quantity / pdf). A sample whose contribution
    /// is not finite counts as a sample contributing zero and is tallied in
    /// [`XyzEstimator::rejected`], so one bad sample cannot turn the estimate into NaN.
    pub fn add(&mut self, lambda: f64, weight: f64) {
        self.count += 1;
        let c = cmf(lambda) * weight;
        if c.is_finite() {
            self.sum += c;
            self.sum_sq += Xyz::new(c.x * c.x, c.y * c.y, c.z * c.z);
        } else {
            self.rejected += 1;
        }
    }

    /// Number of samples added.
    pub fn count(&self) -> u64 {
        self.count
    }

    /// The estimate (zero before any sample).
    pub fn mean(&self) -> Xyz {
        if self.count == 0 { Xyz::default() } else { self.sum * (1.0 / self.count as f64) }
    }

    /// Standard error of the mean, per component.
    pub fn standard_error(&self) -> Xyz {
        if self.count < 2 {
            return Xyz::new(f64::INFINITY, f64::INFINITY, f64::INFINITY);
        }
        let n = self.count as f64;
        let m = self.mean();
        let var = |s2: f64, mu: f64| ((s2 / n - mu * mu).max(0.0) / (n - 1.0)).sqrt();
        Xyz::new(var(self.sum_sq.x, m.x), var(self.sum_sq.y, m.y), var(self.sum_sq.z, m.z))
    }

    /// Samples whose contribution was not finite (counted as zero in the estimate).
    pub fn rejected(&self) -> u64 {
        self.rejected
    }
}

/// The sRGB (IEC 61966-2-1) primaries and white: R, G, B and D65 chromaticities.
pub const SRGB_PRIMARIES: [(f64, f64); 3] = [(0.64, 0.33), (0.30, 0.60), (0.15, 0.06)];
/// The D65 white point chromaticity used by sRGB.
pub const SRGB_WHITE: (f64, f64) = (0.3127, 0.3290);

/// XYZ -> linear sRGB matrix, derived from [`SRGB_PRIMARIES`] and [`SRGB_WHITE`] (so the white
/// maps to exactly `(1, 1, 1)`), rows R, G, B.
pub static XYZ_TO_SRGB: LazyLock<[[f64; 3]; 3]> = LazyLock::new(|| invert3(&srgb_to_xyz_matrix()));

/// Linear sRGB -> XYZ matrix (columns are the primaries scaled so that white has `Y = 1`).
pub fn srgb_to_xyz_matrix() -> [[f64; 3]; 3] {
    let col = |(x, y): (f64, f64)| [x / y, 1.0, (1.0 - x - y) / y];
    let p = SRGB_PRIMARIES.map(col);
    let primaries =
        [[p[0][0], p[1][0], p[2][0]], [p[0][1], p[1][1], p[2][1]], [p[0][2], p[1][2], p[2][2]]];
    let w = col(SRGB_WHITE);
    let inv = invert3(&primaries);
    let s = [0, 1, 2].map(|r| inv[r][0] * w[0] + inv[r][1] * w[1] + inv[r][2] * w[2]);
    [0, 1, 2].map(|r| [0, 1, 2].map(|c| primaries[r][c] * s[c]))
}

fn invert3(m: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let c = |r: usize, k: usize| {
        let (r1, r2) = ((r + 1) % 3, (r + 2) % 3);
        let (k1, k2) = ((k + 1) % 3, (k + 2) % 3);
        m[r1][k1] * m[r2][k2] - m[r1][k2] * m[r2][k1]
    };
    let det = m[0][0] * c(0, 0) + m[0][1] * c(0, 1) + m[0][2] * c(0, 2);
    [0, 1, 2].map(|r| [0, 1, 2].map(|k| c(k, r) / det))
}

/// The sRGB transfer function (IEC 61966-2-1): linear `[0, 1]` -> encoded `[0, 1]`. Values
/// outside `[0, 1]` are clamped first (an encoding step, not a colour operation); NaN gives 0.
pub fn srgb_encode(linear: f64) -> f64 {
    let c = if linear > 0.0 { linear.min(1.0) } else { 0.0 };
    if c <= 0.003_130_8 { 12.92 * c } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 }
}

/// Inverse of [`srgb_encode`]: encoded `[0, 1]` -> linear.
pub fn srgb_decode(encoded: f64) -> f64 {
    let c = if encoded > 0.0 { encoded.min(1.0) } else { 0.0 };
    if c <= 0.040_45 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cmf_interpolates_the_table() {
        assert_eq!(cmf(555.0).y, CIE_1931_2DEG[195][1]);
        let mid = cmf(555.5);
        assert!((mid.y - (CIE_1931_2DEG[195][1] + CIE_1931_2DEG[196][1]) / 2.0).abs() < 1e-15);
        assert_eq!(cmf(359.9), Xyz::default());
        assert_eq!(cmf(830.0).y, CIE_1931_2DEG[470][1]);
        assert_eq!(cmf(f64::NAN), Xyz::default());
    }

    #[test]
    fn y_integral_matches_the_reference() {
        let r = crate::data::reference::YBAR_INTEGRAL_TRAPEZOID;
        assert!((*CIE_Y_INTEGRAL - r).abs() < 1e-9, "{} vs {r}", *CIE_Y_INTEGRAL);
    }

    #[test]
    fn srgb_matrix_matches_the_published_one() {
        // IEC 61966-2-1 gives the XYZ -> linear sRGB matrix to 4 decimals.
        let published =
            [[3.2406, -1.5372, -0.4986], [-0.9689, 1.8758, 0.0415], [0.0557, -0.2040, 1.0570]];
        for r in 0..3 {
            for c in 0..3 {
                assert!((XYZ_TO_SRGB[r][c] - published[r][c]).abs() < 6e-4, "[{r}][{c}]");
            }
        }
        let (x, y) = SRGB_WHITE;
        let white = Xyz::new(x / y, 1.0, (1.0 - x - y) / y).to_linear_srgb();
        for c in white {
            assert!((c - 1.0).abs() < 1e-14);
        }
    }

    #[test]
    fn transfer_function_round_trips_and_matches_known_points() {
        assert_eq!(srgb_encode(0.0), 0.0);
        assert!((srgb_encode(1.0) - 1.0).abs() < 1e-15);
        assert!((srgb_encode(0.18) - 0.461_356).abs() < 1e-6);
        for k in 0..=100 {
            let v = k as f64 / 100.0;
            assert!((srgb_decode(srgb_encode(v)) - v).abs() < 1e-12);
        }
        assert_eq!(srgb_encode(f64::NAN), 0.0);
        assert_eq!(srgb_encode(7.0), srgb_encode(1.0));
    }
}
