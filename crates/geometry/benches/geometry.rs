//! Rays per second through the BVH for a mesh of ~100k triangles (closest hit and shadow rays),
//! with `obvhs`'s own traversal of the same BVH over the same rays as the peer (its f32
//! Moller-Trumbore `Triangle`), against brute force on a small subset, and against the analytic
//! shapes. The mesh and the rays are `spectrace_geometry::bench_scenes`, shared with the comparison
//! with Embree (`cargo xtask peer --geometry`).
#![allow(clippy::unwrap_used, missing_docs)]

use divan::Bencher;
use glam::DVec3;
use obvhs::ray::RayHit;
use obvhs::triangle::Triangle;
use spectrace_geometry::bench_scenes::{BENCH_SPHERE_N, SHADOW_T_MAX, bumpy_sphere, rays};
use spectrace_geometry::{Shape, Sphere, Torus, World};

fn main() {
    divan::main();
}

#[divan::bench(sample_count = 10)]
fn bvh_mesh_100k_triangles(bencher: Bencher<'_, '_>) {
    let world = World::new(vec![bumpy_sphere(BENCH_SPHERE_N).unwrap()]).unwrap();
    let rays = rays(10_000);
    bencher
        .counter(divan::counter::ItemsCount::new(rays.len()))
        .bench(|| rays.iter().filter(|r| world.intersect(r, f64::INFINITY).is_some()).count());
}

#[divan::bench(sample_count = 10)]
fn bvh_mesh_100k_triangles_shadow_rays(bencher: Bencher<'_, '_>) {
    let world = World::new(vec![bumpy_sphere(BENCH_SPHERE_N).unwrap()]).unwrap();
    // Shadow rays towards the centre, stopping at SHADOW_T_MAX (2.5): most are blocked.
    let rays = rays(10_000);
    bencher
        .counter(divan::counter::ItemsCount::new(rays.len()))
        .bench(|| rays.iter().filter(|r| world.occluded(r, SHADOW_T_MAX)).count());
}

/// The peer: `obvhs`'s own `Bvh2::ray_traverse` over the world's BVH (same nodes, same rays,
/// rounded to f32), with its `Triangle::intersect` (f32, not watertight).
#[divan::bench(sample_count = 10)]
fn obvhs_traversal_mesh_100k_triangles(bencher: Bencher<'_, '_>) {
    let shape = bumpy_sphere(BENCH_SPHERE_N).unwrap();
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
    let world = World::new(vec![bumpy_sphere(22).unwrap()]).unwrap();
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
