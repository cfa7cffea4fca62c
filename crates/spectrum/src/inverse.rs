//! [`InverseCdf`]: exact inverse-CDF sampling of a smooth density in O(1), from a table built once.
//!
//! # Design
//! The constructor integrates the density adaptively (4-point Gauss-Legendre, a panel is split
//! until it agrees with its two halves to 1e-14 of the total) on panels that start at the mode
//! and grow geometrically away from it (so narrow peaks and long tails are both resolved, for any
//! range), and sums the panel masses with compensation: this gives the exact CDF `u_i` at every
//! node `x_i`. On each panel the inverse CDF `x(u)` is interpolated by the quintic Hermite
//! polynomial through `(u_i, x_i)` and `(u_{i+1}, x_{i+1})` with the exact slopes `dx/du = 1 / pdf`
//! and curvatures `-pdf' / pdf^3` at the nodes (after Hörmann and Leydold's fast numerical
//! inversion). A panel is kept only when the interpolant is monotone (its slope is checked at 17
//! points) and its error, measured against the exact CDF (Gauss-Legendre quadrature of the density
//! from the node) at five interior points, is below [`TOLERANCE`] in `u`; otherwise it is split
//! into as many equal pieces as the sixth-power error law says are needed, recursively. A panel
//! whose whole mass is below [`NEGLIGIBLE`] needs no interpolant (any point in it is within that
//! mass of the right `u`). A panel that still fails after [`MAX_SPLITS`] levels of splitting, or
//! once the table holds [`MAX_PANELS`] panels, is flagged and
//! sampled at run time by safeguarded Newton steps on its exact CDF (a safety net: none of the
//! tables measured while writing this needed it).
//!
//! Sampling locates the panel with a guide table over `u` (O(1): `guide[k]` is the panel that
//! holds `u = k / m`, and only the panels between two cutpoints are searched) and evaluates one
//! quintic: about 15 ns with no `exp` or `ln` at all. A table holds 5 to 150 panels of 68 bytes
//! (2.6 KB for a 6500 K blackbody, 5 KB at 2856 K, 10 KB at 100 K).

use crate::spd::gauss_legendre;

/// Largest error in `u` allowed at the check points of an interpolated panel; the tests demand
/// `|cdf(sample(u)) - u| <= 1e-9`, so this leaves a factor 10 for the points between checks (the
/// interpolation error is a smooth bump, largest near the middle of the panel).
pub(crate) const TOLERANCE: f64 = 1e-10;

/// A panel with less mass than this (in `u`) is sampled linearly in `x`: no point of it can be
/// further than this from the right `u`.
pub(crate) const NEGLIGIBLE: f64 = 1e-13;

/// Most levels of splitting of one quadrature panel before it is flagged for the exact run-time
/// fallback.
const MAX_SPLITS: u32 = 16;

/// Most panels in a table: past it, failing panels are flagged instead of split (densities whose
/// own rounding exceeds [`TOLERANCE`], e.g. Planck's law at 1e-5 K, where `ln f` is ~1e9).
pub(crate) const MAX_PANELS: usize = 1024;

/// Most bisections of one initial panel by the adaptive quadrature.
const MAX_QUADRATURE_SPLITS: u32 = 60;

/// Where the error of a panel's interpolant is measured, as fractions `t` of its `u` interval.
const CHECKS: [f64; 5] = [0.1, 0.3, 0.5, 0.7, 0.9];

/// What the constructor needs to know about a density besides its values.
pub(crate) struct Shape<'a> {
    /// `ln` of the unnormalised density; may be `-inf` where the density is zero.
    pub(crate) ln_f: &'a dyn Fn(f64) -> f64,
    /// The support `[min, max]`.
    pub(crate) min: f64,
    /// Upper end of the support.
    pub(crate) max: f64,
    /// Where the density peaks (clamped into the support); panels start there.
    pub(crate) mode: f64,
    /// The width of the peak (or the decay length at a peak on the boundary): the first panels
    /// next to the mode are an eighth of it.
    pub(crate) scale: f64,
    /// Further panel edges: kinks, jumps and narrow features of the density.
    pub(crate) extra: &'a [f64],
    /// `d ln f / dx`, if known in closed form (otherwise estimated by differences).
    pub(crate) d_ln_f: Option<&'a dyn Fn(f64) -> f64>,
}

/// One panel of the inverse CDF: `x(t) = x0 + t (c[0] + t (c[1] + ... + t c[4]))` for
/// `t = (u - u_i) / du`.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Panel {
    x0: f64,
    /// `1 / du` (0 for a panel of zero mass, which the search never returns).
    inv_du: f64,
    /// The polynomial's coefficients; `c[0]` is NaN for a panel whose interpolant did not reach
    /// [`TOLERANCE`], sampled by Newton on the exact CDF instead.
    c: [f64; 5],
}

impl Panel {
    /// A panel sampled linearly in `x` (or, if `exact`, by Newton on the exact CDF).
    fn linear(a: f64, b: f64, du: f64, exact: bool) -> Self {
        let inv_du = if du > 0.0 { 1.0 / du } else { 0.0 };
        Self { x0: a, inv_du, c: [if exact { f64::NAN } else { b - a }, 0.0, 0.0, 0.0, 0.0] }
    }

    /// `true` if the panel is sampled by Newton on the exact CDF.
    #[inline(always)]
    fn exact(&self) -> bool {
        self.c[0].is_nan()
    }

    /// The interpolant at `t` in `[0, 1]`, kept inside the panel `[x0, x1]`.
    #[inline(always)]
    fn eval(&self, t: f64, x1: f64) -> f64 {
        let c = &self.c;
        let poly = t * (c[0] + t * (c[1] + t * (c[2] + t * (c[3] + t * c[4]))));
        (self.x0 + poly).clamp(self.x0, x1)
    }

    /// `dx/dt / du` at `t` (up to the positive factor `du`): the interpolant's slope.
    fn slope(&self, t: f64) -> f64 {
        let c = &self.c;
        c[0] + t * (2.0 * c[1] + t * (3.0 * c[2] + t * (4.0 * c[3] + t * 5.0 * c[4])))
    }
}

/// The exact inverse CDF of a smooth density, tabulated (see the module documentation).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct InverseCdf {
    /// `us[i]` = CDF at the start of panel `i`; `us[n] = 1` for `n` panels.
    us: Vec<f64>,
    /// The `n` panels and a last one that only holds the support's upper end in `x0`.
    panels: Vec<Panel>,
    /// `guide[k]` = the panel holding `u = k / (guide.len() - 1)`.
    guide: Vec<u32>,
    /// `ln` of the integral of the unnormalised density.
    ln_norm: f64,
}

/// Sums with Neumaier's compensation.
#[derive(Default)]
struct Compensated {
    sum: f64,
    c: f64,
}

impl Compensated {
    fn add(&mut self, v: f64) {
        let t = self.sum + v;
        self.c += if self.sum.abs() >= v.abs() { (self.sum - t) + v } else { (v - t) + self.sum };
        self.sum = t;
    }
    fn value(&self) -> f64 {
        self.sum + self.c
    }
}

impl InverseCdf {
    /// Builds the table; `None` if the density has no finite, positive integral.
    pub(crate) fn new(shape: &Shape<'_>) -> Option<Self> {
        let Shape { ln_f, min, max, mode, scale, extra, d_ln_f } = *shape;
        if !(min < max && min.is_finite() && max.is_finite()) {
            return None;
        }
        let mode = mode.clamp(min, max);
        let edges = initial_edges(min, max, mode, scale, extra);
        let ln_peak = edges.iter().map(|&x| ln_f(x)).fold(f64::NEG_INFINITY, f64::max);
        if !ln_peak.is_finite() {
            return None;
        }
        // Work relative to the peak so nothing overflows or underflows needlessly.
        let rel = |x: f64| {
            let v = (ln_f(x) - ln_peak).exp();
            if v.is_finite() { v } else { 0.0 }
        };
        let rough: f64 = edges.windows(2).map(|p| gauss_legendre(&rel, p[0], p[1])).sum();
        if !(rough > 0.0 && rough.is_finite()) {
            return None;
        }
        // Adaptive quadrature: panels (a, b, mass) in increasing order.
        let tol = 1e-14 * rough;
        let mut quad: Vec<(f64, f64, f64)> = Vec::new();
        for p in edges.windows(2) {
            let mut stack = vec![(p[0], p[1], 0_u32)];
            while let Some((a, b, depth)) = stack.pop() {
                let mid = 0.5 * (a + b);
                let whole = gauss_legendre(&rel, a, b);
                let (left, right) = (gauss_legendre(&rel, a, mid), gauss_legendre(&rel, mid, b));
                let halves = left + right;
                if (whole - halves).abs() <= tol
                    || depth >= MAX_QUADRATURE_SPLITS
                    || quad.len() + stack.len() >= MAX_PANELS
                    || !(mid > a && mid < b)
                {
                    quad.push((a, b, halves));
                } else {
                    stack.push((mid, b, depth + 1));
                    stack.push((a, mid, depth + 1));
                }
            }
        }
        let mut sum = Compensated::default();
        quad.iter().for_each(|q| sum.add(q.2));
        let total = sum.value();
        if !(total > 0.0 && total.is_finite()) {
            return None;
        }
        let ln_norm = ln_peak + total.ln();
        let density = Density { ln_f, d_ln_f, ln_norm };
        // Normalised mass of [a, x].
        let mass = |a: f64, x: f64| gauss_legendre(&rel, a, x) / total;

        let mut us = Vec::with_capacity(quad.len() + 1);
        let mut panels = Vec::with_capacity(quad.len());
        let mut cumulative = Compensated::default();
        for (qi, &(a, b, m)) in quad.iter().enumerate() {
            let u_a = (cumulative.value() / total).min(1.0);
            cumulative.add(m);
            let u_b =
                if qi + 1 == quad.len() { 1.0 } else { (cumulative.value() / total).min(1.0) };
            let mut stack = vec![(a, b, u_a, u_b.max(u_a), 0_u32)];
            while let Some((a, b, u_a, u_b, depth)) = stack.pop() {
                match interpolate(a, b, u_a, u_b, &density, &mass) {
                    Ok(panel) => {
                        us.push(u_a);
                        panels.push(panel);
                    }
                    Err(pieces) => {
                        let mid = 0.5 * (a + b);
                        let budget = quad.len() + panels.len() + stack.len() + pieces;
                        if depth >= MAX_SPLITS || budget > MAX_PANELS || !(mid > a && mid < b) {
                            us.push(u_a);
                            panels.push(Panel::linear(a, b, u_b - u_a, true));
                        } else {
                            // Pieces of equal width, pushed right to left so they pop in order.
                            let edge = |k: usize| {
                                if k == pieces { b } else { a + (b - a) * k as f64 / pieces as f64 }
                            };
                            let mut cdf_at = Vec::with_capacity(pieces + 1);
                            cdf_at.push(u_a);
                            for k in 1..pieces {
                                let u = cdf_at[k - 1] + mass(edge(k - 1), edge(k));
                                cdf_at.push(u.clamp(u_a, u_b));
                            }
                            cdf_at.push(u_b);
                            for k in (0..pieces).rev() {
                                let (lo, hi) = (edge(k), edge(k + 1));
                                if hi > lo {
                                    stack.push((lo, hi, cdf_at[k], cdf_at[k + 1], depth + 1));
                                }
                            }
                        }
                    }
                }
            }
        }
        us.push(1.0);
        let n = panels.len();
        panels.push(Panel::linear(max, max, 0.0, false));
        let search = |u: f64| us[1..n].partition_point(|&v| v <= u);
        let guide = (0..=n)
            .map(|k| {
                search((k as f64 / n as f64).min(spectrace_sampling::ONE_MINUS_EPSILON)) as u32
            })
            .collect();
        Some(Self { us, panels, guide, ln_norm })
    }

    /// The normalised density at a point where the unnormalised log-density is `ln_f_at_x`.
    #[inline]
    pub(crate) fn density(&self, ln_f_at_x: f64) -> f64 {
        (ln_f_at_x - self.ln_norm).exp()
    }

    /// The number of panels.
    pub(crate) fn len(&self) -> usize {
        self.panels.len() - 1
    }

    /// `true` if every panel is interpolated (none falls back to Newton on the exact CDF).
    pub(crate) fn is_interpolated(&self) -> bool {
        !self.panels.iter().any(Panel::exact)
    }

    /// Inverse CDF at `u` (NaN or out-of-range `u` is clamped into `[0, 1)`, NaN to 0); `ln_f`
    /// must be the density the table was built from (used only by flagged panels).
    #[inline]
    pub(crate) fn sample(&self, ln_f: &dyn Fn(f64) -> f64, u: f64) -> f64 {
        let u = spectrace_sampling::clamp_uniform(u);
        let m = self.guide.len() - 1;
        let k = spectrace_sampling::cell_index(u * m as f64, m - 1);
        let (lo, hi) = (self.guide[k] as usize, self.guide[k + 1] as usize);
        let i = if lo == hi { lo } else { lo + self.us[lo + 1..=hi].partition_point(|&v| v <= u) };
        let (p, x1) = (&self.panels[i], self.panels[i + 1].x0);
        if p.exact() {
            return self.newton(ln_f, p.x0, x1, u - self.us[i]);
        }
        // A panel whose mass underflows to 0 has an infinite `inv_du`: `0 * inf` is NaN, and the
        // sample is then the panel's start (where the CDF still equals `u`).
        let t = (u - self.us[i]) * p.inv_du;
        p.eval(if t > 0.0 { t.min(1.0) } else { 0.0 }, x1)
    }

    /// Solves `integral of pdf over [x0, x] = target` in `[x0, x1]` by safeguarded Newton steps.
    #[cold]
    fn newton(&self, ln_f: &dyn Fn(f64) -> f64, x0: f64, x1: f64, target: f64) -> f64 {
        let pdf = |x: f64| (ln_f(x) - self.ln_norm).exp();
        let (mut lo, mut hi) = (x0, x1);
        let mut x = 0.5 * (lo + hi);
        for _ in 0..200 {
            let g = gauss_legendre(&pdf, x0, x) - target;
            if g == 0.0 {
                break;
            }
            if g > 0.0 {
                hi = x;
            } else {
                lo = x;
            }
            let d = pdf(x);
            let newton = if d > 0.0 { x - g / d } else { f64::NAN };
            let next = if newton > lo && newton < hi { newton } else { 0.5 * (lo + hi) };
            if next == x || hi - lo <= 4.0 * f64::EPSILON * hi.abs() {
                break;
            }
            x = next;
        }
        x.clamp(x0, x1)
    }
}

/// Panel edges: the support's ends, the mode, the `extra` points, and points at `scale / 8 * 2^k` on either side of
/// the mode, so panels grow geometrically away from the peak.
fn initial_edges(min: f64, max: f64, mode: f64, scale: f64, extra: &[f64]) -> Vec<f64> {
    let width = max - min;
    let scale = if scale > 0.0 && scale.is_finite() { scale.min(width) } else { width };
    let mut edges = vec![min, max, mode];
    edges.extend(extra.iter().copied().filter(|x| x.is_finite()));
    let mut d = scale / 8.0;
    while d.is_finite() && (mode - d > min || mode + d < max) {
        edges.extend([mode - d, mode + d]);
        d *= 2.0;
    }
    edges.retain(|&x| x >= min && x <= max);
    edges.sort_by(f64::total_cmp);
    edges.dedup();
    edges
}

/// The panel `[a, b]` with CDF `u_a` .. `u_b` as a quintic Hermite inverse (value, slope
/// `1 / pdf` and curvature `-pdf' / pdf^3` of `x(u)` at both ends), or, if that is not monotone
/// (its slope is checked at 17 points) or misses the exact CDF by more than [`TOLERANCE`] at a
/// check point, the number of equal pieces to split the panel into.
fn interpolate(
    a: f64,
    b: f64,
    u_a: f64,
    u_b: f64,
    density: &Density<'_>,
    mass: &dyn Fn(f64, f64) -> f64,
) -> Result<Panel, usize> {
    let du = u_b - u_a;
    let d = b - a;
    if du <= NEGLIGIBLE {
        return Ok(Panel::linear(a, b, du, false));
    }
    // One-sided values and log-derivatives, from inside the panel: a jump or kink at a panel
    // edge belongs to neither neighbour.
    let (pdf_a, dln_a) = density.at_start(a, b);
    let (pdf_b, dln_b) = density.at_end(a, b);
    // Slopes and curvatures of x(t), t = (u - u_a) / du.
    let (v0, v1) = (du / pdf_a, du / pdf_b);
    let (k0, k1) = (-dln_a * v0 * v0, -dln_b * v1 * v1);
    if !(v0.is_finite() && v1.is_finite() && k0.is_finite() && k1.is_finite()) {
        return Err(2);
    }
    let r0 = d - v0 - 0.5 * k0;
    let r1 = v1 - v0 - k0;
    let r2 = k1 - k0;
    let c = [
        v0,
        0.5 * k0,
        10.0 * r0 - 4.0 * r1 + 0.5 * r2,
        -15.0 * r0 + 7.0 * r1 - r2,
        6.0 * r0 - 3.0 * r1 + 0.5 * r2,
    ];
    let panel = Panel { c, ..Panel::linear(a, b, du, false) };
    if !(0..=16).all(|k| panel.slope(k as f64 / 16.0) >= 0.0) {
        return Err(2);
    }
    let error = CHECKS
        .iter()
        .map(|&t| (mass(a, panel.eval(t, b)) - t * du).abs())
        .fold(0.0_f64, |e, x| if x.is_nan() { f64::INFINITY } else { e.max(x) });
    if error <= TOLERANCE {
        return Ok(panel);
    }
    // The error falls like the sixth power of the width: split into enough pieces to meet the
    // tolerance at once (with a margin), instead of halving repeatedly.
    let pieces = (1.15 * (error / TOLERANCE).powf(1.0 / 6.0)).ceil();
    Err(if pieces.is_finite() { (pieces as usize).clamp(2, 64) } else { 2 })
}

/// The normalised density and its log-derivative, evaluated from inside a panel.
struct Density<'a> {
    ln_f: &'a dyn Fn(f64) -> f64,
    /// The exact `d ln f / dx`, if known; otherwise a one-sided difference is used.
    d_ln_f: Option<&'a dyn Fn(f64) -> f64>,
    ln_norm: f64,
}

impl Density<'_> {
    /// Density and log-derivative at `a`, from the right (inside `[a, b]`).
    fn at_start(&self, a: f64, b: f64) -> (f64, f64) {
        let x = a.next_up().min(b);
        (self.normalised(x), self.derivative(a, b, 1.0))
    }

    /// Density and log-derivative at `b`, from the left.
    fn at_end(&self, a: f64, b: f64) -> (f64, f64) {
        let x = b.next_down().max(a);
        (self.normalised(x), self.derivative(b, a, -1.0))
    }

    fn normalised(&self, x: f64) -> f64 {
        ((self.ln_f)(x) - self.ln_norm).exp()
    }

    /// `d ln f / dx` at `x`, exact or by the second-order one-sided difference towards `other`.
    fn derivative(&self, x: f64, other: f64, direction: f64) -> f64 {
        if let Some(d) = self.d_ln_f {
            return d(x);
        }
        let h = direction * (1e-3 * (other - x).abs()).min(6e-6 * x.abs().max(1e-300));
        let f = |k: f64| (self.ln_f)(x + k * h);
        (-3.0 * f(0.0) + 4.0 * f(1.0) - f(2.0)) / (2.0 * h)
    }
}
