//! [`PiecewiseLinear`]: the seed's continuous generator with linear gap filling (section 2.2.1),
//! with an in-segment inversion that never divides by the slope.
//!
//! # The in-segment inversion
//! On a segment of width `w` with end values `a` and `b`, the density is `a + (b - a) t` for
//! `t = (x - x0) / w` in `[0, 1]`. Having chosen the segment with a fraction `s` of its mass still
//! to cover, we need `t` with `a t + (b - a) t^2 / 2 = s (a + b) / 2`. The seed solves this with
//! the textbook root `(-a + sqrt(D)) / (b - a)`, which divides by the slope and cancels
//! catastrophically on nearly flat segments. We instead use the other form of the root,
//!
//! ```text
//!     t = s (a + b) / (a + sqrt((1 - s) a^2 + s b^2))
//! ```
//!
//! whose discriminant `(1 - s) a^2 + s b^2` is a sum of two non-negative terms (the expanded
//! `a^2 + 2 (b - a) M` cancels when `b < a`), and whose denominator adds two non-negative numbers.
//! Every operation is therefore accurate to a few ulps whatever `a`, `b` and `s` are: flat
//! segments give `t = s` exactly, `a = 0` gives `t = sqrt(s)`, and values are first divided by
//! `max(a, b)` so that squares can neither overflow nor lose the larger end.
//!
//! To make `sample` provably monotone in `u` (so stratified and low-discrepancy sequences keep
//! their structure) the formula is evaluated after dividing numerator and denominator by `s`:
//! `t = (a + b) / (a r + sqrt(r ((1 - s) r a^2 + b^2)))` with `r = 1 / s`. Every operation in the
//! denominator is a correctly rounded, monotone function of `s` (`r` falls as `s` grows, and all
//! terms are non-negative), so the computed `t` is non-decreasing in `s`. For `s < 2^-500`, where
//! `r^2` could overflow, the root is split as `sqrt(r) sqrt(...)` and capped by the value at
//! `2^-500`, which keeps the whole function monotone.

use rand::{Rng, RngExt, distr::Distribution};
use serde::{Deserialize, Serialize};

use crate::table::{
    Cdf, exponent, first_float_where, last_float_where, ldexp, unit, validate_grid,
    validate_nonnegative,
};
use crate::{GridLocator, SamplingError};

/// One linear segment, with everything `sample` needs in one 64-byte cache line.
#[derive(Debug, Clone, Copy, PartialEq)]
#[repr(align(64))]
struct Segment {
    x0: f64,
    width: f64,
    /// Density at `x0` divided by `max(density at x0, density at x1)`; in `[0, 1]`.
    alpha: f64,
    /// Density at `x1` divided by the same; in `[0, 1]`, and `max(alpha, beta) == 1` unless both
    /// ends are zero.
    beta: f64,
    /// Smallest sample value: `x0`, or the first float above it with a positive density.
    lo: f64,
    /// Largest sample value: `x1`, or the last float below it with a positive density.
    hi: f64,
    /// Rescaled cumulative mass at the segment's start (the CDF table's lower edge).
    mass_lo: f64,
    /// `1 / (rescaled mass of the segment)`, so the in-segment fraction is one multiplication.
    inv_mass: f64,
}

/// A continuous distribution whose density is linear between the points `(xs[i], ys[i])` of an
/// irregular, strictly increasing grid, sampled exactly by inverting its CDF.
///
/// The segment is chosen by bisection over the cumulative segment masses; inside it the quadratic
/// is solved in a cancellation-free form (see the module documentation). No sample ever lands where
/// `pdf` is zero: zero-mass segments are never chosen (nor segments whose normalised density
/// underflows), and a sample that would land on a zero end of a chosen segment is moved to the
/// nearest float inside it where the density is positive.
///
/// # Example
/// ```
/// use spectrace_sampling::PiecewiseLinear;
/// // A triangle on [0, 2] peaking at 1.
/// let d = PiecewiseLinear::new(&[0.0, 1.0, 2.0], &[0.0, 1.0, 0.0]).unwrap();
/// assert_eq!(d.integral(), 1.0);
/// assert!((d.sample(0.5) - 1.0).abs() < 1e-15);
/// assert!((d.cdf(d.sample(0.125)) - 0.125).abs() < 1e-15);
/// assert_eq!(d.pdf(0.5), 0.5);
/// ```
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "PiecewiseLinearRepr", into = "PiecewiseLinearRepr")]
pub struct PiecewiseLinear {
    xs: Vec<f64>,
    ys: Vec<f64>,
    /// `ys` times `2^-ey`, so the largest is in `[1, 2)`.
    ys_scaled: Vec<f64>,
    segments: Vec<Segment>,
    cdf: Cdf,
    /// Raw integral of the unnormalised density.
    integral: f64,
    /// `pdf(x) = interpolated ys_scaled(x) * pdf_factor`, computed without overflow.
    pdf_factor: f64,
    /// Finds the segment of a point (in `O(1)` on evenly spaced grids).
    locator: GridLocator,
}

/// The serialised form of a [`PiecewiseLinear`]: its grid and values.
#[derive(Serialize, Deserialize)]
struct PiecewiseLinearRepr {
    xs: Vec<f64>,
    ys: Vec<f64>,
}

impl TryFrom<PiecewiseLinearRepr> for PiecewiseLinear {
    type Error = SamplingError;
    fn try_from(repr: PiecewiseLinearRepr) -> Result<Self, SamplingError> {
        Self::new(&repr.xs, &repr.ys)
    }
}

impl From<PiecewiseLinear> for PiecewiseLinearRepr {
    fn from(d: PiecewiseLinear) -> Self {
        Self { xs: d.xs, ys: d.ys }
    }
}

impl PiecewiseLinear {
    /// Builds the generator from grid points `xs` (strictly increasing) and non-negative density
    /// values `ys` (unnormalised).
    ///
    /// # Errors
    /// [`SamplingError::Empty`], [`SamplingError::LengthMismatch`], [`SamplingError::TooFewPoints`];
    /// [`SamplingError::NaN`] / [`SamplingError::Infinite`] for `xs` or `ys`,
    /// [`SamplingError::Negative`] for `ys`, [`SamplingError::NotIncreasing`] for `xs`, each naming
    /// the index; [`SamplingError::SpanOverflow`], [`SamplingError::ZeroTotal`],
    /// [`SamplingError::TotalOverflow`], [`SamplingError::TotalUnderflow`] and
    /// [`SamplingError::DensityOverflow`] for tables whose
    /// integral or normalised density cannot be represented.
    pub fn new(xs: &[f64], ys: &[f64]) -> Result<Self, SamplingError> {
        if xs.is_empty() {
            return Err(SamplingError::Empty { array: "xs" });
        }
        if xs.len() != ys.len() {
            return Err(SamplingError::LengthMismatch {
                first: "xs",
                first_len: xs.len(),
                second: "ys",
                second_len: ys.len(),
                expected: "equal lengths",
            });
        }
        if xs.len() < 2 {
            return Err(SamplingError::TooFewPoints { array: "xs", len: xs.len() });
        }
        validate_grid("xs", xs)?;
        let max_y = validate_nonnegative("ys", ys)?;
        if max_y <= 0.0 {
            return Err(SamplingError::ZeroTotal { array: "ys" });
        }
        // Values rescaled by 2^-ey so the largest is in [1, 2); widths by 2^-2 only if a mass
        // could otherwise overflow (w * (a + b) / 2 <= 2 w).
        let ey = exponent(max_y);
        let max_width = xs.windows(2).map(|p| p[1] - p[0]).fold(0.0_f64, f64::max);
        let ew = if max_width > f64::MAX / 4.0 { 2 } else { 0 };
        let mut segments = Vec::with_capacity(xs.len() - 1);
        let mut masses = Vec::with_capacity(xs.len() - 1);
        let mut max_mass = 0.0_f64;
        for (i, x) in xs.windows(2).enumerate() {
            let (a, b) = (ldexp(ys[i], -ey), ldexp(ys[i + 1], -ey));
            let width = x[1] - x[0];
            let mass = ldexp(width, -ew) * ((a + b) * 0.5);
            max_mass = max_mass.max(mass);
            masses.push(mass);
            let m = a.max(b);
            let (alpha, beta) = if m > 0.0 { (a / m, b / m) } else { (0.0, 0.0) };
            segments.push(Segment {
                x0: x[0],
                width,
                alpha,
                beta,
                lo: x[0],
                hi: x[1],
                mass_lo: 0.0,
                inv_mass: 0.0,
            });
        }
        let mut cdf = Cdf::new("ys", &masses, max_mass)?;
        let ys_scaled: Vec<f64> = ys.iter().map(|&y| ldexp(y, -ey)).collect();
        // pdf(x) = y(x) / integral = y_scaled(x) / (sum of masses) * 2^-ew, where y_scaled <= 2.
        let mut pdf_factor = ldexp(1.0 / cdf.total(), -ew);
        if let Some(index) = ys_scaled.iter().position(|&y| !(y * pdf_factor).is_finite()) {
            return Err(SamplingError::DensityOverflow { array: "ys", index });
        }
        // A segment whose normalised density underflows to zero everywhere carries no
        // representable probability: drop its mass, so no sample lands where `pdf` says zero.
        let mut dropped = false;
        for (i, mass) in masses.iter_mut().enumerate() {
            if *mass > 0.0 && ys_scaled[i].max(ys_scaled[i + 1]) * pdf_factor == 0.0 {
                *mass = 0.0;
                dropped = true;
            }
        }
        if dropped {
            cdf = Cdf::new("ys", &masses, max_mass)?;
            pdf_factor = ldexp(1.0 / cdf.total(), -ew);
        }
        // Where a segment's density reaches zero (a zero end, or values that underflow once
        // normalised), keep samples on the floats where `pdf` is positive.
        for (i, seg) in segments.iter_mut().enumerate() {
            let (mass_lo, mass_hi) = cdf.bounds(i);
            seg.mass_lo = mass_lo;
            seg.inv_mass = if mass_hi > mass_lo { 1.0 / (mass_hi - mass_lo) } else { 0.0 };
            let (a, b) = (ys_scaled[i], ys_scaled[i + 1]);
            let density = |x: f64| {
                segment_density(a, b, ((x - seg.x0) / seg.width).clamp(0.0, 1.0)) * pdf_factor
            };
            if masses[i] > 0.0 {
                if density(seg.x0) == 0.0 {
                    seg.lo = first_float_where(seg.x0, xs[i + 1], |x| density(x) > 0.0);
                }
                if density(xs[i + 1]) == 0.0 {
                    seg.hi = last_float_where(seg.lo, xs[i + 1], |x| density(x) > 0.0);
                }
            }
        }
        let integral = ldexp(cdf.total(), ey + ew);
        if !integral.is_finite() {
            return Err(SamplingError::TotalOverflow { array: "ys" });
        }
        if integral == 0.0 {
            return Err(SamplingError::TotalUnderflow { array: "ys" });
        }
        Ok(Self {
            xs: xs.to_vec(),
            ys: ys.to_vec(),
            ys_scaled,
            segments,
            cdf,
            integral,
            pdf_factor,
            locator: GridLocator::new(xs),
        })
    }

    /// Maps a uniform `u` in `[0, 1)` to a point of the support; non-decreasing in `u`.
    ///
    /// `u` outside `[0, 1)` or NaN is a caller bug: it panics in debug builds and is clamped in
    /// release builds.
    #[inline]
    pub fn sample(&self, u: f64) -> f64 {
        self.invert(unit(u))
    }

    #[inline(always)]
    fn invert(&self, u: f64) -> f64 {
        let (i, target) = self.cdf.locate(u);
        let seg = &self.segments[i];
        // Where in the segment's mass the target fell: monotone in `target` (a multiplication by
        // a positive constant), in [0, 1] after the clamp.
        let s = ((target - seg.mass_lo) * seg.inv_mass).min(1.0);
        let t = invert_linear_segment(seg.alpha, seg.beta, s);
        // Clamping to [lo, hi] keeps the result inside the segment and off any zero-density end
        // (a monotone operation, so `sample` stays monotone).
        (seg.x0 + t * seg.width).clamp(seg.lo, seg.hi)
    }

    /// The normalised density at `x` (0 outside the support).
    #[inline]
    pub fn pdf(&self, x: f64) -> f64 {
        match self.locate(x) {
            Some((i, t)) => {
                segment_density(self.ys_scaled[i], self.ys_scaled[i + 1], t) * self.pdf_factor
            }
            None => 0.0,
        }
    }

    /// The cumulative distribution function at `x`: 0 below the support, 1 above it.
    #[inline]
    pub fn cdf(&self, x: f64) -> f64 {
        if x.is_nan() {
            return f64::NAN;
        }
        if x <= self.xs[0] {
            return 0.0;
        }
        if x >= self.xs[self.xs.len() - 1] {
            return 1.0;
        }
        match self.locate(x) {
            Some((i, t)) => {
                let seg = &self.segments[i];
                let (a, b) = (seg.alpha, seg.beta);
                // Fraction of the segment's mass below t: t (a (2 - t) + b t) / (a + b).
                let fraction =
                    if a + b > 0.0 { t * (a * (2.0 - t) + b * t) / (a + b) } else { 0.0 };
                self.cdf.cdf_at(i, fraction.min(1.0))
            }
            None => 0.0,
        }
    }

    /// Segment index and position `t` in `[0, 1]` of `x`, or `None` outside the support.
    #[inline]
    fn locate(&self, x: f64) -> Option<(usize, f64)> {
        let n = self.xs.len();
        if !(x >= self.xs[0] && x <= self.xs[n - 1]) {
            return None;
        }
        let i = self.locator.last_at_or_below(&self.xs, x).min(n - 2);
        let seg = &self.segments[i];
        Some((i, ((x - seg.x0) / seg.width).clamp(0.0, 1.0)))
    }

    /// The integral of the unnormalised density (the table as given).
    #[inline]
    pub fn integral(&self) -> f64 {
        self.integral
    }

    /// The support `(xs[0], xs[last])`.
    #[inline]
    pub fn range(&self) -> (f64, f64) {
        (self.xs[0], self.xs[self.xs.len() - 1])
    }

    /// The grid points.
    #[inline]
    pub fn xs(&self) -> &[f64] {
        &self.xs
    }

    /// The unnormalised density values at the grid points.
    #[inline]
    pub fn ys(&self) -> &[f64] {
        &self.ys
    }
}

/// Inverts the CDF of one linear segment: given end densities `a`, `b` (non-negative, not both
/// zero) and a fraction `s` in `[0, 1]` of the segment's mass, returns the position `t` in `[0, 1]`
/// with `a t + (b - a) t^2 / 2 = s (a + b) / 2`. Cancellation-free, no division by the slope, and
/// non-decreasing in `s` (the in-segment step of [`PiecewiseLinear::sample`]).
///
/// Useful as the first guess of an inverse-CDF sampler for a smooth density tabulated on a grid.
pub fn linear_segment_inverse(a: f64, b: f64, s: f64) -> f64 {
    let m = a.max(b);
    if !(m > 0.0 && m.is_finite()) || s.is_nan() {
        return s.clamp(0.0, 1.0);
    }
    invert_linear_segment(a / m, b / m, s.clamp(0.0, 1.0))
}

/// The unnormalised density `a (1 - t) + b t` at position `t` of a segment: both terms are
/// non-negative, and the ends are exact.
#[inline(always)]
fn segment_density(a: f64, b: f64, t: f64) -> f64 {
    a * (1.0 - t) + b * t
}

/// Solves `alpha t + (beta - alpha) t^2 / 2 = s (alpha + beta) / 2` for `t` in `[0, 1]`, given
/// `max(alpha, beta) == 1` and `s` in `[0, 1]`, without dividing by the slope; the result is
/// non-decreasing in `s` (see the module documentation).
#[inline(always)]
pub(crate) fn invert_linear_segment(alpha: f64, beta: f64, s: f64) -> f64 {
    if alpha == 0.0 {
        // Density rising from zero: the CDF is s = t^2.
        return s.sqrt();
    }
    if s >= TINY_S {
        // r <= 2^500, so r * ((1 - s) r a^2 + b^2) <= 2^1001: one square root, no overflow.
        let r = 1.0 / s;
        let denominator = alpha * r + (r * ((1.0 - s) * r * (alpha * alpha) + beta * beta)).sqrt();
        ((alpha + beta) / denominator).min(1.0)
    } else {
        // Tiny s: split the square root so r^2 cannot overflow, and cap the result by the value
        // at TINY_S so the two branches together stay monotone.
        let r = 1.0 / s;
        if r.is_infinite() {
            // s is zero or subnormal: t rounds to zero against alpha > 0.
            return 0.0;
        }
        let denominator =
            alpha * r + r.sqrt() * ((1.0 - s) * r * (alpha * alpha) + beta * beta).sqrt();
        ((alpha + beta) / denominator).min(invert_linear_segment(alpha, beta, TINY_S))
    }
}

/// Below this in-segment fraction the inversion uses the overflow-safe two-root form.
const TINY_S: f64 = 3.054936363499605e-151; // 2^-500

impl Distribution<f64> for PiecewiseLinear {
    #[inline]
    fn sample<R: Rng + ?Sized>(&self, rng: &mut R) -> f64 {
        self.invert(rng.random::<f64>())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Four ulps of a number in [0, 1].
    const TOL: f64 = 4.0 * f64::EPSILON;

    #[test]
    fn inversion_of_flat_rising_and_falling_segments() {
        for s in [0.0, 1e-300, 1e-200, 1e-17, 0.1, 0.5, 0.9, 1.0] {
            let flat = invert_linear_segment(1.0, 1.0, s);
            assert!((flat - s).abs() <= TOL * s, "flat at s = {s}: {flat}");
            assert_eq!(invert_linear_segment(0.0, 1.0, s), s.sqrt(), "rising from 0 at s = {s}");
            // Falling to zero: CDF = 1 - (1 - t)^2, so t = 1 - sqrt(1 - s).
            let t = invert_linear_segment(1.0, 0.0, s);
            let expected = 1.0 - (1.0 - s).sqrt();
            assert!((t - expected).abs() <= TOL, "falling at s = {s}: {t} vs {expected}");
        }
    }

    #[test]
    fn inversion_is_exact_for_a_generic_slope() {
        // A steep segment, where the seed's textbook root (-a + sqrt(D)) / (b - a) is accurate and
        // serves as the reference.
        let (a, b) = (0.25_f64, 1.0_f64);
        for k in 0..=100 {
            let s = k as f64 / 100.0;
            let t = invert_linear_segment(a, b, s);
            let m = s * (a + b) / 2.0;
            let reference = (-a + (a * a + 2.0 * (b - a) * m).sqrt()) / (b - a);
            assert!((t - reference).abs() <= TOL, "s = {s}: {t} vs {reference}");
        }
    }

    #[test]
    fn inversion_is_monotone_across_the_tiny_branch_and_everywhere() {
        for (alpha, beta) in
            [(1.0, 1.0), (1.0, 0.0), (1.0, 1e-300), (0.3, 1.0), (1e-300, 1.0), (1.0, 0.7)]
        {
            let mut s = TINY_S;
            for _ in 0..64 {
                s = s.next_down();
            }
            let mut previous = 0.0;
            for _ in 0..128 {
                let t = invert_linear_segment(alpha, beta, s);
                assert!(t >= previous, "({alpha}, {beta}) at s = {s:e}: {t:e} < {previous:e}");
                previous = t;
                s = s.next_up();
            }
            let mut previous = 0.0;
            for k in 0..=100_000 {
                let s = k as f64 / 100_000.0;
                let t = invert_linear_segment(alpha, beta, s);
                assert!(t >= previous && t <= 1.0, "({alpha}, {beta}) at s = {s}");
                previous = t;
            }
        }
    }

    #[test]
    fn nearly_flat_segment_has_no_cancellation() {
        let (a, b) = (1.0, 1.0 - 1e-15);
        for s in [1e-10, 0.3, 0.999_999] {
            let t = invert_linear_segment(a, b, s);
            assert!((t - s).abs() < 1e-14 * s.max(1e-300) + 1e-15, "s = {s}: t = {t}");
        }
    }
}
