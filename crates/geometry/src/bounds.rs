//! [`Bounds`]: an axis-aligned box in f64.

use glam::DVec3;

/// An axis-aligned box `[min, max]` (m). Empty when any `min > max`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bounds {
    /// Smallest corner.
    pub min: DVec3,
    /// Largest corner.
    pub max: DVec3,
}

impl Bounds {
    /// The empty box (`min = +inf`, `max = -inf`).
    pub const EMPTY: Self =
        Self { min: DVec3::splat(f64::INFINITY), max: DVec3::splat(f64::NEG_INFINITY) };

    /// The box around the given points.
    pub fn from_points(points: impl IntoIterator<Item = DVec3>) -> Self {
        points.into_iter().fold(Self::EMPTY, |b, p| b.with_point(p))
    }

    /// This box grown to contain `p`.
    pub fn with_point(self, p: DVec3) -> Self {
        Self { min: self.min.min(p), max: self.max.max(p) }
    }

    /// The smallest box containing both.
    pub fn union(self, other: Self) -> Self {
        Self { min: self.min.min(other.min), max: self.max.max(other.max) }
    }

    /// This box grown by `margin` on every side.
    pub fn expanded(self, margin: DVec3) -> Self {
        Self { min: self.min - margin, max: self.max + margin }
    }

    /// Whether the box holds no point.
    pub fn is_empty(&self) -> bool {
        self.min.cmpgt(self.max).any()
    }

    /// Whether `p` is inside or on the box.
    pub fn contains(&self, p: DVec3) -> bool {
        p.cmpge(self.min).all() && p.cmple(self.max).all()
    }

    /// The centre.
    pub fn center(&self) -> DVec3 {
        (self.min + self.max) * 0.5
    }

    /// `max - min`.
    pub fn diagonal(&self) -> DVec3 {
        self.max - self.min
    }

    /// The parameter interval `(t0, t1)` in which the ray `origin + t direction` is inside the box,
    /// clipped to `[0, t_max]`, or `None`. Conservative: `t1` is enlarged by `2 gamma(3)` as in
    /// pbrt, so rounding never loses an overlap; a zero direction component is handled by IEEE
    /// infinities (NaNs from `0 * inf` are ignored, which only widens the interval).
    pub fn ray_interval(
        &self,
        origin: DVec3,
        inv_direction: DVec3,
        t_max: f64,
    ) -> Option<(f64, f64)> {
        let mut t0 = 0.0_f64;
        let mut t1 = t_max;
        let widen = 1.0 + 2.0 * crate::float::gamma(3);
        for i in 0..3 {
            let mut near = (self.min[i] - origin[i]) * inv_direction[i];
            let mut far = (self.max[i] - origin[i]) * inv_direction[i];
            if near > far {
                std::mem::swap(&mut near, &mut far);
            }
            far *= widen;
            t0 = if near > t0 { near } else { t0 };
            t1 = if far < t1 { far } else { t1 };
            if t0 > t1 {
                return None;
            }
        }
        Some((t0, t1))
    }
}
