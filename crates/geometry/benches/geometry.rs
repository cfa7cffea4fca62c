//! Rays per second through the BVH for a mesh of ~100k triangles (closest hit and shadow rays),
//! with `obvhs`'s own traversal of the same BVH over the same rays as the peer (its f32
//! Moller-Trumbore `Triangle`), against brute force on a small subset, and against the analytic
//! shapes.
#![allow(clippy::unwrap_used, missing_docs)]

use std::f64::consts::PI;

use divan::Bencher;
use glam::DVec3;
use obvhs::ray::RayHit;
use obvhs::triangle::Triangle;
use spectrace_geometry::{Mesh, Ray, Shape, Sphere, Torus, World};

fn main() {
    divan::main();
}

/// A UV sphere of `n x 2n` quads (4 n^2 triangles) with a bumpy radius.
fn bumpy_sphere(n: u32) -> Shape {
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
    Mesh::from_triangles(positions, triangles).unwrap().into()
}

/// Deterministic rays from a sphere of radius 3 towards the unit ball.
fn rays(count: usize) -> Vec<Ray> {
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

#[divan::bench(sample_count = 10)]
fn bvh_mesh_100k_triangles(bencher: Bencher<'_, '_>) {
    let world = World::new(vec![bumpy_sphere(160)]).unwrap();
    let rays = rays(10_000);
    bencher
        .counter(divan::counter::ItemsCount::new(rays.len()))
        .bench(|| rays.iter().filter(|r| world.intersect(r, f64::INFINITY).is_some()).count());
}

#[divan::bench(sample_count = 10)]
fn bvh_mesh_100k_triangles_shadow_rays(bencher: Bencher<'_, '_>) {
    let world = World::new(vec![bumpy_sphere(160)]).unwrap();
    // Shadow rays towards the centre, stopping at distance 2.5: most are blocked by the mesh.
    let rays = rays(10_000);
    bencher
        .counter(divan::counter::ItemsCount::new(rays.len()))
        .bench(|| rays.iter().filter(|r| world.occluded(r, 2.5)).count());
}

/// The peer: `obvhs`'s own `Bvh2::ray_traverse` over the world's BVH (same nodes, same rays,
/// rounded to f32), with its `Triangle::intersect` (f32, not watertight).
#[divan::bench(sample_count = 10)]
fn obvhs_traversal_mesh_100k_triangles(bencher: Bencher<'_, '_>) {
    let shape = bumpy_sphere(160);
    let Shape::Mesh(mesh) = &shape else { unreachable!() };
    let tris: Vec<Triangle> = mesh
        .triangles()
        .iter()
        .map(|t| {
            let v = t.map(|i| mesh.positions()[i as usize].as_vec3a());
            Triangle { v0: v[0], v1: v[1], v2: v[2] }
        })
        .collect();
    let world = World::new(vec![shape.clone()]).unwrap();
    let bvh = world.obvhs_bvh();
    let rays: Vec<obvhs::ray::Ray> = rays(10_000)
        .iter()
        .map(|r| obvhs::ray::Ray::new_inf(r.origin.as_vec3a(), r.direction.as_vec3a()))
        .collect();
    bencher.counter(divan::counter::ItemsCount::new(rays.len())).bench(|| {
        rays.iter()
            .filter(|&&r| {
                let mut hit = RayHit::none();
                bvh.ray_traverse(r, &mut hit, |ray, id| {
                    tris[bvh.primitive_indices[id] as usize].intersect(ray)
                })
            })
            .count()
    });
}

#[divan::bench(sample_count = 10)]
fn brute_force_mesh_2k_triangles(bencher: Bencher<'_, '_>) {
    let world = World::new(vec![bumpy_sphere(22)]).unwrap();
    let rays = rays(200);
    bencher.counter(divan::counter::ItemsCount::new(rays.len())).bench(|| {
        rays.iter().filter(|r| world.intersect_brute_force(r, f64::INFINITY).is_some()).count()
    });
}

#[divan::bench(sample_count = 10)]
fn bvh_sphere_and_torus(bencher: Bencher<'_, '_>) {
    let world = World::new(vec![
        Sphere::new(DVec3::ZERO, 0.5).unwrap().into(),
        Torus::new(DVec3::ZERO, DVec3::Y, 0.8, 0.15).unwrap().into(),
    ])
    .unwrap();
    let rays = rays(10_000);
    bencher
        .counter(divan::counter::ItemsCount::new(rays.len()))
        .bench(|| rays.iter().filter(|r| world.intersect(r, f64::INFINITY).is_some()).count());
}
