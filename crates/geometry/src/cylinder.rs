//! [`Cylinder`]: an open tube (no caps), e.g. the seed's ring.
//!
//! | field | unit | default | meaning |
//! |---|---|---|---|
//! | `center` | m, `[x, y, z]` | required | centre of the base circle |
//! | `axis` | m, `[x, y, z]` | required | direction from the base to the top; its length is the height unless `height` is given |
//! | `height` | m | length of `axis` | extent along the axis, > 0 |
//! | `radius` | m | required | finite, > 0 |
//! | `transform` | [`Transform`] | none | must be a similarity |
//!
//! ```json
//! {"type": "Cylinder", "center": [0, 0, 0], "axis": [0, 0.1, 0], "radius": 1}
//! ```
//!
//! The geometric normal points away from the axis (outwards); rays inside see it facing them.
//! `uv`: `u` = angle about the axis over `2 pi`, `v` = height over `height`. Robustness: the
//! quadratic in the plane perpendicular to the axis is solved as for [`crate::Sphere`]
//! (discriminant in vector form, no cancelling root); the hit is re-projected radially onto the
//! tube. A ray parallel to the axis never hits.

use std::f64::consts::PI;

use glam::{DVec2, DVec3};
use serde::{Deserialize, Serialize};
use spectrace_sampling::Frame;

use crate::disk::circle_extent;
use crate::float::{
    finite_point, gamma, positive, safe_length, stable_quadratic_roots, unit_direction,
};
use crate::shape::{Primitives, SurfacePoint, similarity};
use crate::{Bounds, GeometryError, Hit, Ray, Transform};

/// An open cylinder.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "CylinderRepr", into = "CylinderRepr")]
pub struct Cylinder {
    center: DVec3,
    frame: Frame,
    height: f64,
    radius: f64,
    repr: Box<CylinderRepr>,
}

/// Scene-file form of [`Cylinder`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct CylinderRepr {
    center: DVec3,
    axis: DVec3,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    height: Option<f64>,
    radius: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    transform: Option<Transform>,
}

impl TryFrom<CylinderRepr> for Cylinder {
    type Error = GeometryError;
    fn try_from(r: CylinderRepr) -> Result<Self, GeometryError> {
        const S: &str = "Cylinder";
        let center = finite_point(S, "center", r.center)?;
        let axis = unit_direction(S, "axis", r.axis)?;
        let height = match r.height {
            Some(h) => positive(S, "height", h)?,
            None => {
                let len = safe_length(r.axis);
                if !len.is_finite() {
                    return Err(GeometryError::parameter(
                        S,
                        "axis",
                        r.axis,
                        "too large: its length (the height) overflows; give a smaller axis or `height`",
                    ));
                }
                positive(S, "axis", len)?
            }
        };
        let radius = positive(S, "radius", r.radius)?;
        let t = r.transform.unwrap_or_default();
        let s = similarity(S, &t)?;
        let axis = unit_direction(S, "transform", t.vector(axis))?;
        Ok(Self {
            center: finite_point(S, "transform", t.point(center))?,
            frame: Frame::from_normal(axis),
            height: positive(S, "transform", height * s)?,
            radius: positive(S, "transform", radius * s)?,
            repr: Box::new(r),
        })
    }
}

impl From<Cylinder> for CylinderRepr {
    fn from(s: Cylinder) -> Self {
        *s.repr
    }
}

impl Cylinder {
    /// An open cylinder from the base circle at `center` along `axis` (normalised) for `height`.
    ///
    /// # Errors
    /// [`GeometryError::Parameter`] naming `center`, `axis`, `height` or `radius`.
    pub fn new(
        center: DVec3,
        axis: DVec3,
        height: f64,
        radius: f64,
    ) -> Result<Self, GeometryError> {
        CylinderRepr { center, axis, height: Some(height), radius, transform: None }.try_into()
    }

    /// Area of the side `2 pi r h` (m^2; the cylinder is open).
    pub(crate) fn area(&self) -> f64 {
        2.0 * PI * self.radius * self.height
    }

    /// A point uniform by area on the side (height `u0 h`, angle `2 pi u1`: the side unrolls to
    /// a rectangle), from uniforms already in `[0, 1)`; normal away from the axis.
    pub(crate) fn sample_area(&self, u: [f64; 3]) -> SurfacePoint {
        let fr = &self.frame;
        let phi = 2.0 * PI * u[1];
        let n = (fr.t() * phi.cos() + fr.b() * phi.sin()).normalize();
        let point = self.center + fr.n() * (u[0] * self.height) + n * self.radius;
        SurfacePoint { point, normal: n }
    }
}

impl Primitives for Cylinder {
    fn count(&self) -> usize {
        1
    }

    fn bounds(&self, _index: u32) -> Bounds {
        let e = circle_extent(self.frame.n(), self.radius);
        let top = self.center + self.frame.n() * self.height;
        Bounds { min: self.center.min(top) - e, max: self.center.max(top) + e }
    }

    fn hit_t(&self, _index: u32, ray: &Ray, t_max: f64) -> Option<f64> {
        self.solve(ray, t_max).map(|h| h.0)
    }

    fn intersect(&self, _index: u32, ray: &Ray, t_max: f64) -> Option<Hit> {
        let (t, z, n) = self.solve(ray, t_max)?;
        let (c, r, fr, h) = (self.center, self.radius, &self.frame, self.height);
        let along = fr.n() * z;
        let point = c + along + n * r;
        let error = (c.abs() + along.abs() + (n * r).abs()) * gamma(10);
        let phi = n.dot(fr.b()).atan2(n.dot(fr.t()));
        let phi = if phi < 0.0 { phi + 2.0 * PI } else { phi };
        Some(Hit {
            t,
            point,
            geometric_normal: n,
            shading_normal: n,
            uv: DVec2::new(phi / (2.0 * PI), (z / h).clamp(0.0, 1.0)),
            primitive: 0,
            triangle: 0,
            error,
        })
    }
}

impl Cylinder {
    /// The nearest crossing of the side in `(0, t_max)`: `(t, height along the axis, normal)`.
    #[inline]
    fn solve(&self, ray: &Ray, t_max: f64) -> Option<(f64, f64, DVec3)> {
        let (c, r, fr) = (self.center, self.radius, &self.frame);
        let o = fr.to_local(ray.origin - c);
        let d = fr.to_local(ray.direction);
        let (o2, d2) = (DVec2::new(o.x, o.y), DVec2::new(d.x, d.y));
        let a = d2.length_squared();
        if !(a > 0.0) {
            return None;
        }
        let b = o2.dot(d2);
        let l = (o2 - d2 * (b / a)).length();
        let disc = a * ((r - l) * (r + l));
        if !(disc >= 0.0) {
            return None;
        }
        let rho = o2.length();
        let cc = (rho - r) * (rho + r);
        let (t0, t1) = stable_quadratic_roots(a, b, cc, disc);
        let h = self.height;
        let t = [t0, t1].into_iter().find(|&t| {
            let z = o.z + t * d.z;
            t > 0.0 && t < t_max && (0.0..=h).contains(&z)
        })?;
        let q = ray.at(t) - c;
        let z = q.dot(fr.n());
        let radial = q - fr.n() * z;
        let len = radial.length();
        if !(len > 0.0) {
            return None;
        }
        Some((t, z, radial / len))
    }
}
