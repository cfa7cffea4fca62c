//! [`Disk`]: a flat disk with a centre, a normal and a radius.
//!
//! | field | unit | default | meaning |
//! |---|---|---|---|
//! | `center` | m, `[x, y, z]` | required | centre |
//! | `normal` | `[x, y, z]` | required | the outward side (normalised; non-zero) |
//! | `radius` | m | required | finite, > 0 |
//! | `transform` | [`Transform`] | none | must be a similarity |
//!
//! ```json
//! {"type": "Disk", "center": [0, 0, 0], "normal": [0, 1, 0], "radius": 2}
//! ```
//!
//! `uv`: `u` = angle about the normal over `2 pi`, `v` = distance from the centre over the radius.
//! Same plane robustness as [`crate::Rectangle`].

use std::f64::consts::PI;

use glam::{DVec2, DVec3};
use serde::{Deserialize, Serialize};
use spectrace_sampling::Frame;

use crate::float::{finite_point, positive, unit_direction};
use crate::rectangle::{plane_error, plane_hit};
use crate::shape::{Primitives, SurfacePoint, similarity};
use crate::{Bounds, GeometryError, Hit, Ray, Transform};

/// A disk.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "DiskRepr", into = "DiskRepr")]
pub struct Disk {
    center: DVec3,
    radius: f64,
    frame: Frame,
    repr: Box<DiskRepr>,
}

/// Scene-file form of [`Disk`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct DiskRepr {
    center: DVec3,
    normal: DVec3,
    radius: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    transform: Option<Transform>,
}

impl TryFrom<DiskRepr> for Disk {
    type Error = GeometryError;
    fn try_from(r: DiskRepr) -> Result<Self, GeometryError> {
        const S: &str = "Disk";
        let center = finite_point(S, "center", r.center)?;
        let normal = unit_direction(S, "normal", r.normal)?;
        let radius = positive(S, "radius", r.radius)?;
        let t = r.transform.unwrap_or_default();
        let s = similarity(S, &t)?;
        let normal = unit_direction(S, "transform", t.normal(normal))?;
        let center = finite_point(S, "transform", t.point(center))?;
        let radius = positive(S, "transform", radius * s)?;
        Ok(Self { center, radius, frame: Frame::from_normal(normal), repr: Box::new(r) })
    }
}

impl From<Disk> for DiskRepr {
    fn from(s: Disk) -> Self {
        *s.repr
    }
}

impl Disk {
    /// A disk of `radius` around `center` facing `normal`.
    ///
    /// # Errors
    /// [`GeometryError::Parameter`] naming `center`, `normal` or `radius`.
    pub fn new(center: DVec3, normal: DVec3, radius: f64) -> Result<Self, GeometryError> {
        DiskRepr { center, normal, radius, transform: None }.try_into()
    }

    /// Unit normal.
    pub fn normal(&self) -> DVec3 {
        self.frame.n()
    }

    /// Area `pi r^2` (m^2).
    pub(crate) fn area(&self) -> f64 {
        PI * self.radius * self.radius
    }

    /// A point uniform by area (`rho = r sqrt(u0)`, angle `2 pi u1`), from uniforms already in
    /// `[0, 1)`; normal the front face's.
    pub(crate) fn sample_area(&self, u: [f64; 3]) -> SurfacePoint {
        let rho = self.radius * u[0].sqrt();
        let phi = 2.0 * PI * u[1];
        let offset = self.frame.to_world(DVec3::new(rho * phi.cos(), rho * phi.sin(), 0.0));
        SurfacePoint { point: self.center + offset, normal: self.frame.n() }
    }
}

impl Disk {
    /// The plane crossing inside the radius: `(t, point, local point, rho)`.
    #[inline]
    fn solve(&self, ray: &Ray, t_max: f64) -> Option<(f64, DVec3, DVec3, f64)> {
        let (t, point) = plane_hit(self.center, self.frame.n(), ray, t_max)?;
        let local = self.frame.to_local(point - self.center);
        let rho = local.x.hypot(local.y);
        if !(rho <= self.radius) {
            return None;
        }
        Some((t, point, local, rho))
    }
}

/// Half-extents of a circle of `radius` with unit `normal`, per axis: `r sqrt(1 - n_i^2)`.
pub(crate) fn circle_extent(normal: DVec3, radius: f64) -> DVec3 {
    (DVec3::ONE - normal * normal).max(DVec3::ZERO).powf(0.5) * radius
}

impl Primitives for Disk {
    fn count(&self) -> usize {
        1
    }

    fn bounds(&self, _index: u32) -> Bounds {
        let e = circle_extent(self.frame.n(), self.radius);
        Bounds { min: self.center - e, max: self.center + e }
    }

    fn hit_t(&self, _index: u32, ray: &Ray, t_max: f64) -> Option<f64> {
        self.solve(ray, t_max).map(|s| s.0)
    }

    fn intersect(&self, _index: u32, ray: &Ray, t_max: f64) -> Option<Hit> {
        let (t, point, local, rho) = self.solve(ray, t_max)?;
        let error = plane_error(point, self.center);
        let phi = local.y.atan2(local.x);
        let phi = if phi < 0.0 { phi + 2.0 * PI } else { phi };
        Some(Hit {
            t,
            point,
            geometric_normal: self.frame.n(),
            shading_normal: self.frame.n(),
            uv: DVec2::new(phi / (2.0 * PI), rho / self.radius),
            primitive: 0,
            triangle: 0,
            error,
        })
    }
}
