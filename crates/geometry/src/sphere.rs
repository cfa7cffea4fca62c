//! [`Sphere`]: centre and radius, intersected with the numerically stable quadratic.
//!
//! | field | unit | default | meaning |
//! |---|---|---|---|
//! | `center` | m, `[x, y, z]` | required | centre, finite |
//! | `radius` | m | required | finite, > 0 |
//! | `transform` | [`Transform`] | none | applied to the sphere; must be a similarity (rotation, uniform scale, translation) |
//!
//! ```json
//! {"type": "Sphere", "center": [0, 1, 0], "radius": 0.5}
//! ```
//!
//! `uv`: `u` = azimuth about the pole (`+y`, rotated by the transform) from `+x`, over `2 pi`;
//! `v` = polar angle from the pole, over `pi`. The geometric normal points outwards.
//!
//! Robustness (Ray Tracing Gems, ch. 7, as in pbrt-v4): with `f = o - c`, `b = f . d`, the
//! discriminant is computed as `r^2 - |f - b d|^2 = (r - |l|)(r + |l|)`, which does not cancel
//! for distant spheres; `c = (|f| - r)(|f| + r)`; roots `q = -(b + sign(b) sqrt(disc))`,
//! `t0 = c / q`, `t1 = q / a`, never subtracting nearly equal numbers. The hit point is
//! re-projected onto the sphere, leaving an error of `gamma(6) (|c| + |p - c|)` per axis.

use std::f64::consts::PI;

use glam::{DVec2, DVec3};
use serde::{Deserialize, Serialize};
use spectrace_sampling::Frame;

use crate::float::{finite_point, gamma, positive, stable_quadratic_roots};
use crate::shape::{Primitives, SurfacePoint, similarity};
use crate::{Bounds, GeometryError, Hit, Ray, Transform};

/// A sphere.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "SphereRepr", into = "SphereRepr")]
pub struct Sphere {
    center: DVec3,
    radius: f64,
    frame: Frame,
    repr: Box<SphereRepr>,
}

/// Scene-file form of [`Sphere`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct SphereRepr {
    center: DVec3,
    radius: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    transform: Option<Transform>,
}

impl TryFrom<SphereRepr> for Sphere {
    type Error = GeometryError;
    fn try_from(r: SphereRepr) -> Result<Self, GeometryError> {
        const S: &str = "Sphere";
        let center = finite_point(S, "center", r.center)?;
        let radius = positive(S, "radius", r.radius)?;
        let t = r.transform.unwrap_or_default();
        let s = similarity(S, &t)?;
        let frame =
            Frame::from_normal_and_tangent(t.vector(DVec3::Y).normalize(), t.vector(DVec3::X));
        let center = finite_point(S, "transform", t.point(center))?;
        let radius = positive(S, "transform", radius * s)?;
        Ok(Self { center, radius, frame, repr: Box::new(r) })
    }
}

impl From<Sphere> for SphereRepr {
    fn from(s: Sphere) -> Self {
        *s.repr
    }
}

impl Sphere {
    /// A sphere of `radius` around `center`.
    ///
    /// # Errors
    /// [`GeometryError::Parameter`] naming `center` or `radius`.
    pub fn new(center: DVec3, radius: f64) -> Result<Self, GeometryError> {
        SphereRepr { center, radius, transform: None }.try_into()
    }

    /// This sphere with `transform` applied (a similarity).
    ///
    /// # Errors
    /// [`GeometryError::Parameter`] naming `transform` if it is not a similarity.
    pub fn transformed(&self, transform: &Transform) -> Result<Self, GeometryError> {
        let t = self.repr.transform.map_or(*transform, |own| own.then(transform));
        SphereRepr { transform: Some(t), ..(*self.repr).clone() }.try_into()
    }

    /// Centre in world space (m).
    pub fn center(&self) -> DVec3 {
        self.center
    }

    /// Radius in world space (m).
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// Surface area `4 pi r^2` (m^2).
    pub(crate) fn area(&self) -> f64 {
        4.0 * PI * self.radius * self.radius
    }

    /// A point uniform by area (Archimedes: `z = 1 - 2 u0` along the pole is uniform), from
    /// uniforms already in `[0, 1)`.
    pub(crate) fn sample_area(&self, u: [f64; 3]) -> SurfacePoint {
        let z = 1.0 - 2.0 * u[0];
        let s = (1.0 - z * z).max(0.0).sqrt();
        let phi = 2.0 * PI * u[1];
        let n = self.frame.to_world(DVec3::new(s * phi.cos(), s * phi.sin(), z)).normalize();
        SurfacePoint { point: self.center + n * self.radius, normal: n }
    }
}

impl Primitives for Sphere {
    fn count(&self) -> usize {
        1
    }

    fn bounds(&self, _index: u32) -> Bounds {
        Bounds { min: self.center - self.radius, max: self.center + self.radius }
    }

    fn hit_t(&self, _index: u32, ray: &Ray, t_max: f64) -> Option<f64> {
        self.solve(ray, t_max).map(|(t, _)| t)
    }

    fn intersect(&self, _index: u32, ray: &Ray, t_max: f64) -> Option<Hit> {
        let (t, n) = self.solve(ray, t_max)?;
        let (c, r) = (self.center, self.radius);
        let v = n * r;
        let point = c + v;
        let error = (c.abs() + v.abs()) * gamma(6);
        let local = self.frame.to_local(n);
        let phi = local.y.atan2(local.x);
        let phi = if phi < 0.0 { phi + 2.0 * PI } else { phi };
        let uv = DVec2::new(phi / (2.0 * PI), local.z.clamp(-1.0, 1.0).acos() / PI);
        Some(Hit {
            t,
            point,
            geometric_normal: n,
            shading_normal: n,
            uv,
            primitive: 0,
            triangle: 0,
            error,
        })
    }
}

/// Whether a ray whose squared distance from the centre at its closest approach is `l2`
/// (rounded) surely misses a sphere of radius `r`: `l2 > r^2 (1 + 8 eps)`, with `r^2` a normal
/// number. Then `sqrt(l2)` rounds above `r` (the rounding of `r^2`, of the product and of the
/// square root together are below `3 eps / 2`), so the discriminant `(r - l)(r + l)` that
/// [`Sphere::solve`] would compute from the same `l2` is negative: the same answer without the
/// square root, for the rays that miss by more than a few ulps (most rays, in most scenes).
#[inline(always)]
fn is_clear_miss(l2: f64, r: f64) -> bool {
    let r2 = r * r;
    r2 >= f64::MIN_POSITIVE && l2 > r2 * (1.0 + 8.0 * f64::EPSILON)
}

impl Sphere {
    /// The nearest root in `(0, t_max)` and the unit normal there.
    #[inline]
    fn solve(&self, ray: &Ray, t_max: f64) -> Option<(f64, DVec3)> {
        let (c, r) = (self.center, self.radius);
        let f = ray.origin - c;
        let d = ray.direction;
        let a = d.length_squared();
        let b = f.dot(d);
        // `l = sqrt(l2)` is `|f - d (b / a)|` as `DVec3::length` computes it.
        let l2 = (f - d * (b / a)).length_squared();
        if is_clear_miss(l2, r) {
            return None;
        }
        let l = l2.sqrt();
        let disc = a * ((r - l) * (r + l));
        if !(disc >= 0.0) {
            return None;
        }
        let fl = f.length();
        let cc = (fl - r) * (fl + r);
        let (t0, t1) = stable_quadratic_roots(a, b, cc, disc);
        let t = if t0 > 0.0 && t0 < t_max {
            t0
        } else if t1 > 0.0 && t1 < t_max {
            t1
        } else {
            return None;
        };
        let v = ray.at(t) - c;
        let len = v.length();
        if !(len > 0.0) {
            return None;
        }
        Some((t, v / len))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_clear_miss_is_a_negative_discriminant() {
        // Radii over the whole normal range and beyond it, squared distances within a few
        // hundred ulps of r^2 either way: whenever the early test says "miss", the square root
        // it skips rounds above r, so the full test would have said so too; and far misses are
        // caught.
        let mut fired = 0;
        for e in (-530..=511).step_by(7) {
            for m in [1.0, 1.1, 1.3, 1.5, 1.7, 1.9, 1.999_999_999_999] {
                let r = m * 2f64.powi(e);
                let r2 = r * r;
                let mut l2 = r2 * (1.0 - 200.0 * f64::EPSILON);
                for _ in 0..400 {
                    if is_clear_miss(l2, r) {
                        fired += 1;
                        assert!(l2.sqrt() > r, "r {r:e}, l2 {l2:e}");
                    }
                    l2 = l2.next_up();
                }
                assert_eq!(is_clear_miss(4.0 * r2, r), r2 >= f64::MIN_POSITIVE, "r {r:e}");
            }
        }
        assert!(fired > 10_000, "{fired}");
    }
}
