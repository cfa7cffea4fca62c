//! Floating-point helpers: error bounds (`gamma`), outward rounding, validation, frames.

use glam::DVec3;

use crate::GeometryError;

/// Unit roundoff of f64 (half an ulp of 1).
const MACHINE_EPSILON: f64 = f64::EPSILON * 0.5;

/// Higham's bound `n u / (1 - n u)` on the relative error of `n` chained floating-point operations.
pub(crate) fn gamma(n: u32) -> f64 {
    let nu = f64::from(n) * MACHINE_EPSILON;
    nu / (1.0 - nu)
}

/// A finite point, or an error naming the field.
pub(crate) fn finite_point(
    shape: &'static str,
    field: &'static str,
    p: DVec3,
) -> Result<DVec3, GeometryError> {
    if p.is_finite() {
        Ok(p)
    } else {
        Err(GeometryError::parameter(shape, field, p, "must be finite"))
    }
}

/// The length of `v`, computed without overflow or underflow in the squares (scaled by its
/// largest component first): finite for any finite `v` whose length fits in an f64, infinite if
/// the length itself exceeds `f64::MAX`, NaN if `v` is not finite.
pub(crate) fn safe_length(v: DVec3) -> f64 {
    if !v.is_finite() {
        return f64::NAN;
    }
    let m = v.abs().max_element();
    if m == 0.0 { 0.0 } else { m * (v / m).length() }
}

/// A unit vector along `v`, or an error naming the field when `v` is zero or not finite. Any
/// finite non-zero vector is accepted however large or small its components: it is scaled by its
/// largest component before normalising, so the squares neither overflow nor underflow.
pub(crate) fn unit_direction(
    shape: &'static str,
    field: &'static str,
    v: DVec3,
) -> Result<DVec3, GeometryError> {
    if !v.is_finite() {
        return Err(GeometryError::parameter(shape, field, v, "must be finite"));
    }
    let m = v.abs().max_element();
    if m == 0.0 {
        return Err(GeometryError::parameter(shape, field, v, "must be non-zero (no direction)"));
    }
    let scaled = v / m;
    Ok(scaled / scaled.length())
}

/// A finite value `> 0`, or an error naming the field.
pub(crate) fn positive(
    shape: &'static str,
    field: &'static str,
    x: f64,
) -> Result<f64, GeometryError> {
    if x > 0.0 && x.is_finite() {
        Ok(x)
    } else {
        Err(GeometryError::parameter(shape, field, x, "must be finite and > 0"))
    }
}

/// The stable roots `t0 <= t1` of `a t^2 + 2 b t + c = 0` given the reduced discriminant
/// `disc = b^2 - a c >= 0` computed by the caller (in a cancellation-free form).
pub(crate) fn stable_quadratic_roots(a: f64, b: f64, c: f64, disc: f64) -> (f64, f64) {
    let q = -(b + b.signum() * disc.sqrt());
    let (t0, t1) = if q == 0.0 { (0.0, 0.0) } else { (c / q, q / a) };
    if t0 <= t1 { (t0, t1) } else { (t1, t0) }
}

/// The largest f64 below 1 (`1 - 2^-53`).
const ONE_MINUS_EPSILON: f64 = 1.0 - f64::EPSILON / 2.0;

/// A uniform variate clamped into `[0, 1)`: NaN and negative values become 0, values `>= 1`
/// become `1 - 2^-53`; values already in `[0, 1)` are unchanged. Never panics.
pub(crate) fn unit_uniform(u: f64) -> f64 {
    if u >= 0.0 { u.min(ONE_MINUS_EPSILON) } else { 0.0 }
}
