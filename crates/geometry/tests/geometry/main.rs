//! Tests of `spectrace-geometry` through its public API, one module per subject: accuracy far from the origin, tangent and
//! grazing rays, watertightness, self-intersection after spawning, a closed mirror box, the torus,
//! transforms, scene-file validation, OBJ loading, and the BVH against brute force.
#![allow(clippy::unwrap_used)]

use std::f64::consts::PI;
use std::path::Path;

use glam::{DMat4, DVec3};
use proptest::prelude::*;
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64;
use spectrace_geometry::*;

pub(crate) fn v(x: f64, y: f64, z: f64) -> DVec3 {
    DVec3::new(x, y, z)
}

pub(crate) fn rng(seed: u64) -> Pcg64 {
    Pcg64::seed_from_u64(seed)
}

/// A uniform random unit vector.
pub(crate) fn unit(r: &mut Pcg64) -> DVec3 {
    let z: f64 = r.random_range(-1.0..1.0);
    let phi: f64 = r.random_range(0.0..2.0 * PI);
    let s = (1.0 - z * z).sqrt();
    v(s * phi.cos(), s * phi.sin(), z)
}

/// A random unit vector in the hemisphere around `n`.
pub(crate) fn hemisphere(r: &mut Pcg64, n: DVec3) -> DVec3 {
    let d = unit(r);
    if d.dot(n) < 0.0 { -d } else { d }
}

pub(crate) fn reflect(d: DVec3, n: DVec3) -> DVec3 {
    d - n * (2.0 * d.dot(n))
}

pub(crate) fn shape(json: &str) -> Shape {
    serde_json::from_str(json).unwrap()
}

pub(crate) fn shape_err(json: &str) -> String {
    serde_json::from_str::<Shape>(json).unwrap_err().to_string()
}

mod bvh;
mod hostile;
mod intersection;
mod sampling;
mod scene_files;

// Helpers of one module are used by others: each module sees all of them through `super::*`.
#[allow(unused_imports)]
use {bvh::*, hostile::*, intersection::*, sampling::*, scene_files::*};
