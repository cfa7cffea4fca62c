//! [`Rectangle`]: the parallelogram `corner + s edge_u + t edge_v`, `s, t` in `[0, 1]`.
//!
//! | field | unit | default | meaning |
//! |---|---|---|---|
//! | `corner` | m, `[x, y, z]` | required | one corner |
//! | `edge_u` | m, `[x, y, z]` | required | first edge from `corner` |
//! | `edge_v` | m, `[x, y, z]` | required | second edge from `corner`; not parallel to `edge_u` (else "degenerate") |
//! | `transform` | [`Transform`] | none | any affine transform (a parallelogram stays one) |
//!
//! ```json
//! {"type": "Rectangle", "corner": [-1, 0, -1], "edge_u": [0, 0, 2], "edge_v": [2, 0, 0]}
//! ```
//!
//! The edges need not be perpendicular (any parallelogram). Geometric normal:
//! `normalize(edge_u x edge_v)` of the transformed edges (the example faces `+y`);
//! `uv = (s, t)`.
//!
//! Robustness: the hit point `o + t d` is re-projected onto the plane, so its error no longer
//! depends on `t` (grazing rays); what remains is bounded by
//! `gamma(12) (|p| + |corner|) + gamma(6) |p - corner|` per axis.

use glam::{DVec2, DVec3};
use serde::{Deserialize, Serialize};

use crate::float::{finite_point, gamma, safe_length, unit_direction};
use crate::shape::{Primitives, SurfacePoint};
use crate::{Bounds, GeometryError, Hit, Ray, Transform};

/// A parallelogram (a rectangle when the edges are perpendicular).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "RectangleRepr", into = "RectangleRepr")]
pub struct Rectangle {
    corner: DVec3,
    edge_u: DVec3,
    edge_v: DVec3,
    normal: DVec3,
    dual_u: DVec3,
    dual_v: DVec3,
    area: f64,
    repr: Box<RectangleRepr>,
}

/// Scene-file form of [`Rectangle`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct RectangleRepr {
    corner: DVec3,
    edge_u: DVec3,
    edge_v: DVec3,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    transform: Option<Transform>,
}

impl TryFrom<RectangleRepr> for Rectangle {
    type Error = GeometryError;
    fn try_from(r: RectangleRepr) -> Result<Self, GeometryError> {
        const S: &str = "Rectangle";
        finite_point(S, "corner", r.corner)?;
        finite_point(S, "edge_u", r.edge_u)?;
        finite_point(S, "edge_v", r.edge_v)?;
        edge_frame(S, "edge_u", r.edge_u, "edge_v", r.edge_v)?;
        if !(r.corner + r.edge_u + r.edge_v).is_finite() {
            return Err(GeometryError::parameter(
                S,
                "corner",
                r.corner,
                "too large: corner + edge_u + edge_v overflows",
            ));
        }
        let t = r.transform.unwrap_or_default();
        let corner = finite_point(S, "transform", t.point(r.corner))?;
        let edge_u = t.vector(r.edge_u);
        let edge_v = t.vector(r.edge_v);
        if !(corner + edge_u + edge_v).is_finite() {
            return Err(GeometryError::parameter(
                S,
                "transform",
                t.to_rows(),
                "too large: the transformed corners overflow",
            ));
        }
        let f = edge_frame(S, "transform", edge_u, "transform", edge_v)?;
        Ok(Self {
            corner,
            edge_u,
            edge_v,
            normal: f.normal,
            dual_u: f.unit_v.cross(f.normal) / (f.len_u * f.sin),
            dual_v: f.normal.cross(f.unit_u) / (f.len_v * f.sin),
            area: f.len_u * f.len_v * f.sin,
            repr: Box::new(r),
        })
    }
}

/// The normalised edges of a parallelogram, their lengths and the sine of the angle between them.
struct EdgeFrame {
    unit_u: DVec3,
    unit_v: DVec3,
    len_u: f64,
    len_v: f64,
    sin: f64,
    normal: DVec3,
}

/// Judges two edges on their directions (normalised first, so huge or tiny finite edges are not
/// mistaken for degenerate ones): each must be non-zero, they must not be parallel, and the area
/// `|u| |v| sin` must fit in an f64.
fn edge_frame(
    shape: &'static str,
    field_u: &'static str,
    u: DVec3,
    field_v: &'static str,
    v: DVec3,
) -> Result<EdgeFrame, GeometryError> {
    let unit_u = unit_direction(shape, field_u, u)?;
    let unit_v = unit_direction(shape, field_v, v)?;
    let cross = unit_u.cross(unit_v);
    let sin = cross.length();
    if !(sin > 1e-12) {
        return Err(GeometryError::parameter(
            shape,
            field_v,
            v,
            "degenerate: parallel to edge_u (the edges span no area)",
        ));
    }
    let (len_u, len_v) = (safe_length(u), safe_length(v));
    let area = len_u * len_v * sin;
    if !area.is_finite() {
        let (field, value) = if len_u >= len_v { (field_u, u) } else { (field_v, v) };
        return Err(GeometryError::parameter(
            shape,
            field,
            value,
            "too large: the area |edge_u| |edge_v| sin(angle) overflows",
        ));
    }
    if !(area > 0.0) {
        return Err(GeometryError::parameter(
            shape,
            field_v,
            v,
            "too small: the area |edge_u| |edge_v| sin(angle) underflows to 0",
        ));
    }
    Ok(EdgeFrame { unit_u, unit_v, len_u, len_v, sin, normal: cross / sin })
}

impl From<Rectangle> for RectangleRepr {
    fn from(s: Rectangle) -> Self {
        *s.repr
    }
}

impl Rectangle {
    /// The parallelogram `corner + s edge_u + t edge_v`.
    ///
    /// # Errors
    /// [`GeometryError::Parameter`] naming a non-finite field, or `edge_v` when degenerate.
    pub fn new(corner: DVec3, edge_u: DVec3, edge_v: DVec3) -> Result<Self, GeometryError> {
        RectangleRepr { corner, edge_u, edge_v, transform: None }.try_into()
    }

    /// This rectangle with `transform` applied.
    ///
    /// # Errors
    /// As [`Rectangle::new`].
    pub fn transformed(&self, transform: &Transform) -> Result<Self, GeometryError> {
        let t = self.repr.transform.map_or(*transform, |own| own.then(transform));
        RectangleRepr { transform: Some(t), ..(*self.repr).clone() }.try_into()
    }

    /// Unit normal `edge_u x edge_v`, normalised.
    pub fn normal(&self) -> DVec3 {
        self.normal
    }

    /// Area `|edge_u x edge_v|` of the transformed edges (m^2; checked finite and `> 0`).
    pub(crate) fn area(&self) -> f64 {
        self.area
    }

    /// The point `corner + u0 edge_u + u1 edge_v` (uniform by area: the map is affine), from
    /// uniforms already in `[0, 1)`; normal the front face's.
    pub(crate) fn sample_area(&self, u: [f64; 3]) -> SurfacePoint {
        let point = self.corner + self.edge_u * u[0] + self.edge_v * u[1];
        SurfacePoint { point, normal: self.normal }
    }
}

/// The ray's crossing of the plane through `anchor` with unit `normal`, in `(0, t_max)`,
/// re-projected onto the plane: `(t, point)`. A plane behind the ray (numerator and
/// denominator of `t` of opposite signs) is rejected before the division.
#[inline]
pub(crate) fn plane_hit(
    anchor: DVec3,
    normal: DVec3,
    ray: &Ray,
    t_max: f64,
) -> Option<(f64, DVec3)> {
    let den = ray.direction.dot(normal);
    let num = (anchor - ray.origin).dot(normal);
    if den == 0.0 || (num > 0.0) != (den > 0.0) {
        return None;
    }
    let t = num / den;
    if !(t > 0.0 && t < t_max) {
        return None;
    }
    let p = ray.at(t);
    Some((t, p - normal * (p - anchor).dot(normal)))
}

/// The rounding error bound of a point `p` that [`plane_hit`] re-projected onto the plane
/// through `anchor` (computed only for accepted hits).
#[inline]
pub(crate) fn plane_error(p: DVec3, anchor: DVec3) -> DVec3 {
    let q = (p - anchor).abs().max_element();
    (p.abs() + anchor.abs()) * gamma(12) + DVec3::splat(gamma(6) * q)
}

impl Rectangle {
    /// The plane crossing inside the parallelogram: `(t, point, s, t)`.
    #[inline]
    fn solve(&self, ray: &Ray, t_max: f64) -> Option<(f64, DVec3, f64, f64)> {
        let (t, point) = plane_hit(self.corner, self.normal, ray, t_max)?;
        let q = point - self.corner;
        let s = q.dot(self.dual_u);
        let v = q.dot(self.dual_v);
        if !((0.0..=1.0).contains(&s) && (0.0..=1.0).contains(&v)) {
            return None;
        }
        Some((t, point, s, v))
    }
}

impl Primitives for Rectangle {
    fn count(&self) -> usize {
        1
    }

    fn bounds(&self, _index: u32) -> Bounds {
        let c = self.corner;
        Bounds::from_points([c, c + self.edge_u, c + self.edge_v, c + self.edge_u + self.edge_v])
    }

    fn hit_t(&self, _index: u32, ray: &Ray, t_max: f64) -> Option<f64> {
        self.solve(ray, t_max).map(|h| h.0)
    }

    fn intersect(&self, _index: u32, ray: &Ray, t_max: f64) -> Option<Hit> {
        let (t, point, s, v) = self.solve(ray, t_max)?;
        let error = plane_error(point, self.corner);
        Some(Hit {
            t,
            point,
            geometric_normal: self.normal,
            shading_normal: self.normal,
            uv: DVec2::new(s, v),
            primitive: 0,
            triangle: 0,
            error,
        })
    }
}
