//! The geometry benchmark's fixed scenes: a bumpy triangle sphere and a deterministic bundle of
//! rays towards it.
//!
//! They are shared by the divan benchmark (`benches/geometry.rs`) and by the comparison with
//! Embree (`examples/ray_rate.rs`, run by `cargo xtask peer --geometry`), so that both measure
//! rays per second on exactly the same mesh and the same rays. Nothing here is random: the same
//! arguments always give the same scene, bit for bit.

use std::f64::consts::PI;

use glam::DVec3;

use crate::{GeometryError, Mesh, Ray, Shape};

/// The `n` of [`bumpy_sphere`] the benchmarks use: 4 x 160^2 = 102,400 triangles.
pub const BENCH_SPHERE_N: u32 = 160;

/// The `t_max` of the benchmark's shadow rays: [`rays`] start at distance 3 from the centre and
/// aim into the unit ball, so most of them are blocked by the sphere (radius ~1) before 2.5.
pub const SHADOW_T_MAX: f64 = 2.5;

/// The vertices and triangles of [`bumpy_sphere`]`(n)`: a UV sphere of `n` rings of `2 n` quads,
/// each split into two triangles (4 n^2 triangles, `(n + 1) 2 n` vertices, with the poles'
/// vertices repeated, so the triangles touching a pole are degenerate), whose radius varies as
/// `1 + 0.05 sin(7 theta) cos(5 phi)`.
pub fn bumpy_sphere_triangles(n: u32) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let mut positions = Vec::new();
    for i in 0..=n {
        let theta = PI * f64::from(i) / f64::from(n);
        for j in 0..2 * n {
            let phi = PI * f64::from(j) / f64::from(n);
            let r = 1.0 + 0.05 * (7.0 * theta).sin() * (5.0 * phi).cos();
            positions.push(
                DVec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin()) * r,
            );
        }
    }
    let idx = |i: u32, j: u32| i * 2 * n + j % (2 * n);
    let mut triangles = Vec::new();
    for i in 0..n {
        for j in 0..2 * n {
            triangles.push([idx(i, j), idx(i + 1, j), idx(i + 1, j + 1)]);
            triangles.push([idx(i, j), idx(i + 1, j + 1), idx(i, j + 1)]);
        }
    }
    (positions, triangles)
}

/// A UV sphere of `n x 2n` quads (4 n^2 triangles) with a bumpy radius, as a mesh shape (see
/// [`bumpy_sphere_triangles`]); `n = `[`BENCH_SPHERE_N`] is the benchmark's mesh.
///
/// # Errors
/// As [`Mesh::from_triangles`]: for `n = 0` (no triangles), or an `n` so large that the mesh
/// exceeds the mesh limits.
pub fn bumpy_sphere(n: u32) -> Result<Shape, GeometryError> {
    let (positions, triangles) = bumpy_sphere_triangles(n);
    Ok(Mesh::from_triangles(positions, triangles)?.into())
}

/// `count` deterministic rays from a sphere of radius 3 around the origin towards points of the
/// ball of radius 0.5: origins on a Fibonacci spiral, targets on a Lissajous-like curve, so the
/// rays cross the unit sphere at all angles, from head-on to grazing. Directions are unit.
pub fn rays(count: usize) -> Vec<Ray> {
    (0..count)
        .map(|k| {
            let a = k as f64 * 2.399_963;
            let z = 1.0 - 2.0 * (k as f64 + 0.5) / count as f64;
            let s = (1.0 - z * z).sqrt();
            let origin = DVec3::new(s * a.cos(), z, s * a.sin()) * 3.0;
            let target = DVec3::new((a * 1.7).sin(), (a * 2.3).cos(), (a * 0.7).sin()) * 0.5;
            Ray::new(origin, target - origin)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]

    use super::{BENCH_SPHERE_N, SHADOW_T_MAX, bumpy_sphere, bumpy_sphere_triangles, rays};
    use crate::World;

    #[test]
    fn the_bench_scene_has_its_documented_size_and_is_deterministic() {
        let (positions, triangles) = bumpy_sphere_triangles(BENCH_SPHERE_N);
        assert_eq!(triangles.len(), 4 * 160 * 160);
        assert_eq!(positions.len(), 161 * 320);
        assert_eq!(bumpy_sphere_triangles(BENCH_SPHERE_N), (positions, triangles));
        assert_eq!(rays(1000), rays(1000));
        assert!(rays(1000).iter().all(|r| (r.direction.length() - 1.0).abs() < 1e-12));
        assert!(bumpy_sphere(0).is_err());
    }

    #[test]
    fn most_rays_hit_and_most_shadow_rays_are_blocked() {
        let world = World::new(vec![bumpy_sphere(20).unwrap()]).unwrap();
        let rays = rays(2000);
        let hits = rays.iter().filter(|r| world.intersect(r, f64::INFINITY).is_some()).count();
        let blocked = rays.iter().filter(|r| world.occluded(r, SHADOW_T_MAX)).count();
        assert!(hits > 1900, "{hits}");
        assert!(blocked > 1900 && blocked <= hits, "{blocked}");
    }
}
