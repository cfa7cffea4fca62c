//! [`Torus`]: a ring torus around an axis, intersected by root isolation on its quartic.
//!
//! | field | unit | default | meaning |
//! |---|---|---|---|
//! | `center` | m, `[x, y, z]` | required | centre of the hole |
//! | `axis` | `[x, y, z]` | required | axis of revolution (normalised; non-zero) |
//! | `major_radius` | m | required | distance from the centre to the middle of the tube, > `minor_radius` |
//! | `minor_radius` | m | required | radius of the tube, > 0 and < `major_radius` |
//! | `transform` | [`Transform`] | none | must be a similarity |
//!
//! ```json
//! {"type": "Torus", "center": [0, 1, 0], "axis": [0, 1, 0], "major_radius": 1, "minor_radius": 0.25}
//! ```
//!
//! Horn and spindle tori (`minor_radius >= major_radius`) are rejected: the root-finding argument
//! below needs the tube not to cross the axis. `uv`: `u` = angle about the axis, `v` = angle around
//! the tube (from the outer equator towards `+axis`), both over `2 pi`. The normal points out of
//! the tube.
//!
//! Robustness. The ray is clipped to the bounding sphere (radius `R + r`) and re-based at its entry
//! point, so the quartic's coefficients are of the torus's own scale however far it is from the
//! origin. The quartic `f(s) = (|q|^2 + R^2 - r^2)^2 - 4 R^2 (q_x^2 + q_y^2)` is never solved in
//! closed form (Ferrari's formulas lose all precision for grazing rays). Instead (Yuksel 2022,
//! "High-performance polynomial root finding for graphics"), the roots of `f'` (themselves isolated
//! by the roots of `f''`) split the interval into pieces on which `f` is monotone, so each holds at
//! most one root. The sign on each piece is then evaluated with the torus's exact signed distance
//! `h(q) = |(rho - R, q_z)| - r` (same sign as `f`, since `f = h (h + 2r) (|q|^2 + R^2 - r^2 + 2 R
//! rho)`), which does not suffer the cancellation of the expanded quartic, and the first piece
//! whose ends differ in sign is bisected to full precision. A reported hit is therefore always a
//! true crossing of `h`; only a ray tangent to within rounding may be reported as a miss. The hit
//! is then projected onto the nearest point of the tube.

use std::f64::consts::PI;

use glam::{DVec2, DVec3};
use serde::{Deserialize, Serialize};
use spectrace_sampling::Frame;

use crate::float::{finite_point, gamma, positive, unit_direction};
use crate::shape::{Primitives, SurfacePoint, similarity};
use crate::{Bounds, GeometryError, Hit, Ray, Transform};

/// A ring torus.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "TorusRepr", into = "TorusRepr")]
pub struct Torus {
    center: DVec3,
    frame: Frame,
    major: f64,
    minor: f64,
    repr: Box<TorusRepr>,
}

/// Scene-file form of [`Torus`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct TorusRepr {
    center: DVec3,
    axis: DVec3,
    major_radius: f64,
    minor_radius: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    transform: Option<Transform>,
}

impl TryFrom<TorusRepr> for Torus {
    type Error = GeometryError;
    fn try_from(r: TorusRepr) -> Result<Self, GeometryError> {
        const S: &str = "Torus";
        let center = finite_point(S, "center", r.center)?;
        let axis = unit_direction(S, "axis", r.axis)?;
        let major = positive(S, "major_radius", r.major_radius)?;
        let minor = positive(S, "minor_radius", r.minor_radius)?;
        if !(minor < major) {
            return Err(GeometryError::parameter(
                S,
                "minor_radius",
                minor,
                "must be < major_radius (ring torus)",
            ));
        }
        let t = r.transform.unwrap_or_default();
        let s = similarity(S, &t)?;
        let axis = unit_direction(S, "transform", t.vector(axis))?;
        Ok(Self {
            center: finite_point(S, "transform", t.point(center))?,
            frame: Frame::from_normal(axis),
            major: positive(S, "transform", major * s)?,
            minor: positive(S, "transform", minor * s)?,
            repr: Box::new(r),
        })
    }
}

impl From<Torus> for TorusRepr {
    fn from(s: Torus) -> Self {
        *s.repr
    }
}

/// `p(x)` for coefficients in increasing degree (Horner).
fn poly(c: &[f64], x: f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, &k| acc * x + k)
}

/// The derivative's coefficients.
fn derivative<const N: usize, const M: usize>(c: &[f64; N]) -> [f64; M] {
    std::array::from_fn(|i| c[i + 1] * (i + 1) as f64)
}

/// Bisects a sign change of `f` on `[a, b]` (`f(a)` and `f(b)` of different sign) to full precision.
fn bisect(mut a: f64, mut b: f64, f: impl Fn(f64) -> f64) -> f64 {
    let fa_neg = f(a) < 0.0;
    for _ in 0..200 {
        let m = 0.5 * (a + b);
        if m <= a || m >= b {
            break;
        }
        let fm = f(m);
        if fm == 0.0 {
            return m;
        }
        if (fm < 0.0) == fa_neg {
            a = m;
        } else {
            b = m;
        }
    }
    0.5 * (a + b)
}

/// The sorted roots in `(lo, hi)` of the polynomial `c` (increasing degree), given the sorted
/// critical points (roots of its derivative) in `(lo, hi)`; found by bisecting each monotone piece.
fn roots_between(c: &[f64], lo: f64, hi: f64, critical: &[f64]) -> Vec<f64> {
    let mut knots = Vec::with_capacity(critical.len() + 2);
    knots.push(lo);
    knots.extend(critical.iter().copied().filter(|&x| x > lo && x < hi));
    knots.push(hi);
    let mut roots = Vec::new();
    for w in knots.windows(2) {
        let (fa, fb) = (poly(c, w[0]), poly(c, w[1]));
        if fa == 0.0 && w[0] > lo {
            roots.push(w[0]);
        } else if (fa < 0.0) != (fb < 0.0) && fb != 0.0 {
            roots.push(bisect(w[0], w[1], |x| poly(c, x)));
        }
    }
    roots
}

/// The angle `phi` in `[0, 2 pi)` around the tube at which the CDF of the density
/// `(1 + k cos phi) / (2 pi)` (with `k = r / R` in `(0, 1)`) equals `u` in `[0, 1)`: the root of
/// `g(phi) = phi + k sin phi - 2 pi u`, which is increasing (`g' = 1 + k cos phi >= 1 - k > 0`).
/// Newton's method from `2 pi u`, kept inside a bracket that every step narrows and falling back
/// to bisection when a step leaves it, until the step or the bracket is below `1e-12` rad
/// (at most 200 iterations; Newton converges in a handful).
fn minor_angle(u: f64, k: f64) -> f64 {
    let target = 2.0 * PI * u;
    let g = |phi: f64| phi + k * phi.sin() - target;
    let (mut lo, mut hi) = (0.0, 2.0 * PI);
    let mut phi = target;
    for _ in 0..200 {
        let value = g(phi);
        if value == 0.0 {
            break;
        }
        if value < 0.0 {
            lo = phi;
        } else {
            hi = phi;
        }
        let slope = 1.0 + k * phi.cos();
        let newton = phi - value / slope;
        let next = if newton > lo && newton < hi { newton } else { 0.5 * (lo + hi) };
        let step = (next - phi).abs();
        phi = next;
        if step < 1e-12 || hi - lo < 1e-12 {
            break;
        }
    }
    phi.clamp(0.0, 2.0 * PI)
}

impl Torus {
    /// A torus around `center` and `axis`.
    ///
    /// # Errors
    /// [`GeometryError::Parameter`] naming `center`, `axis`, `major_radius` or `minor_radius`.
    pub fn new(
        center: DVec3,
        axis: DVec3,
        major_radius: f64,
        minor_radius: f64,
    ) -> Result<Self, GeometryError> {
        TorusRepr { center, axis, major_radius, minor_radius, transform: None }.try_into()
    }

    /// Area `4 pi^2 R r` (m^2).
    pub(crate) fn area(&self) -> f64 {
        4.0 * PI * PI * self.major * self.minor
    }

    /// A point uniform by area, from uniforms already in `[0, 1)`: the angle about the axis is
    /// uniform (`2 pi u0`); the angle around the tube `phi` (from the outer equator towards
    /// `+axis`) has density `(R + r cos phi) / (2 pi R)`, whose CDF is inverted exactly from
    /// `u1` ([`minor_angle`]). The normal points out of the tube.
    pub(crate) fn sample_area(&self, u: [f64; 3]) -> SurfacePoint {
        let theta = 2.0 * PI * u[0];
        let phi = minor_angle(u[1], self.minor / self.major);
        let ring = DVec3::new(theta.cos(), theta.sin(), 0.0);
        let nl = ring * phi.cos() + DVec3::Z * phi.sin();
        let offset = self.frame.to_world(ring * self.major + nl * self.minor);
        SurfacePoint { point: self.center + offset, normal: self.frame.to_world(nl).normalize() }
    }

    /// Signed distance of the local point `q` to the tube (negative inside).
    fn signed_distance(&self, q: DVec3) -> f64 {
        let rho = q.x.hypot(q.y);
        (rho - self.major).hypot(q.z) - self.minor
    }
}

impl Primitives for Torus {
    fn count(&self) -> usize {
        1
    }

    fn bounds(&self, _index: u32) -> Bounds {
        let e = crate::disk::circle_extent(self.frame.n(), self.major) + self.minor;
        Bounds { min: self.center - e, max: self.center + e }
    }

    fn hit_t(&self, _index: u32, ray: &Ray, t_max: f64) -> Option<f64> {
        self.solve(ray, t_max).map(|h| h.0)
    }

    fn intersect(&self, _index: u32, ray: &Ray, t_max: f64) -> Option<Hit> {
        let (t, q) = self.solve(ray, t_max)?;
        let (big_r, r, fr) = (self.major, self.minor, &self.frame);
        // Nearest point on the tube.
        let rho = q.x.hypot(q.y);
        let ring = if rho > 0.0 {
            DVec3::new(q.x / rho, q.y / rho, 0.0) * big_r
        } else {
            DVec3::new(big_r, 0.0, 0.0)
        };
        let m = q - ring;
        let ml = m.length();
        let nl = if ml > 0.0 { m / ml } else { ring / big_r };
        let local = ring + nl * r;
        let offset = fr.to_world(local);
        let point = self.center + offset;
        let error =
            (self.center.abs() + offset.abs()) * gamma(10) + DVec3::splat(gamma(10) * (big_r + r));
        let n = fr.to_world(nl).normalize();
        let phi = ring.y.atan2(ring.x);
        let theta = nl.z.atan2(nl.dot(ring) / big_r);
        let wrap = |x: f64| (if x < 0.0 { x + 2.0 * PI } else { x }) / (2.0 * PI);
        Some(Hit {
            t,
            point,
            geometric_normal: n,
            shading_normal: n,
            uv: DVec2::new(wrap(phi), wrap(theta)),
            primitive: 0,
            triangle: 0,
            error,
        })
    }
}

impl Torus {
    /// The first crossing in `(0, t_max)`: `(t, local point on the ray there)`.
    fn solve(&self, ray: &Ray, t_max: f64) -> Option<(f64, DVec3)> {
        let (big_r, r, fr) = (self.major, self.minor, &self.frame);
        let o = fr.to_local(ray.origin - self.center);
        let d = fr.to_local(ray.direction);
        // Bounding sphere of radius R + r, slightly enlarged.
        let rb = (big_r + r) * (1.0 + 1e-9);
        let a = d.length_squared();
        let b = o.dot(d);
        let l = (o - d * (b / a)).length();
        let disc = a * ((rb - l) * (rb + l));
        if !(disc >= 0.0) {
            return None;
        }
        let ol = o.length();
        let (e0, e1) = crate::float::stable_quadratic_roots(a, b, (ol - rb) * (ol + rb), disc);
        // The search interval does not depend on t_max, so the result does not either (the BVH
        // and a brute-force loop pass different t_max and must agree to the last bit).
        let t0 = e0.max(0.0);
        let t1 = e1;
        if !(t0 < t1 && t0 < t_max) {
            return None;
        }
        // Re-base at the entry point: s = t - t0 in [0, len].
        let o = o + d * t0;
        let len = t1 - t0;
        let (b, bxy) = (o.dot(d), o.x * d.x + o.y * d.y);
        let (axy, cxy) = (d.x * d.x + d.y * d.y, o.x * o.x + o.y * o.y);
        let cc = o.length_squared() + big_r * big_r - r * r;
        let k = 4.0 * big_r * big_r;
        let quartic = [
            cc * cc - k * cxy,
            4.0 * b * cc - 2.0 * k * bxy,
            4.0 * b * b + 2.0 * a * cc - k * axy,
            4.0 * a * b,
            a * a,
        ];
        let cubic: [f64; 4] = derivative(&quartic);
        let quadratic: [f64; 3] = derivative(&cubic);
        // Roots of the quadratic f'' (stable form), then of the cubic f', then h on each piece.
        let mut crit2 = Vec::with_capacity(2);
        let (qa, qb, qc) = (quadratic[2], quadratic[1] * 0.5, quadratic[0]);
        let qdisc = qb * qb - qa * qc;
        if qdisc >= 0.0 && qa != 0.0 {
            let (x0, x1) = crate::float::stable_quadratic_roots(qa, qb, qc, qdisc);
            crit2.extend([x0, x1]);
        }
        let crit1 = roots_between(&cubic, 0.0, len, &crit2);
        let h = |s: f64| self.signed_distance(o + d * s);
        let mut knots = Vec::with_capacity(crit1.len() + 2);
        knots.push(0.0);
        knots.extend(crit1);
        knots.push(len);
        let mut s_hit = None;
        let mut h_prev = h(0.0);
        for w in knots.windows(2) {
            let h_next = h(w[1]);
            if h_next == 0.0 && w[1] > 0.0 {
                s_hit = Some(w[1]);
                break;
            }
            if h_prev != 0.0 && (h_prev < 0.0) != (h_next < 0.0) {
                s_hit = Some(bisect(w[0], w[1], h));
                break;
            }
            h_prev = h_next;
        }
        let s = s_hit?;
        let t = t0 + s;
        if !(t > 0.0 && t < t_max) {
            return None;
        }
        Some((t, o + d * s))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The CDF of the angle around the tube, `(phi + k sin phi) / (2 pi)`.
    fn cdf(phi: f64, k: f64) -> f64 {
        (phi + k * phi.sin()) / (2.0 * PI)
    }

    #[test]
    fn the_minor_angle_inverts_its_cdf_to_1e_12() {
        let mut worst: f64 = 0.0;
        for k in [1e-9, 0.1, 0.5, 0.9, 0.999, 1.0 - 1e-12] {
            let us = (0..=10_000).map(|i| f64::from(i) / 10_000.0).chain([
                1e-300,
                1e-17,
                0.5 - 1e-13,
                1.0 - 1e-16,
            ]);
            for u in us.filter(|&u| u < 1.0) {
                let phi = minor_angle(u, k);
                assert!((0.0..=2.0 * PI).contains(&phi), "k {k} u {u}: phi {phi}");
                worst = worst.max((cdf(phi, k) - u).abs());
            }
        }
        assert!(worst < 1e-12, "worst CDF error {worst:e}");
        // Monotone in u, and the symmetric point u = 1/2 is phi = pi.
        assert!((minor_angle(0.5, 0.7) - PI).abs() < 1e-12);
        assert_eq!(minor_angle(0.0, 0.7), 0.0);
    }
}
