//! [`LightBounds`]: where a light is, which way it shines and how strongly, as a light tree
//! needs to know it (Conty Estevez and Kulla 2018, "Importance Sampling of Many Lights with
//! Adaptive Tree Splitting"; pbrt-v4's `LightBounds`).
//!
//! A bound is a box that holds every emitting point, a cone of emission normals (`axis`,
//! half-angle `theta_o`), a further angle `theta_e` beyond those normals into which light still
//! leaves (90 degrees for a Lambertian surface, the cone itself for a spot), a power `phi`
//! (W, as a peak: `4 pi` times the peak intensity for a point-like light, so that
//! `phi / d^2` compares lights of any kind) and whether both sides of a surface emit.
//! [`LightBounds::union`] merges two bounds into one that holds both, and
//! [`LightBounds::importance`] gives a number that is 0 only where no light of the bound can
//! reach a point: the one property an unbiased sampler needs of it.
//!
//! | constructor | emitting points | normals | spread beyond them |
//! |---|---|---|---|
//! | [`LightBounds::point`] | one point | every direction | none |
//! | [`LightBounds::spot`] | one point | the cone | none |
//! | [`LightBounds::surface`] | a box | one normal (both ways if two-sided) | 90 degrees |

use glam::DVec3;

/// Where a light emits, which way and how strongly: a light tree's view of it (see the module
/// documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightBounds {
    /// Least corner of the box holding every emitting point.
    pub min: DVec3,
    /// Greatest corner of the box.
    pub max: DVec3,
    /// Power as a peak (W): `4 pi` times the peak radiant intensity for a point-like light, the
    /// emitted power for a Lambertian surface (per side).
    pub phi: f64,
    /// Axis of the cone of emission normals (unit).
    pub axis: DVec3,
    /// Cosine of the half-angle of the cone of normals (`-1`: every direction).
    pub cos_theta_o: f64,
    /// Cosine of the angle beyond the cone of normals into which light still leaves (`0` for a
    /// Lambertian surface, `1` for a point or spot, which emit only inside their cone).
    pub cos_theta_e: f64,
    /// Both sides of the surfaces emit.
    pub two_sided: bool,
}

impl LightBounds {
    /// A point emitting in every direction, with `phi = 4 pi` times its peak intensity (W).
    pub fn point(position: DVec3, phi: f64) -> Self {
        Self {
            min: position,
            max: position,
            phi,
            axis: DVec3::Z,
            cos_theta_o: -1.0,
            cos_theta_e: 1.0,
            two_sided: false,
        }
    }

    /// A point emitting into the cone about `axis` whose half-angle has cosine `cos_cone`, with
    /// `phi = 4 pi` times its peak intensity (W).
    pub fn spot(position: DVec3, axis: DVec3, cos_cone: f64, phi: f64) -> Self {
        Self {
            min: position,
            max: position,
            phi,
            axis: axis.normalize_or(DVec3::Z),
            cos_theta_o: cos_cone.clamp(-1.0, 1.0),
            cos_theta_e: 1.0,
            two_sided: false,
        }
    }

    /// A flat Lambertian surface spanning `points`, facing `normal` (and its opposite if
    /// `two_sided`), emitting `phi` (W per side).
    pub fn surface(points: &[DVec3], normal: DVec3, phi: f64, two_sided: bool) -> Self {
        let (min, max) = points
            .iter()
            .fold((DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)), |(lo, hi), p| {
                (lo.min(*p), hi.max(*p))
            });
        Self {
            min,
            max,
            phi,
            axis: normal.normalize_or(DVec3::Z),
            cos_theta_o: 1.0,
            cos_theta_e: 0.0,
            two_sided,
        }
    }

    /// Any emitter inside the box `[min, max]`, shining every way (a shape whose normals are
    /// not known to lie in a cone).
    pub fn anywhere(min: DVec3, max: DVec3, phi: f64) -> Self {
        Self {
            min,
            max,
            phi,
            axis: DVec3::Z,
            cos_theta_o: -1.0,
            cos_theta_e: 0.0,
            two_sided: false,
        }
    }

    /// Whether the bound is usable: finite corners in order, a finite positive power, a unit
    /// axis and cosines in `[-1, 1]`.
    pub fn is_valid(&self) -> bool {
        self.min.is_finite()
            && self.max.is_finite()
            && self.min.cmple(self.max).all()
            && self.phi > 0.0
            && self.phi.is_finite()
            && (self.axis.length() - 1.0).abs() < 1e-6
            && (-1.0..=1.0).contains(&self.cos_theta_o)
            && (-1.0..=1.0).contains(&self.cos_theta_e)
    }

    /// The centre of the box.
    pub fn centre(&self) -> DVec3 {
        0.5 * (self.min + self.max)
    }

    /// A bound holding both `self` and `other`: the union of the boxes, the sum of the powers,
    /// a cone holding both cones of normals, the wider spread, two-sided if either is.
    pub fn union(&self, other: &Self) -> Self {
        let (axis, cos_theta_o) =
            cone_union((self.axis, self.cos_theta_o), (other.axis, other.cos_theta_o));
        Self {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
            phi: self.phi + other.phi,
            axis,
            cos_theta_o,
            cos_theta_e: self.cos_theta_e.min(other.cos_theta_e),
            two_sided: self.two_sided || other.two_sided,
        }
    }

    /// How much light the bound may send to `point`, up to a common factor: `phi / d^2` times
    /// the cosine of the least angle between a direction from the bound to `point` and the
    /// cone of normals (beyond the spread, 0). `d` is the distance to the box's centre, at
    /// least half its diagonal, so that a point inside the box does not divide by zero. It is
    /// 0 only where no emitter of the bound can shine on `point`, and finite for finite bounds.
    /// (For many queries of one bound, [`LightBounds::prepare`] it once.)
    pub fn importance(&self, point: DVec3) -> f64 {
        self.prepare().importance(point)
    }

    /// The bound with what every [`importance`](Self::importance) query needs computed once.
    pub fn prepare(&self) -> PreparedBounds {
        PreparedBounds {
            centre: self.centre(),
            half_diagonal: 0.5 * (self.max - self.min).length(),
            axis: self.axis,
            phi: self.phi,
            cos_theta_o: self.cos_theta_o,
            sin_theta_o: (1.0 - self.cos_theta_o * self.cos_theta_o).max(0.0).sqrt(),
            cos_theta_e: self.cos_theta_e,
            two_sided: self.two_sided,
        }
    }
}

/// A [`LightBounds`] prepared for importance queries ([`LightBounds::prepare`]): its centre,
/// half-diagonal and the sine of its cone computed once.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PreparedBounds {
    centre: DVec3,
    half_diagonal: f64,
    axis: DVec3,
    phi: f64,
    cos_theta_o: f64,
    sin_theta_o: f64,
    cos_theta_e: f64,
    two_sided: bool,
}

impl PreparedBounds {
    /// [`LightBounds::importance`] at `point`.
    #[inline]
    pub fn importance(&self, point: DVec3) -> f64 {
        self.importance_at(point, DVec3::ZERO)
    }

    /// [`LightBounds::importance`] at `point` on a surface of unit `normal` (either side;
    /// `DVec3::ZERO` for a point on no surface), times a bound on the cosine at the receiver
    /// (pbrt-v4's `LightBounds::Importance` bounds it by `cos(theta_i - theta_b)`; this takes
    /// the larger `min(1, cos theta_i + sin theta_b)`, which needs no angle): 0 only for a box
    /// that is a point in the surface's plane, which sends it nothing.
    #[inline]
    pub fn importance_at(&self, point: DVec3, normal: DVec3) -> f64 {
        let half_diagonal = self.half_diagonal;
        let to = point - self.centre;
        let distance2 = to.length_squared();
        let d2 = distance2.max(half_diagonal * half_diagonal).max(f64::MIN_POSITIVE);
        let distance = distance2.sqrt();
        let receiver = if normal == DVec3::ZERO || !(distance > half_diagonal) {
            1.0
        } else {
            ((normal.dot(to).abs() + half_diagonal) / distance).min(1.0)
        };
        if self.cos_theta_o <= -1.0 {
            // Normals every way: theta' is 0 wherever the point is (the general case below
            // gives cos theta' = 1 too), so only the distance and the receiver count.
            let value = self.phi * receiver / d2;
            return if value.is_finite() { value } else { f64::MAX };
        }
        // The angle between the axis and the direction to the point.
        let mut cos_w = if distance > 0.0 { self.axis.dot(to) / distance } else { 1.0 };
        if self.two_sided {
            cos_w = cos_w.abs();
        }
        let sin_w = (1.0 - cos_w * cos_w).max(0.0).sqrt();
        // Every direction from the box towards the point lies within theta_b of `to`.
        let (sin_b, cos_b) = if distance > half_diagonal && distance > 0.0 {
            let sin_b = (half_diagonal / distance).min(1.0);
            (sin_b, (1.0 - sin_b * sin_b).max(0.0).sqrt())
        } else {
            (1.0, -1.0)
        };
        // theta' = max(0, theta_w - theta_o - theta_b).
        let (sin_x, cos_x) = sub_clamped((sin_w, cos_w), (self.sin_theta_o, self.cos_theta_o));
        let (_, cos_p) = sub_clamped((sin_x, cos_x), (sin_b, cos_b));
        if cos_p < self.cos_theta_e {
            return 0.0;
        }
        let value = self.phi * cos_p * receiver / d2;
        if value.is_finite() { value } else { f64::MAX }
    }
}

/// `(sin, cos)` of `max(0, a - b)` for angles in `[0, pi]` given by their sines and cosines.
fn sub_clamped((sin_a, cos_a): (f64, f64), (sin_b, cos_b): (f64, f64)) -> (f64, f64) {
    if cos_a > cos_b {
        return (0.0, 1.0);
    }
    let sin = (sin_a * cos_b - cos_a * sin_b).clamp(-1.0, 1.0);
    let cos = (cos_a * cos_b + sin_a * sin_b).clamp(-1.0, 1.0);
    (sin.max(0.0), cos)
}

/// The narrowest cone (axis, cosine of its half-angle) found holding two cones: one of them if
/// it holds the other, else the cone spanning both, else every direction.
fn cone_union(a: (DVec3, f64), b: (DVec3, f64)) -> (DVec3, f64) {
    // Every direction already, or one and the same cone: no trigonometry needed.
    if a.1 <= -1.0 || (a.1 <= b.1 && a.0 == b.0) {
        return a;
    }
    if b.1 <= -1.0 || (b.1 <= a.1 && a.0 == b.0) {
        return b;
    }
    let theta_a = a.1.clamp(-1.0, 1.0).acos();
    let theta_b = b.1.clamp(-1.0, 1.0).acos();
    let theta_d = a.0.dot(b.0).clamp(-1.0, 1.0).acos();
    if (theta_d + theta_b).min(std::f64::consts::PI) <= theta_a {
        return a;
    }
    if (theta_d + theta_a).min(std::f64::consts::PI) <= theta_b {
        return b;
    }
    let theta_o = 0.5 * (theta_a + theta_d + theta_b);
    if theta_o >= std::f64::consts::PI {
        return (a.0, -1.0);
    }
    // Rotate a's axis towards b's by theta_o - theta_a, about their common normal.
    let normal = a.0.cross(b.0);
    if !(normal.length_squared() > 1e-24) {
        return (a.0, -1.0);
    }
    let normal = normal.normalize();
    let turn = theta_o - theta_a;
    let axis = a.0 * turn.cos() + normal.cross(a.0) * turn.sin();
    (axis.normalize_or(a.0), theta_o.cos())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// Directions on a Fibonacci sphere.
    fn directions(n: usize) -> impl Iterator<Item = DVec3> {
        (0..n).map(move |i| {
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
            let r = (1.0 - z * z).sqrt();
            let phi = i as f64 * PI * (3.0 - 5f64.sqrt());
            DVec3::new(r * phi.cos(), r * phi.sin(), z)
        })
    }

    #[test]
    fn the_union_of_two_cones_holds_every_direction_either_holds() {
        let cones = [
            (DVec3::Z, 0.9),
            (DVec3::X, 0.5),
            (DVec3::new(0.0, 0.6, -0.8), 0.99),
            (-DVec3::Z, 1.0),
            (DVec3::Y, -1.0),
            (DVec3::Z, 1.0),
        ];
        for a in cones {
            for b in cones {
                let (axis, cos) = cone_union(a, b);
                assert!((axis.length() - 1.0).abs() < 1e-9);
                for d in directions(2000) {
                    for (w, c) in [a, b] {
                        if d.dot(w) >= c {
                            assert!(d.dot(axis) >= cos - 1e-9, "{a:?} u {b:?} loses {d}");
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn importance_is_zero_only_where_no_light_arrives() {
        // A one-sided square facing +z: nothing reaches points strictly below its plane.
        let square = LightBounds::surface(
            &[DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y],
            DVec3::Z,
            1.0,
            false,
        );
        assert!(square.importance(DVec3::new(0.5, 0.5, 1.0)) > 0.0);
        assert!(square.importance(DVec3::new(5.0, 0.5, 0.01)) > 0.0);
        assert_eq!(square.importance(DVec3::new(0.5, 0.5, -1.0)), 0.0);
        let two_sided = LightBounds { two_sided: true, ..square };
        assert!(two_sided.importance(DVec3::new(0.5, 0.5, -1.0)) > 0.0);
        // A spot of 30 degrees down -z: zero outside its cone, positive inside.
        let spot = LightBounds::spot(DVec3::ZERO, -DVec3::Z, (PI / 6.0).cos(), 1.0);
        assert!(spot.importance(DVec3::new(0.0, 0.4, -1.0)) > 0.0);
        assert_eq!(spot.importance(DVec3::new(0.0, 0.7, -1.0)), 0.0);
        // A point: phi / d^2 everywhere, and finite at the point itself.
        let point = LightBounds::point(DVec3::ONE, 2.0);
        assert!((point.importance(DVec3::new(1.0, 1.0, 3.0)) - 0.5).abs() < 1e-12);
        assert!(point.importance(DVec3::ONE).is_finite());
    }

    #[test]
    fn the_receiver_normal_weighs_by_the_cosine_and_rejects_only_the_plane() {
        let point = LightBounds::point(DVec3::Y, 1.0).prepare();
        let at = DVec3::ZERO;
        assert!((point.importance_at(at, DVec3::Y) - 1.0).abs() < 1e-12);
        assert!((point.importance_at(at, -DVec3::Y) - 1.0).abs() < 1e-12, "either side");
        let tilted = DVec3::new(1.0, 1.0, 0.0).normalize();
        assert!((point.importance_at(at, tilted) - 0.5f64.sqrt()).abs() < 1e-12, "cos 45");
        assert_eq!(point.importance_at(at, DVec3::X), 0.0, "a point in the receiver's plane");
        // A square straddling the receiver's plane still reaches it.
        let square = LightBounds::surface(
            &[DVec3::new(-0.5, 0.9, 0.0), DVec3::new(0.5, 1.1, 0.0)],
            DVec3::X,
            1.0,
            true,
        )
        .prepare();
        assert!(square.importance_at(DVec3::new(-3.0, 1.0, 0.0), DVec3::Y) > 0.0);
        assert_eq!(point.importance_at(at, DVec3::ZERO), point.importance(at));
    }

    #[test]
    fn a_union_is_at_least_as_important_as_its_parts_share() {
        // Where either part reaches a point, the union does too (never 0 where a part is not).
        let a = LightBounds::spot(DVec3::ZERO, -DVec3::Z, 0.9, 1.0);
        let b = LightBounds::surface(
            &[DVec3::new(3.0, 0.0, 1.0), DVec3::new(4.0, 1.0, 1.0)],
            DVec3::X,
            2.0,
            false,
        );
        let u = a.union(&b);
        assert!(u.is_valid());
        for d in directions(500) {
            let p = DVec3::new(1.5, 0.5, 0.5) + 4.0 * d;
            if a.importance(p) > 0.0 || b.importance(p) > 0.0 {
                assert!(u.importance(p) > 0.0, "{p}");
            }
        }
    }
}
