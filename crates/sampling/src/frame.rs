//! An orthonormal frame around a unit normal, for moving directions between a local space (the
//! normal along `+z`) and the world.

use glam::DVec3;

/// A right-handed orthonormal frame `(t, b, n)` with `t x b = n`, built around a unit normal `n`.
///
/// The construction is Duff et al.'s "Building an orthonormal basis, revisited" (JCGT 2017):
/// branch-free apart from the sign of `n.z`, no division that can overflow (the divisor
/// `sign(n.z) + n.z` is at least 1), and orthonormal to rounding for every unit `n`, including
/// `(0, 0, -1)` and normals with tiny or subnormal components. It is continuous everywhere except
/// where `n.z` changes sign.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    t: DVec3,
    b: DVec3,
    n: DVec3,
}

impl Frame {
    /// The frame around the unit vector `n` (not renormalised: pass a unit vector).
    #[inline]
    pub fn from_normal(n: DVec3) -> Self {
        let sign = 1.0_f64.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        let t = DVec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let bt = DVec3::new(b, sign + n.y * n.y * a, -n.y);
        Self { t, b: bt, n }
    }

    /// The frame around the unit vector `n` whose first tangent is `tangent` made orthogonal to
    /// `n` (Gram-Schmidt), so that a shape's local `+x` follows its transform; the frame of
    /// [`from_normal`](Self::from_normal) when `tangent` is (nearly) parallel to `n` or not
    /// finite.
    pub fn from_normal_and_tangent(n: DVec3, tangent: DVec3) -> Self {
        let t = tangent - n * tangent.dot(n);
        let len = t.length();
        if len > 1e-9 && len.is_finite() {
            let t = t / len;
            Self { t, b: n.cross(t), n }
        } else {
            Self::from_normal(n)
        }
    }

    /// The first tangent (local `+x`).
    #[inline]
    pub fn t(&self) -> DVec3 {
        self.t
    }

    /// The second tangent (local `+y`), `n x t`.
    #[inline]
    pub fn b(&self) -> DVec3 {
        self.b
    }

    /// The normal (local `+z`), as given.
    #[inline]
    pub fn n(&self) -> DVec3 {
        self.n
    }

    /// The world vector with local coordinates `local`: `t local.x + b local.y + n local.z`.
    #[inline]
    pub fn to_world(&self, local: DVec3) -> DVec3 {
        self.t * local.x + self.b * local.y + self.n * local.z
    }

    /// The local coordinates of the world vector `v`: its dot products with `t`, `b` and `n`.
    #[inline]
    pub fn to_local(&self, v: DVec3) -> DVec3 {
        DVec3::new(v.dot(self.t), v.dot(self.b), v.dot(self.n))
    }
}
