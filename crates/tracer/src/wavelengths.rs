//! Wavelengths for camera paths: hero wavelengths drawn from the observer's sensitivity.
//!
//! A camera path does not know which light it will reach, so its wavelengths cannot come from a
//! light's spectrum. They are drawn from a density over the range of the CIE 1931 observer,
//! [`CAMERA_LAMBDA_MIN`]..[`CAMERA_LAMBDA_MAX`]: by default the *visible* density, which puts
//! samples where the eye is sensitive; or uniformly.
//!
//! The visible density is [`VISIBLE_STEPS`] steps of equal probability cut from
//! `1 / cosh^2(0.0072 (lambda - 538 nm))`, a smooth fit to the sum of the colour matching
//! functions (the choice of pbrt-v4 and of Radziszewski et al. 2009): step `k` spans the
//! wavelengths where that fit's CDF runs from `k / VISIBLE_STEPS` to `(k + 1) / VISIBLE_STEPS`,
//! and the density is constant on it. Its inverse CDF is exact and costs a multiplication, a
//! floor and two table reads, where the fit's own needs a logarithm per wavelength (a tenth of
//! a camera sample on the race's spot over a plane, measured). The steps follow the fit closely
//! (the widest, at the long end, 15.3 nm, over which the fit changes by a factor of 1.24; 1 nm
//! in the middle), so that the variance is the fit's.
//!
//! A path carries [`HERO`] wavelengths (Wilkie et al. 2014): one uniform `u` gives the hero
//! `lambda_0 = P^-1(u)` and its companions `lambda_j = P^-1((u + j / HERO) mod 1)`, so the four are
//! stratified over the density. Each is an unbiased estimate on its own; the path's estimate is
//! their mean, `(1 / HERO) sum_j f(lambda_j) / p(lambda_j)`. At a dispersive surface the
//! companions are dropped and the hero alone continues with weight `f(lambda_0) / p(lambda_0)`,
//! which is still unbiased because the hero alone is distributed by `p`.

use std::sync::LazyLock;

use serde::{Deserialize, Serialize};

/// Shortest wavelength a camera path draws (nm): the start of the CIE 1931 tables.
pub const CAMERA_LAMBDA_MIN: f64 = 360.0;
/// Longest wavelength a camera path draws (nm): the end of the CIE 1931 tables.
pub const CAMERA_LAMBDA_MAX: f64 = 830.0;
/// Wavelengths carried by one camera path when nothing disperses.
pub const HERO: usize = 4;
/// Steps of equal probability of the visible density (see the module docs).
pub const VISIBLE_STEPS: usize = 256;

/// The steepness of the visible density's fit (nm^-1).
const VISIBLE_K: f64 = 0.0072;
/// The centre of the visible density's fit (nm).
const VISIBLE_CENTRE: f64 = 538.0;
/// `tanh(K (CAMERA_LAMBDA_MIN - centre))`: the fit's CDF is affine in `tanh`, from this value
/// to [`VISIBLE_TANH_MAX`] (checked against `tanh` by a test).
const VISIBLE_TANH_MIN: f64 = -0.856_910_625_469_828;
/// `tanh(K (CAMERA_LAMBDA_MAX - centre))`.
const VISIBLE_TANH_MAX: f64 = 0.970_591_346_940_269_8;

/// The visible density's step edges (nm), increasing from [`CAMERA_LAMBDA_MIN`] to
/// [`CAMERA_LAMBDA_MAX`]: edge `k` is the fit's exact inverse CDF at `k / VISIBLE_STEPS`.
static VISIBLE_EDGES: LazyLock<[f64; VISIBLE_STEPS + 1]> = LazyLock::new(|| {
    std::array::from_fn(|k| match k {
        0 => CAMERA_LAMBDA_MIN,
        VISIBLE_STEPS => CAMERA_LAMBDA_MAX,
        _ => fit_inverse_cdf(k as f64 / VISIBLE_STEPS as f64),
    })
});

/// The fit's inverse CDF at `u` in `[0, 1]`: `centre + atanh(t) / K` with `t` uniform over
/// `[VISIBLE_TANH_MIN, VISIBLE_TANH_MAX]`.
fn fit_inverse_cdf(u: f64) -> f64 {
    let t = VISIBLE_TANH_MIN + u * (VISIBLE_TANH_MAX - VISIBLE_TANH_MIN);
    (VISIBLE_CENTRE + t.atanh() / VISIBLE_K).clamp(CAMERA_LAMBDA_MIN, CAMERA_LAMBDA_MAX)
}

/// How camera paths draw their wavelengths.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CameraWavelengths {
    /// In proportion to the observer's sensitivity ([`VISIBLE_STEPS`] steps of a `1 / cosh^2`
    /// fit, see the module docs). The default.
    #[default]
    Visible,
    /// Uniformly over 360..830 nm.
    Uniform,
}

impl CameraWavelengths {
    /// The wavelength (nm) at probability `u` in `[0, 1)` (the exact inverse CDF).
    pub fn sample(self, u: f64) -> f64 {
        let u = spectrace_sampling::clamp_uniform(u);
        match self {
            Self::Uniform => (CAMERA_LAMBDA_MIN + u * (CAMERA_LAMBDA_MAX - CAMERA_LAMBDA_MIN))
                .clamp(CAMERA_LAMBDA_MIN, CAMERA_LAMBDA_MAX),
            Self::Visible => visible(&VISIBLE_EDGES, u),
        }
    }

    /// The density (nm^-1) of [`sample`](Self::sample) at `lambda`; 0 outside the range.
    pub fn pdf(self, lambda: f64) -> f64 {
        if !(CAMERA_LAMBDA_MIN..=CAMERA_LAMBDA_MAX).contains(&lambda) {
            return 0.0;
        }
        match self {
            Self::Uniform => 1.0 / (CAMERA_LAMBDA_MAX - CAMERA_LAMBDA_MIN),
            Self::Visible => {
                let edges = &*VISIBLE_EDGES;
                // The step holding `lambda` (the last one for the range's end).
                let k = (edges.partition_point(|&e| e <= lambda) - 1).min(VISIBLE_STEPS - 1);
                1.0 / (VISIBLE_STEPS as f64 * (edges[k + 1] - edges[k]))
            }
        }
    }

    /// The [`HERO`] stratified wavelengths of one path from one uniform, with the weight
    /// `1 / (HERO p(lambda_j))` of each in the path's estimate.
    pub fn sample_hero(self, u: f64) -> ([f64; HERO], [f64; HERO]) {
        match self {
            Self::Visible => visible_hero(&VISIBLE_EDGES, spectrace_sampling::clamp_uniform(u)),
            Self::Uniform => {
                let lambdas = std::array::from_fn(|j| {
                    self.sample(spectrace_sampling::shifted_uniform(u, j, HERO))
                });
                let weights = lambdas.map(|l| {
                    let p = self.pdf(l);
                    if p > 0.0 { 1.0 / (HERO as f64 * p) } else { 0.0 }
                });
                (lambdas, weights)
            }
        }
    }
}

/// Steps between a hero's step and its next companion's: `(u + 1 / HERO) N = u N + N / HERO`.
const HERO_STRIDE: usize = VISIBLE_STEPS / HERO;

// `visible_hero`'s index arithmetic needs both.
const _: () = assert!(VISIBLE_STEPS.is_power_of_two() && VISIBLE_STEPS.is_multiple_of(HERO));

/// The visible density's [`HERO`] wavelengths at `u` in `[0, 1)` and their weights `1 / (HERO
/// p)`. Wavelength `j` is the inverse CDF at `(u + j / HERO) mod 1`: since the steps hold equal
/// shares and [`HERO`] divides [`VISIBLE_STEPS`], that is the point at the same fraction
/// `frac(u N)` of step `floor(u N) + j N / HERO` (mod `N`), so one index and one fraction serve
/// all four (and `u + j / HERO` is never rounded).
#[inline]
fn visible_hero(edges: &[f64; VISIBLE_STEPS + 1], u: f64) -> ([f64; HERO], [f64; HERO]) {
    let x = u * VISIBLE_STEPS as f64;
    // `u < 1` makes `x < N` (the product rounds below N). The mask is the identity on
    // `0..N` (a power of two) and tells the compiler that `k + 1` indexes the table.
    let k = spectrace_sampling::cell_index(x, VISIBLE_STEPS - 1) & (VISIBLE_STEPS - 1);
    let f = x - k as f64;
    let (mut lambdas, mut weights) = ([0.0; HERO], [0.0; HERO]);
    for j in 0..HERO {
        let kj = (k + j * HERO_STRIDE) & (VISIBLE_STEPS - 1);
        let (lo, hi) = (edges[kj], edges[kj + 1]);
        let width = hi - lo;
        // The bounds keep rounding inside the step (and monotone across its ends).
        lambdas[j] = (lo + f * width).max(lo).min(hi);
        // 1 / (HERO p) with p = 1 / (N width).
        weights[j] = width * (VISIBLE_STEPS as f64 / HERO as f64);
    }
    (lambdas, weights)
}

/// The visible density's wavelength at `u` in `[0, 1)`: [`visible_hero`]'s first.
fn visible(edges: &[f64; VISIBLE_STEPS + 1], u: f64) -> f64 {
    visible_hero(edges, u).0[0]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_uniform_density_integrates_to_one_and_inverts_its_cdf() {
        let s = CameraWavelengths::Uniform;
        // Midpoint rule over 470 000 panels: the density is constant, error < 1e-9.
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
    }

    #[test]
    fn both_densities_cover_the_range_and_nothing_else() {
        for s in [CameraWavelengths::Visible, CameraWavelengths::Uniform] {
            assert_eq!(s.sample(0.0), CAMERA_LAMBDA_MIN);
            assert!((s.sample(1.0 - 1e-16) - CAMERA_LAMBDA_MAX).abs() < 1e-6);
            assert_eq!(s.pdf(300.0), 0.0);
            assert_eq!(s.pdf(830.5), 0.0);
            assert!(s.pdf(CAMERA_LAMBDA_MAX) > 0.0 && s.pdf(CAMERA_LAMBDA_MIN) > 0.0);
            for u in [f64::NAN, -1.0, 2.0, f64::INFINITY, f64::NEG_INFINITY] {
                let l = s.sample(u);
                assert!((CAMERA_LAMBDA_MIN..=CAMERA_LAMBDA_MAX).contains(&l), "{u} -> {l}");
            }
        }
        // The visible density prefers the middle of the spectrum: the fit's ratios are
        // cosh^2(0.0072 * 138) = 2.36 at 400 nm and cosh^2(0.0072 * 182) = 3.9 at 720 nm.
        let v = CameraWavelengths::Visible;
        assert!(v.pdf(555.0) > 2.2 * v.pdf(400.0) && v.pdf(555.0) > 3.8 * v.pdf(720.0));
    }

    #[test]
    fn the_visible_steps_hold_equal_shares_of_the_fit() {
        let v = CameraWavelengths::Visible;
        let edges = &*VISIBLE_EDGES;
        let fit_cdf = |lambda: f64| {
            ((VISIBLE_K * (lambda - VISIBLE_CENTRE)).tanh() - VISIBLE_TANH_MIN)
                / (VISIBLE_TANH_MAX - VISIBLE_TANH_MIN)
        };
        let fit_pdf = |lambda: f64| {
            let c = (VISIBLE_K * (lambda - VISIBLE_CENTRE)).cosh();
            VISIBLE_K / ((VISIBLE_TANH_MAX - VISIBLE_TANH_MIN) * c * c)
        };
        let n = VISIBLE_STEPS as f64;
        let (mut total, mut widest, mut steepest) = (0.0, 0.0_f64, 0.0_f64);
        for k in 0..VISIBLE_STEPS {
            let (lo, hi) = (edges[k], edges[k + 1]);
            assert!(lo < hi, "step {k}: {lo}..{hi}");
            // Each edge is the fit's quantile: its CDF there is k / N.
            assert!((fit_cdf(lo) - k as f64 / n).abs() < 1e-12, "edge {k}");
            // The step's density, read inside it and at both its ends, is its share over its
            // width, and the inverse CDF maps the share's ends to the step's ends.
            let p = v.pdf(0.5 * (lo + hi));
            assert_eq!(p, 1.0 / (n * (hi - lo)));
            assert_eq!((v.pdf(lo), v.sample(k as f64 / n)), (p, lo), "step {k}");
            total += p * (hi - lo);
            widest = widest.max(hi - lo);
            steepest = steepest.max(fit_pdf(lo) / fit_pdf(hi)).max(fit_pdf(hi) / fit_pdf(lo));
        }
        assert!((total - 1.0).abs() < 1e-12, "{total}");
        // As the module docs say: steps of at most 15.3 nm, over which the fit changes by a
        // factor of at most 1.24.
        assert!(widest < 15.35 && steepest < 1.24, "{widest} nm, {steepest}");
        // Sampling is monotone and stays inside the step it picks.
        let mut last = CAMERA_LAMBDA_MIN;
        for i in 0..=100_000 {
            let u = (f64::from(i) / 100_000.0).min(1.0 - f64::EPSILON / 2.0);
            let l = v.sample(u);
            let k = ((u * n) as usize).min(VISIBLE_STEPS - 1);
            assert!(l >= last && (edges[k]..=edges[k + 1]).contains(&l), "{u}: {l}");
            last = l;
        }
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
        let edges = &*VISIBLE_EDGES;
        for u in [0.0, 0.3, 0.7431, 1.0 - f64::EPSILON / 2.0] {
            let (l, w) = v.sample_hero(u);
            // The hero is the inverse CDF at u; companion j sits at the same fraction of the
            // step N j / HERO further on (mod N): the inverse CDF at (u + j / HERO) mod 1.
            assert_eq!(l[0], v.sample(u));
            let x = u * VISIBLE_STEPS as f64;
            let k = x.floor() as usize;
            for j in 0..HERO {
                let kj = (k + j * VISIBLE_STEPS / HERO) % VISIBLE_STEPS;
                let (lo, hi) = (edges[kj], edges[kj + 1]);
                assert!((l[j] - (lo + (x - k as f64) * (hi - lo))).abs() < 1e-12, "{u} {j}");
                let shifted = (u + j as f64 / HERO as f64).fract();
                assert!((l[j] - v.sample(shifted)).abs() < 1e-9, "{u} {j}");
                // The weight is 1 / (HERO p) of the step drawn from, which `pdf` gives inside
                // it (a point rounded onto an edge belongs to either step: measure zero).
                assert_eq!(w[j], (hi - lo) * VISIBLE_STEPS as f64 / HERO as f64);
                if lo < l[j] && l[j] < hi {
                    assert!((w[j] * 4.0 * v.pdf(l[j]) - 1.0).abs() < 1e-12, "{u} {j}");
                }
            }
        }
        // The mean of f(l_j) w_j over u estimates the integral of f: f = 1 gives 470 nm.
        let n = 10_000;
        let total: f64 =
            (0..n).map(|i| v.sample_hero((i as f64 + 0.5) / n as f64).1.iter().sum::<f64>()).sum();
        assert!((total / n as f64 - 470.0).abs() < 0.05, "{}", total / n as f64);
        // Both densities' bundles agree with their single draws.
        let uniform = CameraWavelengths::Uniform;
        let (l, w) = uniform.sample_hero(0.3);
        for j in 0..HERO {
            assert_eq!(l[j], uniform.sample((0.3 + j as f64 / 4.0).fract()));
            assert!((w[j] * 4.0 * uniform.pdf(l[j]) - 1.0).abs() < 1e-12);
        }
    }
}
