//! Small geometric helpers: clamping uniforms, an orthonormal frame, cosine-weighted directions.

use glam::DVec3;
use spectrace_sampling::ONE_MINUS_EPSILON;

/// Clamps a uniform into `[0, 1)` (NaN becomes 0).
#[inline]
pub(crate) fn unit_uniform(u: f64) -> f64 {
    if u >= 0.0 { u.min(ONE_MINUS_EPSILON) } else { 0.0 }
}

/// `normal` turned to face against `direction` (towards where the beam came from). A beam
/// exactly tangent (`direction . normal == 0`) keeps the normal as given.
#[inline]
pub(crate) fn facing(direction: DVec3, normal: DVec3) -> DVec3 {
    if direction.dot(normal) > 0.0 { -normal } else { normal }
}

/// An orthonormal frame `(t, b, n)` around a unit `n` (Duff et al. 2017, branch-free).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Frame {
    t: DVec3,
    b: DVec3,
    n: DVec3,
}

impl Frame {
    #[inline]
    pub(crate) fn new(n: DVec3) -> Self {
        let sign = 1.0_f64.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        let t = DVec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let bt = DVec3::new(b, sign + n.y * n.y * a, -n.y);
        Self { t, b: bt, n }
    }

    #[inline]
    pub(crate) fn to_world(self, x: f64, y: f64, z: f64) -> DVec3 {
        self.t * x + self.b * y + self.n * z
    }
}

/// A cosine-weighted direction around unit `n` from two uniforms in `[0, 1)`, with its cosine
/// to `n`. Malley's method with the polar map: `cos theta = sqrt(1 - u1)`, which is > 0 for every
/// `u1 < 1`, so the sampled direction is never tangent and its pdf never 0.
#[inline]
pub(crate) fn cosine_hemisphere(n: DVec3, u1: f64, u2: f64) -> (DVec3, f64) {
    let r = u1.sqrt();
    let cos_theta = (1.0 - u1).sqrt();
    let (s, c) = (std::f64::consts::TAU * u2).sin_cos();
    let d = Frame::new(n).to_world(r * c, r * s, cos_theta);
    (normalise(d), cos_theta)
}

/// Renormalises a vector that is unit to within rounding (removes accumulated error).
#[inline]
pub(crate) fn normalise(d: DVec3) -> DVec3 {
    let len2 = d.length_squared();
    if len2 > 0.0 && len2.is_finite() { d / len2.sqrt() } else { d }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_is_orthonormal_for_awkward_normals() {
        for n in [
            DVec3::Z,
            DVec3::NEG_Z,
            DVec3::X,
            DVec3::new(0.0, 0.0, -0.0) + DVec3::NEG_Z,
            DVec3::new(1e-9, -1e-9, -1.0).normalize(),
            DVec3::new(0.6, 0.0, 0.8),
        ] {
            let f = Frame::new(n);
            for (a, b) in [(f.t, f.b), (f.b, f.n), (f.t, f.n)] {
                assert!(a.dot(b).abs() < 1e-12, "{n}");
            }
            for v in [f.t, f.b] {
                assert!((v.length() - 1.0).abs() < 1e-12, "{n}");
            }
            assert!((f.t.cross(f.b) - n).length() < 1e-12, "right-handed for {n}");
        }
    }

    #[test]
    fn cosine_directions_are_never_tangent() {
        let (d, cos) = cosine_hemisphere(DVec3::Y, ONE_MINUS_EPSILON, 0.25);
        assert!(cos > 0.0 && d.y > 0.0 && (d.length() - 1.0).abs() < 1e-15);
        let (d, cos) = cosine_hemisphere(DVec3::Y, 0.0, 0.0);
        assert_eq!((d, cos), (DVec3::Y, 1.0));
        assert_eq!(unit_uniform(f64::NAN), 0.0);
        assert_eq!(unit_uniform(1.0), ONE_MINUS_EPSILON);
    }
}
