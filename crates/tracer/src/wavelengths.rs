//! Wavelengths for camera paths: hero wavelengths drawn from the observer's sensitivity.
//!
//! A camera path does not know which light it will reach, so its wavelengths cannot come from a
//! light's spectrum. They are drawn from a density over the range of the CIE 1931 observer,
//! [`CAMERA_LAMBDA_MIN`]..[`CAMERA_LAMBDA_MAX`]: by default the *visible* density
//! `p(lambda) ∝ 1 / cosh^2(0.0072 (lambda - 538 nm))`, a smooth fit to the sum of the colour
//! matching functions (the choice of pbrt-v4 and of Radziszewski et al. 2009), which puts samples
//! where the eye is sensitive; or uniformly. Both have closed-form exact inverse CDFs.
//!
//! A path carries [`HERO`] wavelengths (Wilkie et al. 2014): one uniform `u` gives the hero
//! `lambda_0 = P^-1(u)` and its companions `lambda_j = P^-1((u + j / HERO) mod 1)`, so the four are
//! stratified over the density. Each is an unbiased estimate on its own; the path's estimate is
//! their mean, `(1 / HERO) sum_j f(lambda_j) / p(lambda_j)`. At a dispersive surface the
//! companions are dropped and the hero alone continues with weight `f(lambda_0) / p(lambda_0)`,
//! which is still unbiased because the hero alone is distributed by `p`.

use serde::{Deserialize, Serialize};

/// Shortest wavelength a camera path draws (nm): the start of the CIE 1931 tables.
pub const CAMERA_LAMBDA_MIN: f64 = 360.0;
/// Longest wavelength a camera path draws (nm): the end of the CIE 1931 tables.
pub const CAMERA_LAMBDA_MAX: f64 = 830.0;
/// Wavelengths carried by one camera path when nothing disperses.
pub const HERO: usize = 4;

/// The steepness of the visible density (nm^-1).
const VISIBLE_K: f64 = 0.0072;
/// The centre of the visible density (nm).
const VISIBLE_CENTRE: f64 = 538.0;
/// `tanh(K (CAMERA_LAMBDA_MIN - centre))`: the visible density's CDF is affine in `tanh`, from
/// this value to [`VISIBLE_TANH_MAX`] (a constant, checked against `tanh` by a test, so the hot
/// path needs no lazy initialisation).
const VISIBLE_TANH_MIN: f64 = -0.856_910_625_469_828;
/// `tanh(K (CAMERA_LAMBDA_MAX - centre))`.
const VISIBLE_TANH_MAX: f64 = 0.970_591_346_940_269_8;

/// How camera paths draw their wavelengths.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CameraWavelengths {
    /// In proportion to the observer's sensitivity (`1 / cosh^2`, see the module docs). The
    /// default.
    #[default]
    Visible,
    /// Uniformly over 360..830 nm.
    Uniform,
}

impl CameraWavelengths {
    /// The wavelength (nm) at probability `u` in `[0, 1)` (the exact inverse CDF).
    pub fn sample(self, u: f64) -> f64 {
        let u = spectrace_sampling::clamp_uniform(u);
        let lambda = match self {
            Self::Uniform => CAMERA_LAMBDA_MIN + u * (CAMERA_LAMBDA_MAX - CAMERA_LAMBDA_MIN),
            Self::Visible => return visible(u).0,
        };
        lambda.clamp(CAMERA_LAMBDA_MIN, CAMERA_LAMBDA_MAX)
    }

    /// The density (nm^-1) of [`sample`](Self::sample) at `lambda`; 0 outside the range.
    pub fn pdf(self, lambda: f64) -> f64 {
        if !(CAMERA_LAMBDA_MIN..=CAMERA_LAMBDA_MAX).contains(&lambda) {
            return 0.0;
        }
        match self {
            Self::Uniform => 1.0 / (CAMERA_LAMBDA_MAX - CAMERA_LAMBDA_MIN),
            Self::Visible => {
                let c = (VISIBLE_K * (lambda - VISIBLE_CENTRE)).cosh();
                VISIBLE_K / ((VISIBLE_TANH_MAX - VISIBLE_TANH_MIN) * c * c)
            }
        }
    }

    /// The [`HERO`] stratified wavelengths of one path from one uniform, with the weight
    /// `1 / (HERO p(lambda_j))` of each in the path's estimate.
    pub fn sample_hero(self, u: f64) -> ([f64; HERO], [f64; HERO]) {
        let mut lambdas = [0.0; HERO];
        let mut weights = [0.0; HERO];
        let u = spectrace_sampling::clamp_uniform(u);
        for j in 0..HERO {
            // `(u + j / HERO) mod 1`, exactly (`x - 1` is exact for `x` in `[1, 2)`).
            let shifted = u + j as f64 / HERO as f64;
            let uj = if shifted >= 1.0 { shifted - 1.0 } else { shifted };
            let p = match self {
                Self::Visible => {
                    // The density from the `tanh` the sample came from: `1 / cosh^2 = 1 - tanh^2`
                    // (no `cosh` per wavelength).
                    let (lambda, t) = visible(uj);
                    lambdas[j] = lambda;
                    VISIBLE_K * (1.0 - t * t) / (VISIBLE_TANH_MAX - VISIBLE_TANH_MIN)
                }
                Self::Uniform => {
                    lambdas[j] = self.sample(uj);
                    self.pdf(lambdas[j])
                }
            };
            weights[j] = if p > 0.0 { 1.0 / (HERO as f64 * p) } else { 0.0 };
        }
        (lambdas, weights)
    }
}

/// The visible density's wavelength at `u` in `[0, 1]` (clamped to the range) and the `tanh`
/// of its argument, `t = tanh(K (lambda - centre))`, which is uniform over
/// `[VISIBLE_TANH_MIN, VISIBLE_TANH_MAX]`.
#[inline]
fn visible(u: f64) -> (f64, f64) {
    let t = VISIBLE_TANH_MIN + u * (VISIBLE_TANH_MAX - VISIBLE_TANH_MIN);
    // atanh(t) = ln((1 + t) / (1 - t)) / 2: one `ln` (libm's `atanh` goes through `log1p`, twice
    // the cost); its rounding near t = 0 is far below a picometre.
    let lambda = VISIBLE_CENTRE + ((1.0 + t) / (1.0 - t)).ln() * (0.5 / VISIBLE_K);
    (lambda.clamp(CAMERA_LAMBDA_MIN, CAMERA_LAMBDA_MAX), t)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_densities_integrate_to_one_and_invert_their_cdfs() {
        for s in [CameraWavelengths::Visible, CameraWavelengths::Uniform] {
            // Midpoint rule over 470 000 panels: the densities are smooth, error < 1e-9.
            let n = 470_000;
            let h = (CAMERA_LAMBDA_MAX - CAMERA_LAMBDA_MIN) / n as f64;
            let mut cdf = 0.0;
            let mut next_check = 0.1;
            for i in 0..n {
                let l = CAMERA_LAMBDA_MIN + (i as f64 + 0.5) * h;
                cdf += s.pdf(l) * h;
                let edge = CAMERA_LAMBDA_MIN + (i + 1) as f64 * h;
                if cdf >= next_check {
                    // sample(cdf) lands at this panel's edge, to the quadrature error.
                    assert!((s.sample(cdf) - edge).abs() < 1e-6, "{s:?} at {edge}");
                    next_check += 0.1;
                }
            }
            assert!((cdf - 1.0).abs() < 1e-9, "{s:?}: {cdf}");
            assert_eq!(s.sample(0.0), CAMERA_LAMBDA_MIN);
            assert!((s.sample(1.0 - 1e-16) - CAMERA_LAMBDA_MAX).abs() < 1e-6);
            assert_eq!(s.pdf(300.0), 0.0);
            for u in [f64::NAN, -1.0, 2.0, f64::INFINITY] {
                let l = s.sample(u);
                assert!((CAMERA_LAMBDA_MIN..=CAMERA_LAMBDA_MAX).contains(&l), "{u} -> {l}");
            }
        }
        // The visible density prefers the middle of the spectrum.
        let v = CameraWavelengths::Visible;
        // cosh^2(0.0072 * 138) = 2.36 at 400 nm and cosh^2(0.0072 * 182) = 3.9 at 720 nm.
        assert!(v.pdf(555.0) > 2.2 * v.pdf(400.0) && v.pdf(555.0) > 3.8 * v.pdf(720.0));
    }

    #[test]
    fn the_tanh_constants_are_the_range_ends() {
        let end = |lambda: f64| (VISIBLE_K * (lambda - VISIBLE_CENTRE)).tanh();
        assert!((VISIBLE_TANH_MIN - end(CAMERA_LAMBDA_MIN)).abs() < 1e-15);
        assert!((VISIBLE_TANH_MAX - end(CAMERA_LAMBDA_MAX)).abs() < 1e-15);
    }

    #[test]
    fn hero_wavelengths_are_stratified_and_weighted_by_their_density() {
        let v = CameraWavelengths::Visible;
        let (l, w) = v.sample_hero(0.3);
        for j in 0..HERO {
            assert_eq!(l[j], v.sample((0.3 + j as f64 / 4.0).fract()));
            assert!((w[j] * 4.0 * v.pdf(l[j]) - 1.0).abs() < 1e-12);
        }
        // The mean of f(l_j) w_j over u estimates the integral of f: f = 1 gives 470 nm.
        let n = 10_000;
        let total: f64 =
            (0..n).map(|i| v.sample_hero((i as f64 + 0.5) / n as f64).1.iter().sum::<f64>()).sum();
        assert!((total / n as f64 - 470.0).abs() < 0.05, "{}", total / n as f64);
    }
}
