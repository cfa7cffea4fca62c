//! Small geometric helpers shared by the lights: validation of vectors, an orthonormal frame, and
//! the warps from uniforms to directions and points.

use std::f64::consts::{PI, TAU};

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

/// An orthonormal frame `(t, b, n)` around a unit normal `n` (Duff et al., "Building an
/// orthonormal basis, revisited", 2017: branch-free and continuous except at one point).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Frame {
    pub(crate) t: DVec3,
    pub(crate) b: DVec3,
    pub(crate) n: DVec3,
}

impl Frame {
    pub(crate) fn new(n: DVec3) -> Self {
        let sign = 1.0_f64.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        let t = DVec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let bt = DVec3::new(b, sign + n.y * n.y * a, -n.y);
        Self { t, b: bt, n }
    }

    /// The world vector with local coordinates `(x, y, z)`.
    #[inline]
    pub(crate) fn local_to_world(&self, x: f64, y: f64, z: f64) -> DVec3 {
        self.t * x + self.b * y + self.n * z
    }
}

/// A direction with the given cosine to the frame's normal and azimuth `2 pi u`, renormalised.
#[inline]
pub(crate) fn direction_from_cos(frame: &Frame, cos_theta: f64, u: f64) -> DVec3 {
    // sin from (1 - c)(1 + c): accurate near c = 1, where 1 - c^2 cancels.
    let sin_theta = ((1.0 - cos_theta) * (1.0 + cos_theta)).max(0.0).sqrt();
    let phi = TAU * u;
    frame.local_to_world(sin_theta * phi.cos(), sin_theta * phi.sin(), cos_theta).normalize()
}

/// A point uniform on the unit disk (Shirley and Chiu's concentric map), as `(x, y)`.
#[inline]
pub(crate) fn concentric_disk(u1: f64, u2: f64) -> (f64, f64) {
    let (a, b) = (2.0 * u1 - 1.0, 2.0 * u2 - 1.0);
    if a == 0.0 && b == 0.0 {
        return (0.0, 0.0);
    }
    let (r, phi) = if a.abs() > b.abs() {
        (a, PI / 4.0 * (b / a))
    } else {
        (b, PI / 2.0 - PI / 4.0 * (a / b))
    };
    (r * phi.cos(), r * phi.sin())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_are_orthonormal_for_every_normal() {
        for n in [
            DVec3::X,
            DVec3::Y,
            DVec3::Z,
            -DVec3::Z,
            DVec3::new(1.0, -2.0, 0.5).normalize(),
            DVec3::new(0.0, 1e-9, -1.0).normalize(),
        ] {
            let f = Frame::new(n);
            for (a, b) in [(f.t, f.b), (f.b, f.n), (f.t, f.n)] {
                assert!(a.dot(b).abs() < 1e-12, "{n:?}");
            }
            for v in [f.t, f.b, f.n] {
                assert!((v.length() - 1.0).abs() < 1e-12);
            }
            assert!(f.t.cross(f.b).dot(f.n) > 0.999_999, "right-handed for {n:?}");
        }
    }

    #[test]
    fn concentric_map_stays_in_the_disk() {
        for i in 0..=20 {
            for j in 0..=20 {
                let (x, y) = concentric_disk(i as f64 / 20.0, j as f64 / 20.0);
                assert!(x * x + y * y <= 1.0 + 1e-12);
            }
        }
    }
}
