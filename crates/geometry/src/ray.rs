//! [`Ray`] and [`Hit`], and the robust spawning of a new ray from a hit.
//!
//! Every hit carries `error`, a conservative per-axis bound on the floating-point error of
//! `point`: the true intersection lies in the box `point +- error`. [`Hit::spawn_ray`] moves the
//! new origin just outside that box along the geometric normal, on the side the new direction
//! leaves into, then rounds once more away from the surface. The surface therefore lies strictly
//! behind the new ray, so it cannot be hit again at `t ~ 0` ("shadow acne") without a fixed epsilon
//! that would be too big near the origin and too small far from it.

use glam::{DVec2, DVec3};

/// A ray `origin + t direction`, `t >= 0`, with a unit direction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ray {
    /// Where the ray starts (m).
    pub origin: DVec3,
    /// Unit direction.
    pub direction: DVec3,
}

impl Ray {
    /// A ray from `origin` along `direction` (normalised here; a zero direction gives NaNs).
    pub fn new(origin: DVec3, direction: DVec3) -> Self {
        Self { origin, direction: direction.normalize() }
    }

    /// The point at parameter `t`.
    pub fn at(&self, t: f64) -> DVec3 {
        self.origin + self.direction * t
    }
}

/// Where a ray meets a surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// Ray parameter of the hit (distance along the unit direction, m).
    pub t: f64,
    /// The hit point (m), on the surface up to `error`.
    pub point: DVec3,
    /// Unit normal of the true surface, pointing to the shape's outward side (for meshes: the
    /// counter-clockwise side, `(p1 - p0) x (p2 - p0)`), whatever side the ray came from.
    pub geometric_normal: DVec3,
    /// Unit shading normal (interpolated vertex normals for meshes that have them, else the
    /// geometric normal), on the same side as `geometric_normal`.
    pub shading_normal: DVec3,
    /// Surface parameters in `[0, 1]^2` (see each shape's documentation).
    pub uv: DVec2,
    /// Index of the shape in the list given to [`crate::World::new`].
    pub primitive: u32,
    /// Index of the triangle within a mesh shape (0 for analytic shapes).
    pub triangle: u32,
    /// Conservative absolute error bound on `point`, per axis (m).
    pub error: DVec3,
}

impl Hit {
    /// Whether the ray arrived on the outward side (against `geometric_normal`).
    pub fn front_face(&self, ray: &Ray) -> bool {
        ray.direction.dot(self.geometric_normal) < 0.0
    }

    /// The origin for a new ray leaving the surface along `direction`: `point` offset along the
    /// geometric normal by `dot(|n|, error)` to the side `direction` points into, then rounded one
    /// more ulp away from the surface (pbrt's offset-ray-origin construction).
    pub fn spawn_origin(&self, direction: DVec3) -> DVec3 {
        let n = self.geometric_normal;
        let d = n.abs().dot(self.error);
        let mut offset = n * d;
        if direction.dot(n) < 0.0 {
            offset = -offset;
        }
        let p = self.point + offset;
        let round = |x: f64, o: f64| {
            if o > 0.0 {
                x.next_up()
            } else if o < 0.0 {
                x.next_down()
            } else {
                x
            }
        };
        DVec3::new(round(p.x, offset.x), round(p.y, offset.y), round(p.z, offset.z))
    }

    /// A new ray leaving the surface along `direction` (normalised here) from
    /// [`Hit::spawn_origin`], so it cannot spuriously re-hit this surface at `t ~ 0`.
    pub fn spawn_ray(&self, direction: DVec3) -> Ray {
        let direction = direction.normalize();
        Ray { origin: self.spawn_origin(direction), direction }
    }

    /// A ray towards `target` (e.g. a light sample), from [`Hit::spawn_origin`]; returns the ray
    /// and the distance to `target` along it, for [`crate::World::occluded`].
    pub fn spawn_ray_to(&self, target: DVec3) -> (Ray, f64) {
        let origin = self.spawn_origin(target - self.point);
        let to = target - origin;
        let distance = to.length();
        (Ray { origin, direction: to / distance }, distance)
    }
}
