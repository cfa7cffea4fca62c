//! Tests of `spectrace-materials` through its public API (one integration-test binary): Fresnel
//! and Snell against closed forms, dispersion against published glass data, the Lambertian
//! lobe's distribution (chi-square and Kolmogorov-Smirnov at fixed seeds), eval/pdf/scatter
//! consistency, energy bookkeeping, serialisation round trips, error messages, property tests of
//! finiteness and unit directions, and checks of the measured metal tables in `data/metals/`.
#![allow(clippy::unwrap_used)]

mod bundles;
mod conductor;
mod dielectric;
mod diffuse;
mod dispersion;
mod fluorescent;
mod fresnel;
mod harness;
mod metal_data;
mod mirror;
mod plastic;
mod properties;
mod rough_dielectric;
mod serde_forms;

use glam::DVec3;
use rand::Rng;
use spectrace_materials::Incoming;

/// Significance level of every statistical test here: a correct material fails one at a random
/// seed with probability 1e-3 (seeds are fixed, so the outcome is reproducible).
pub const ALPHA: f64 = 1e-3;

/// A uniform in `[0, 1)` (53 random bits), as the renderer draws them.
pub fn uniform(rng: &mut impl Rng) -> f64 {
    spectrace_sampling::uniform(rng)
}

/// A unit vector from two uniforms (uniform on the sphere).
pub fn sphere(u: f64, v: f64) -> DVec3 {
    spectrace_sampling::sample_uniform_sphere([u, v]).normalize()
}

/// A random unit vector.
pub fn random_unit(rng: &mut impl Rng) -> DVec3 {
    sphere(uniform(rng), uniform(rng))
}

/// A beam travelling along `direction` onto a surface with outward `normal`.
pub fn beam(direction: DVec3, normal: DVec3, lambda: f64) -> Incoming {
    Incoming { direction: direction.normalize(), normal: normal.normalize(), lambda }
}

/// A unit direction making angle `theta` (radians) with `-normal`, travelling towards a
/// surface with the given unit normal, in the plane spanned by the normal and `tangent`.
pub fn at_angle(theta: f64, normal: DVec3, tangent: DVec3) -> DVec3 {
    (tangent * theta.sin() - normal * theta.cos()).normalize()
}

/// `sin` of the angle between a unit direction and a unit normal, cancellation-free.
pub fn sin_to(d: DVec3, n: DVec3) -> f64 {
    d.cross(n).length()
}
