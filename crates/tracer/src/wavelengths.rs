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
use wide::f64x4;

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
        let uj: [f64; HERO] =
            std::array::from_fn(|j| spectrace_sampling::shifted_uniform(u, j, HERO));
        let (lambdas, p) = match self {
            Self::Visible => {
                // The density from the `tanh` the sample came from: `1 / cosh^2 = 1 - tanh^2`
                // (no `cosh` per wavelength); all four in SIMD lanes.
                let (lambdas, t) = visible4(uj);
                (
                    lambdas,
                    t.map(|t| VISIBLE_K * (1.0 - t * t) / (VISIBLE_TANH_MAX - VISIBLE_TANH_MIN)),
                )
            }
            Self::Uniform => {
                let lambdas = uj.map(|u| self.sample(u));
                (lambdas, lambdas.map(|l| self.pdf(l)))
            }
        };
        let weights = p.map(|p| if p > 0.0 { 1.0 / (HERO as f64 * p) } else { 0.0 });
        (lambdas, weights)
    }
}

/// The visible density's wavelength at `u` in `[0, 1]` (clamped to the range) and the `tanh`
/// of its argument, `t = tanh(K (lambda - centre))`, which is uniform over
/// `[VISIBLE_TANH_MIN, VISIBLE_TANH_MAX]`: [`visible4`]'s first lane, so that one wavelength and
/// a hero's agree bit for bit.
#[inline]
fn visible(u: f64) -> (f64, f64) {
    let (lambda, t) = visible4([u; HERO]);
    (lambda[0], t[0])
}

/// [`visible`] of four uniforms at once, in SIMD lanes (`wide::f64x4`).
#[inline]
fn visible4(u: [f64; HERO]) -> ([f64; HERO], [f64; HERO]) {
    let t = f64x4::splat(VISIBLE_TANH_MIN)
        + f64x4::from(u) * f64x4::splat(VISIBLE_TANH_MAX - VISIBLE_TANH_MIN);
    let one = f64x4::splat(1.0);
    // atanh(t) = ln((1 + t) / (1 - t)) / 2: one `ln` (libm's `atanh` goes through `log1p`, twice
    // the cost); `wide`'s `ln` is within a few ulps of libm's (tested), far below a picometre.
    let lambda =
        f64x4::splat(VISIBLE_CENTRE) + ((one + t) / (one - t)).ln() * f64x4::splat(0.5 / VISIBLE_K);
    (lambda.to_array().map(|l| l.clamp(CAMERA_LAMBDA_MIN, CAMERA_LAMBDA_MAX)), t.to_array())
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
    fn simd_wavelengths_are_libms_to_a_femtometre() {
        for i in 0..=10_000 {
            let u = f64::from(i) / 10_000.0;
            let (lambda, t) = visible(u);
            let exact = VISIBLE_CENTRE + ((1.0 + t) / (1.0 - t)).ln() * (0.5 / VISIBLE_K);
            let exact = exact.clamp(CAMERA_LAMBDA_MIN, CAMERA_LAMBDA_MAX);
            // 1 fm = 1e-6 nm; measured: at most about 2e-11 nm.
            assert!((lambda - exact).abs() < 1e-6, "{u}: {lambda} vs {exact}");
        }
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
