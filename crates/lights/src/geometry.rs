//! Small geometric helpers shared by the lights: validation of points, directions and scalars.
//! (The orthonormal frame and the warps from uniforms to points and directions are
//! `spectrace_sampling::Frame` and `spectrace_sampling::warp`, shared with the materials.)

use glam::DVec3;

use crate::LightError;

/// Checks that a point is finite.
pub(crate) fn finite_point(
    light: &'static str,
    field: &'static str,
    p: DVec3,
) -> Result<DVec3, LightError> {
    if p.is_finite() {
        Ok(p)
    } else {
        Err(LightError::parameter(light, field, p.to_array(), "must be finite"))
    }
}

/// Normalises a direction. Any finite non-zero vector is accepted, however large or small its
/// components: it is scaled by its largest component first, so the squares neither overflow nor
/// underflow. Zero and non-finite vectors are refused, saying which.
pub(crate) fn unit_direction(
    light: &'static str,
    field: &'static str,
    d: DVec3,
) -> Result<DVec3, LightError> {
    if !d.is_finite() {
        return Err(LightError::parameter(light, field, d.to_array(), "must be finite"));
    }
    let m = d.abs().max_element();
    if m == 0.0 {
        return Err(LightError::parameter(
            light,
            field,
            d.to_array(),
            "must be non-zero (no direction)",
        ));
    }
    // Already unit (to rounding): keep it bit for bit, so saving and reloading a light
    // reproduces it exactly.
    if (d.length() - 1.0).abs() <= 4.0 * f64::EPSILON {
        return Ok(d);
    }
    let scaled = d / m;
    Ok(scaled / scaled.length())
}

/// The length of a finite `v` without overflow or underflow in the squares (infinite only if the
/// length itself exceeds `f64::MAX`).
pub(crate) fn safe_length(v: DVec3) -> f64 {
    let m = v.abs().max_element();
    if m == 0.0 || !m.is_finite() { m } else { m * (v / m).length() }
}

/// Checks a non-negative finite scalar.
pub(crate) fn non_negative(
    light: &'static str,
    field: &'static str,
    v: f64,
) -> Result<f64, LightError> {
    if v >= 0.0 && v.is_finite() {
        Ok(v)
    } else {
        Err(LightError::parameter(light, field, v, "must be finite and >= 0"))
    }
}

/// Checks a positive finite scalar.
pub(crate) fn positive(
    light: &'static str,
    field: &'static str,
    v: f64,
) -> Result<f64, LightError> {
    if v > 0.0 && v.is_finite() {
        Ok(v)
    } else {
        Err(LightError::parameter(light, field, v, "must be finite and > 0"))
    }
}
