//! Warps from the unit square to disks, hemispheres, spheres and cones, pbrt style: each
//! `sample_*` comes with its density (`pdf_*`, per unit area for the disk and per steradian for
//! directions) and, where the inverse is natural, `invert_*` taking the sample back to the square.
//!
//! Directions are returned in a *local* space with the axis along `+z`; [`Frame::to_world`]
//! turns them around any unit normal. Every warp takes its two uniforms as `u: [f64; 2]` in
//! `[0, 1)`; values outside (or NaN) are clamped into it by [`clamp_uniform`], never a panic.
//!
//! [`Frame::to_world`]: crate::Frame::to_world

use std::f64::consts::{FRAC_1_PI, FRAC_PI_2, FRAC_PI_4, PI, TAU};

use glam::DVec3;

use crate::{clamp_uniform, sin_cos_turn};

/// `sin theta` from `cos theta`, as `sqrt((1 - c)(1 + c))` (no cancellation near `c = +-1`, where
/// `1 - c^2` would lose the digits), clamped at 0 for `|c| > 1` by rounding.
#[inline]
pub fn sin_from_cos(cos_theta: f64) -> f64 {
    ((1.0 - cos_theta) * (1.0 + cos_theta)).max(0.0).sqrt()
}

/// `1 - cos(angle)` for an angle in radians, computed as `2 sin^2(angle / 2)`: full relative
/// precision for narrow angles, where `1 - cos` cancels to 0.
#[inline]
pub fn one_minus_cos(angle: f64) -> f64 {
    let half = angle / 2.0;
    2.0 * half.sin() * half.sin()
}

/// The local direction `(sin theta cos phi, sin theta sin phi, cos theta)`.
#[inline]
pub fn spherical_direction(sin_theta: f64, cos_theta: f64, phi: f64) -> DVec3 {
    DVec3::new(sin_theta * phi.cos(), sin_theta * phi.sin(), cos_theta)
}

/// [`spherical_direction`] with the azimuth as a fraction of a turn, `phi = 2 pi turn` for
/// `turn` in `[0, 1)`, through [`sin_cos_turn`] (exact reduction, no C library call).
#[inline]
pub fn spherical_direction_turn(sin_theta: f64, cos_theta: f64, turn: f64) -> DVec3 {
    let (s, c) = sin_cos_turn(turn);
    DVec3::new(sin_theta * c, sin_theta * s, cos_theta)
}

/// The azimuth of a local direction (or disk point) as a fraction of a turn, in `[0, 1)`.
#[inline]
fn azimuth_fraction(x: f64, y: f64) -> f64 {
    let f = y.atan2(x) / TAU;
    clamp_uniform(if f < 0.0 { f + 1.0 } else { f })
}

// ---------------------------------------------------------------------------------------------
// Disk
// ---------------------------------------------------------------------------------------------

/// A point uniform on the unit disk, `[x, y]`, by Shirley and Chiu's concentric map (squares to
/// rings, so strata stay compact and the map is area-preserving up to the constant `pi / 4`).
#[inline]
pub fn sample_uniform_disk_concentric(u: [f64; 2]) -> [f64; 2] {
    let (a, b) = (2.0 * clamp_uniform(u[0]) - 1.0, 2.0 * clamp_uniform(u[1]) - 1.0);
    if a == 0.0 && b == 0.0 {
        return [0.0, 0.0];
    }
    let (r, phi) = if a.abs() > b.abs() {
        (a, FRAC_PI_4 * (b / a))
    } else {
        (b, FRAC_PI_2 - FRAC_PI_4 * (a / b))
    };
    [r * phi.cos(), r * phi.sin()]
}

/// Density per unit area of [`sample_uniform_disk_concentric`] at `p`: `1 / pi` on the unit disk,
/// 0 outside it.
#[inline]
pub fn pdf_uniform_disk_concentric(p: [f64; 2]) -> f64 {
    if p[0] * p[0] + p[1] * p[1] <= 1.0 { FRAC_1_PI } else { 0.0 }
}

/// The `u` that [`sample_uniform_disk_concentric`] maps to the disk point `p` (to rounding),
/// in `[0, 1)`.
pub fn invert_uniform_disk_concentric(p: [f64; 2]) -> [f64; 2] {
    let [x, y] = p;
    let r = x.hypot(y);
    if r == 0.0 {
        return [0.5, 0.5];
    }
    // The polar angle, taken in [-pi/4, 7pi/4) so each quadrant of the square is one interval.
    let mut theta = y.atan2(x);
    if theta < -FRAC_PI_4 {
        theta += TAU;
    }
    let (a, b) = if theta < FRAC_PI_4 {
        (r, theta * r / FRAC_PI_4)
    } else if theta < 3.0 * FRAC_PI_4 {
        (-(theta - FRAC_PI_2) * r / FRAC_PI_4, r)
    } else if theta < 5.0 * FRAC_PI_4 {
        (-r, (theta - PI) * -r / FRAC_PI_4)
    } else {
        ((theta - 3.0 * FRAC_PI_2) * r / FRAC_PI_4, -r)
    };
    [clamp_uniform((a + 1.0) / 2.0), clamp_uniform((b + 1.0) / 2.0)]
}

// ---------------------------------------------------------------------------------------------
// Hemisphere, cosine-weighted
// ---------------------------------------------------------------------------------------------

/// A cosine-weighted local direction (density `cos theta / pi` about `+z`), by Malley's method with
/// the polar map: `cos theta = sqrt(1 - u[0])`, `phi = 2 pi u[1]`. The cosine is `> 0` for every
/// `u[0] < 1`, so the direction is never tangent and its density never 0.
#[inline]
pub fn sample_cosine_hemisphere(u: [f64; 2]) -> DVec3 {
    let u0 = clamp_uniform(u[0]);
    let r = u0.sqrt();
    let cos_theta = (1.0 - u0).sqrt();
    let (s, c) = sin_cos_turn(clamp_uniform(u[1]));
    DVec3::new(r * c, r * s, cos_theta)
}

/// Density per steradian of a cosine-weighted direction with the given cosine to the axis:
/// `cos theta / pi`, 0 below the horizon.
#[inline]
pub fn pdf_cosine_hemisphere(cos_theta: f64) -> f64 {
    cos_theta.max(0.0) * FRAC_1_PI
}

/// The `u` that [`sample_cosine_hemisphere`] maps to the unit local direction `w` (to
/// rounding), in `[0, 1)`.
#[inline]
pub fn invert_cosine_hemisphere(w: DVec3) -> [f64; 2] {
    [clamp_uniform(w.x * w.x + w.y * w.y), azimuth_fraction(w.x, w.y)]
}

/// A cosine-weighted local direction by Malley's method with the concentric map (pbrt's
/// `SampleCosineHemisphere`): a uniform point on the disk lifted to `z = sqrt(1 - x^2 - y^2)`.
/// Same density as [`sample_cosine_hemisphere`] ([`pdf_cosine_hemisphere`]), a different map;
/// `z` may round to 0 at the disk's rim (`u` with a coordinate exactly 0).
#[inline]
pub fn sample_cosine_hemisphere_concentric(u: [f64; 2]) -> DVec3 {
    let [x, y] = sample_uniform_disk_concentric(u);
    let z = (1.0 - x * x - y * y).max(0.0).sqrt();
    DVec3::new(x, y, z)
}

/// The `u` that [`sample_cosine_hemisphere_concentric`] maps to the local direction `w`: the
/// concentric inverse of its projection on the disk.
#[inline]
pub fn invert_cosine_hemisphere_concentric(w: DVec3) -> [f64; 2] {
    invert_uniform_disk_concentric([w.x, w.y])
}

// ---------------------------------------------------------------------------------------------
// Hemisphere and sphere, uniform
// ---------------------------------------------------------------------------------------------

/// A local direction uniform on the upper hemisphere (`z >= 0`): `cos theta = u[0]`,
/// `phi = 2 pi u[1]`.
#[inline]
pub fn sample_uniform_hemisphere(u: [f64; 2]) -> DVec3 {
    let z = clamp_uniform(u[0]);
    spherical_direction_turn(sin_from_cos(z), z, clamp_uniform(u[1]))
}

/// Density per steradian of [`sample_uniform_hemisphere`]: `1 / (2 pi)`.
#[inline]
pub fn pdf_uniform_hemisphere() -> f64 {
    1.0 / TAU
}

/// The `u` that [`sample_uniform_hemisphere`] maps to the unit local direction `w`.
#[inline]
pub fn invert_uniform_hemisphere(w: DVec3) -> [f64; 2] {
    [clamp_uniform(w.z), azimuth_fraction(w.x, w.y)]
}

/// A direction uniform on the unit sphere: `cos theta = 1 - 2 u[0]`, `phi = 2 pi u[1]`.
#[inline]
pub fn sample_uniform_sphere(u: [f64; 2]) -> DVec3 {
    let z = 1.0 - 2.0 * clamp_uniform(u[0]);
    spherical_direction_turn(sin_from_cos(z), z, clamp_uniform(u[1]))
}

/// Density per steradian of [`sample_uniform_sphere`]: `1 / (4 pi)`.
#[inline]
pub fn pdf_uniform_sphere() -> f64 {
    1.0 / (4.0 * PI)
}

/// The `u` that [`sample_uniform_sphere`] maps to the unit direction `w`.
#[inline]
pub fn invert_uniform_sphere(w: DVec3) -> [f64; 2] {
    [clamp_uniform((1.0 - w.z) / 2.0), azimuth_fraction(w.x, w.y)]
}

// ---------------------------------------------------------------------------------------------
// Cone
// ---------------------------------------------------------------------------------------------

/// A local direction uniform (per steradian) in the cone about `+z` of half-angle `theta_max`,
/// given as `one_minus_cos_max = 1 - cos(theta_max)` in `(0, 2]` (see [`one_minus_cos`]; passing
/// `1 - cos` rather than `cos` keeps narrow cones exact, where `cos(theta_max)` rounds to 1):
/// `1 - cos theta = u[0] (1 - cos theta_max)`, `phi = 2 pi u[1]`; `sin theta` comes from
/// `1 - cos theta` as `sqrt(t (2 - t))`, so a cone too narrow for `cos theta` to differ from 1
/// still spreads its directions over its full width.
#[inline]
pub fn sample_uniform_cone(u: [f64; 2], one_minus_cos_max: f64) -> DVec3 {
    let t = clamp_uniform(u[0]) * one_minus_cos_max;
    let sin_theta = (t * (2.0 - t)).max(0.0).sqrt();
    spherical_direction_turn(sin_theta, 1.0 - t, clamp_uniform(u[1]))
}

/// Density per steradian of [`sample_uniform_cone`] inside the cone: `1 / (2 pi (1 - cos
/// theta_max))`.
#[inline]
pub fn pdf_uniform_cone(one_minus_cos_max: f64) -> f64 {
    1.0 / (TAU * one_minus_cos_max)
}

/// The `u` that [`sample_uniform_cone`] maps to the unit local direction `w` inside the cone.
#[inline]
pub fn invert_uniform_cone(w: DVec3, one_minus_cos_max: f64) -> [f64; 2] {
    // 1 - cos theta from the tangential part, without cancellation: s^2 / (1 + c).
    let s2 = w.x * w.x + w.y * w.y;
    let one_minus_cos = if w.z > 0.0 { s2 / (1.0 + w.z) } else { 1.0 - w.z };
    [clamp_uniform(one_minus_cos / one_minus_cos_max), azimuth_fraction(w.x, w.y)]
}
