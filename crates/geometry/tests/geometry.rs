//! Tests of `spectrace-geometry` through its public API: accuracy far from the origin, tangent and
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

fn v(x: f64, y: f64, z: f64) -> DVec3 {
    DVec3::new(x, y, z)
}

fn rng(seed: u64) -> Pcg64 {
    Pcg64::seed_from_u64(seed)
}

/// A uniform random unit vector.
fn unit(r: &mut Pcg64) -> DVec3 {
    let z: f64 = r.random_range(-1.0..1.0);
    let phi: f64 = r.random_range(0.0..2.0 * PI);
    let s = (1.0 - z * z).sqrt();
    v(s * phi.cos(), s * phi.sin(), z)
}

/// A random unit vector in the hemisphere around `n`.
fn hemisphere(r: &mut Pcg64, n: DVec3) -> DVec3 {
    let d = unit(r);
    if d.dot(n) < 0.0 { -d } else { d }
}

fn reflect(d: DVec3, n: DVec3) -> DVec3 {
    d - n * (2.0 * d.dot(n))
}

fn shape(json: &str) -> Shape {
    serde_json::from_str(json).unwrap()
}

fn shape_err(json: &str) -> String {
    serde_json::from_str::<Shape>(json).unwrap_err().to_string()
}

// ---------------------------------------------------------------------------------------------
// Sphere accuracy and tangents

#[test]
fn sphere_radius_1_at_distance_1e5_hit_at_right_t() {
    let c = v(1e5, 2e4, -3e4);
    let world = World::new(vec![Sphere::new(c, 1.0).unwrap().into()]).unwrap();
    let mut r = rng(1);
    for _ in 0..2000 {
        let origin = unit(&mut r) * r.random_range(0.0..10.0);
        // A point on the half of the sphere facing the origin, within 60 degrees of it.
        let towards = (origin - c).normalize();
        let n = loop {
            let n = unit(&mut r);
            if n.dot(towards) > 0.5 {
                break n;
            }
        };
        let p = c + n * 1.0;
        let t_true = (p - origin).length();
        let ray = Ray::new(origin, p - origin);
        let hit = world.intersect(&ray, f64::INFINITY).unwrap();
        assert!((hit.t - t_true).abs() <= 1e-12 * t_true, "t {} vs {}", hit.t, t_true);
        assert!((hit.point - p).length() < 1e-6);
        assert!((hit.geometric_normal - n).length() < 1e-6);
        assert!(hit.error.max_element() < 1e-9 && hit.error.min_element() > 0.0);
    }
}

#[test]
fn ray_tangent_to_sphere_is_consistent_and_finite() {
    for c in [DVec3::ZERO, v(1e5, -1e5, 3e5)] {
        let s = Sphere::new(c, 1.0).unwrap();
        let sh: Shape = s.into();
        for start in [-10.0, -3.0, -1e3] {
            // Exactly tangent at c + (1, 0, 0).
            let ray = Ray::new(c + v(1.0, start, 0.0), v(0.0, 1.0, 0.0));
            if let Some(h) = sh.intersect(&ray, f64::INFINITY) {
                assert!(h.t.is_finite() && h.point.is_finite() && h.geometric_normal.is_finite());
                assert!((h.point - (c + v(1.0, 0.0, 0.0))).length() < 1e-4, "{h:?}");
                assert!((h.t + start).abs() < 1e-4 * start.abs().max(1.0));
            }
            // Just inside: always a hit, near the tangent point; just outside: always a miss.
            let inside = Ray::new(c + v(1.0 - 1e-6, start, 0.0), v(0.0, 1.0, 0.0));
            let h = sh.intersect(&inside, f64::INFINITY).unwrap();
            assert!(h.point.is_finite() && (h.point - (c + v(1.0, 0.0, 0.0))).length() < 3e-3);
            let outside = Ray::new(c + v(1.0 + 1e-6, start, 0.0), v(0.0, 1.0, 0.0));
            assert!(sh.intersect(&outside, f64::INFINITY).is_none());
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Grazing rays

#[test]
fn grazing_rays_hit_rectangles_and_triangles_at_the_right_point() {
    let rect: Shape =
        Rectangle::new(v(-1.0, 0.0, -1.0), v(0.0, 0.0, 2.0), v(2.0, 0.0, 0.0)).unwrap().into();
    let tris: Shape = Mesh::from_triangles(
        vec![v(-1.0, 0.0, -1.0), v(-1.0, 0.0, 1.0), v(1.0, 0.0, 1.0), v(1.0, 0.0, -1.0)],
        vec![[0, 1, 2], [0, 2, 3]],
    )
    .unwrap()
    .into();
    let mut r = rng(2);
    for s in [&rect, &tris] {
        for _ in 0..1000 {
            let target = v(r.random_range(-0.9..0.9), 0.0, r.random_range(-0.9..0.9));
            let angle: f64 = 10f64.powf(r.random_range(-9.0..-3.0));
            let az: f64 = r.random_range(0.0..2.0 * PI);
            let below = r.random_bool(0.5);
            let dir = v(az.cos() * angle.cos(), -angle.sin(), az.sin() * angle.cos());
            let dir = if below { v(dir.x, -dir.y, dir.z) } else { dir };
            let dist = 0.05;
            let ray = Ray::new(target - dir * dist, dir);
            let h = s.intersect(&ray, f64::INFINITY).unwrap_or_else(|| panic!("{ray:?}"));
            // The point is on the plane; along the ray it may be off by ~eps / angle.
            assert!(h.point.y.abs() <= h.error.y + 1e-300, "{h:?}");
            assert!((h.point - target).length() < 1e-15 / angle + 1e-12, "{h:?}");
            assert!((h.t - dist).abs() < 1e-15 / angle + 1e-12);
        }
        // Exactly in the plane: a miss, and nothing is NaN.
        let ray = Ray::new(v(-2.0, 0.0, 0.3), v(1.0, 0.0, 0.0));
        assert!(s.intersect(&ray, f64::INFINITY).is_none_or(|h| h.t.is_finite()));
    }
}

#[test]
fn shared_edge_rays_never_pass_between_two_triangles() {
    // Two triangles sharing the diagonal (a, b) of a skew quad, and a fan sharing a vertex.
    let (a, b) = (v(0.1, 0.2, 0.3), v(1.3, 0.9, -0.7));
    let mesh = Mesh::from_triangles(
        vec![a, b, v(1.0, -0.5, 0.2), v(0.2, 1.1, -0.4)],
        vec![[0, 2, 1], [0, 1, 3]],
    )
    .unwrap();
    let s: Shape = mesh.into();
    let (c, d) = (v(1.0, -0.5, 0.2), v(0.2, 1.1, -0.4));
    // The same edge in a planar quad (a parallelogram).
    let planar: Shape =
        Mesh::from_triangles(vec![a, b, c, a + b - c], vec![[0, 2, 1], [0, 1, 3]]).unwrap().into();
    let mut r = rng(3);
    let mut tested = 0;
    for _ in 0..20_000 {
        let on_edge = a + (b - a) * r.random_range(0.0..1.0);
        let origin = on_edge + unit(&mut r) * r.random_range(0.1..100.0);
        let ray = Ray::new(origin, on_edge - origin);
        assert!(planar.intersect(&ray, f64::INFINITY).is_some(), "{ray:?} passed the planar edge");
        // In the skew quad the edge is a silhouette from some viewpoints (both triangles on one
        // side); a ray must hit whenever the triangles lie on both sides of the edge as seen.
        let plane = (b - a).cross(on_edge - origin);
        if (c - origin).dot(plane) * (d - origin).dot(plane) < 0.0 {
            tested += 1;
            assert!(s.intersect(&ray, f64::INFINITY).is_some(), "{ray:?} passed through the edge");
        }
    }
    assert!(tested > 5000);
    let center = v(0.3, -0.2, 0.1);
    let n = 12;
    let ring: Vec<DVec3> = (0..n)
        .map(|i| {
            let a = 2.0 * PI * i as f64 / n as f64;
            center + v(a.cos(), a.sin(), 0.3 * (3.0 * a).sin())
        })
        .collect();
    let mut positions = vec![center];
    positions.extend(ring);
    let triangles: Vec<[u32; 3]> = (0..n).map(|i| [0, 1 + i, 1 + (i + 1) % n]).collect();
    let fan: Shape = Mesh::from_triangles(positions, triangles).unwrap().into();
    for _ in 0..5000 {
        let origin = center + unit(&mut r) * r.random_range(0.1..10.0);
        // Steeper than the fan's slopes, so the fan covers all directions around the vertex.
        if (origin - center).normalize().z.abs() < 0.5 {
            continue;
        }
        let ray = Ray::new(origin, center - origin);
        assert!(fan.intersect(&ray, f64::INFINITY).is_some(), "{ray:?} passed through the vertex");
    }
}

// ---------------------------------------------------------------------------------------------
// Self-intersection after spawning

/// Shoots random rays at `shape`, spawns outgoing rays to both sides of each hit, and checks that
/// none re-hits the same surface at t ~ 0 (closed convex shapes see no outward re-hit at all).
fn check_no_acne(shape: Shape, center: DVec3, convex: bool, seed: u64) {
    let world = World::new(vec![shape]).unwrap();
    let scale = world.bounds().diagonal().length();
    let mut r = rng(seed);
    let mut hits = 0;
    for _ in 0..3000 {
        let origin = center + unit(&mut r) * scale * 2.0;
        let target = center + unit(&mut r) * scale * 0.3;
        let Some(h) = world.intersect(&Ray::new(origin, target - origin), f64::INFINITY) else {
            continue;
        };
        hits += 1;
        let n = h.geometric_normal;
        for side in [1.0, -1.0] {
            let dir = hemisphere(&mut r, n * side);
            let ray = h.spawn_ray(dir);
            if let Some(h2) = world.intersect(&ray, f64::INFINITY) {
                assert!(h2.t > 1e-6 * scale, "acne: t = {} at {:?} side {side}", h2.t, h.point);
                if convex && side > 0.0 {
                    panic!("re-hit a convex shape from outside: {h2:?}");
                }
            }
        }
    }
    assert!(hits > 500, "only {hits} hits");
}

#[test]
fn spawned_rays_never_rehit_spheres_near_and_far_from_origin() {
    for (i, c) in [DVec3::ZERO, v(1e5, 0.0, 0.0), v(-3e5, 7e4, 1e5)].into_iter().enumerate() {
        for radius in [1e-3, 1.0, 100.0] {
            check_no_acne(Sphere::new(c, radius).unwrap().into(), c, true, 10 + i as u64);
        }
    }
}

#[test]
fn spawned_rays_never_rehit_planes_cylinders_tori_and_meshes() {
    for (i, c) in [DVec3::ZERO, v(1e5, -2e5, 5e4)].into_iter().enumerate() {
        let seed = 20 + i as u64;
        let rect = Rectangle::new(c - v(1.0, 0.3, 1.0), v(2.0, 0.4, 0.0), v(0.0, 0.3, 2.0));
        check_no_acne(rect.unwrap().into(), c, false, seed);
        check_no_acne(Disk::new(c, v(0.3, 1.0, -0.2), 1.0).unwrap().into(), c, false, seed);
        let cyl = Cylinder::new(c - v(0.0, 0.5, 0.0), v(0.2, 1.0, 0.1), 1.0, 0.7).unwrap();
        check_no_acne(cyl.into(), c, false, seed);
        let torus = Torus::new(c, v(0.1, 1.0, 0.3), 1.0, 0.3).unwrap();
        check_no_acne(torus.into(), c, false, seed);
        let prism = Prism::new(c, 60.0, 1.0, 1.5).unwrap();
        check_no_acne(prism.into(), c, true, seed);
    }
}

/// A closed box of the given half size around `c`, as six inward or outward rectangles.
fn box_rectangles(c: DVec3, h: f64) -> Vec<Shape> {
    let mut shapes = Vec::new();
    for axis in 0..3 {
        let (u, w) = ((axis + 1) % 3, (axis + 2) % 3);
        for sign in [-1.0, 1.0] {
            let mut corner = c - DVec3::splat(h);
            corner[axis] = c[axis] + sign * h;
            let (mut eu, mut ev) = (DVec3::ZERO, DVec3::ZERO);
            eu[u] = 2.0 * h;
            ev[w] = 2.0 * h;
            shapes.push(Rectangle::new(corner, eu, ev).unwrap().into());
        }
    }
    shapes
}

/// The 12-triangle mesh of the same box.
fn box_mesh(c: DVec3, h: f64) -> Shape {
    let p: Vec<DVec3> = (0..8)
        .map(|i| {
            c + v(
                if i & 1 == 0 { -h } else { h },
                if i & 2 == 0 { -h } else { h },
                if i & 4 == 0 { -h } else { h },
            )
        })
        .collect();
    let quads =
        [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    let tris = quads.iter().flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]).collect();
    Mesh::from_triangles(p, tris).unwrap().into()
}

#[test]
fn a_beam_bouncing_1000_times_inside_a_closed_mirror_box_never_escapes_or_sticks() {
    for (k, c) in [DVec3::ZERO, v(1e5, 1e5, -1e5), v(0.25, -3.0, 7.0)].into_iter().enumerate() {
        for (j, h) in [1.0, 1e-2, 40.0].into_iter().enumerate() {
            for shapes in [box_rectangles(c, h), vec![box_mesh(c, h)]] {
                let world = World::new(shapes).unwrap();
                let inside =
                    world.bounds().expanded(DVec3::splat(1e-9 * (h + c.abs().max_element())));
                let mut r = rng(100 + (k * 3 + j) as u64);
                let mut ray = Ray::new(c + unit(&mut r) * 0.3 * h, unit(&mut r));
                let mut last = ray.origin;
                for bounce in 0..1000 {
                    let hit = world
                        .intersect(&ray, f64::INFINITY)
                        .unwrap_or_else(|| panic!("escaped at bounce {bounce} from {ray:?}"));
                    assert!(hit.t > 1e-9 * h, "stuck at bounce {bounce}: t = {}", hit.t);
                    assert!(inside.contains(hit.point), "outside at bounce {bounce}: {hit:?}");
                    assert!((hit.point - last).length() > 0.0);
                    last = hit.point;
                    ray = hit.spawn_ray(reflect(ray.direction, hit.geometric_normal));
                    assert!(inside.contains(ray.origin));
                }
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Torus

#[test]
fn torus_known_rays_hole_axis_and_equator() {
    for c in [DVec3::ZERO, v(3e4, -1e4, 2e4)] {
        let (big, small) = (2.0, 0.5);
        let t: Shape = Torus::new(c, v(0.0, 1.0, 0.0), big, small).unwrap().into();
        // Along the axis (through the hole): miss.
        assert!(t.intersect(&Ray::new(c + v(0.0, 10.0, 0.0), v(0.0, -1.0, 0.0)), 1e9).is_none());
        // Through the hole, slanted but never touching the tube: miss.
        let ray = Ray::new(c + v(-1.0, 5.0, 0.3), v(0.25, -1.0, -0.05));
        assert!(t.intersect(&ray, 1e9).is_none());
        // In the equatorial plane through the centre: hits at distance d - R - r, then the inner
        // wall at d - (R - r), etc.
        let d = 10.0;
        let ray = Ray::new(c + v(-d, 0.0, 0.0), v(1.0, 0.0, 0.0));
        let expect = [d - big - small, d - big + small, d + big - small, d + big + small];
        let mut ray2 = ray;
        let mut travelled = 0.0;
        for (i, e) in expect.iter().enumerate() {
            let h = t.intersect(&ray2, 1e9).unwrap_or_else(|| panic!("root {i} missing"));
            travelled += h.t + (ray2.origin - ray.origin).length() - travelled;
            let along = (h.point - ray.origin).dot(ray.direction);
            assert!((along - e).abs() < 1e-9, "root {i}: {along} vs {e}");
            let expected_n = if i % 2 == 0 { -ray.direction } else { ray.direction };
            assert!((h.geometric_normal - expected_n).length() < 1e-6, "{h:?}");
            ray2 = h.spawn_ray(ray.direction);
        }
        assert!(t.intersect(&ray2, 1e9).is_none());
        // Tangent on top of the tube at y = r: hit or miss, never NaN; just below it always hits.
        let top = Ray::new(c + v(-d, small, 2.0), v(1.0, 0.0, 0.0));
        if let Some(h) = t.intersect(&top, 1e9) {
            assert!(h.point.is_finite() && (h.point.y - c.y - small).abs() < 1e-4);
        }
        let below = Ray::new(c + v(-d, small - 1e-7, 0.0), v(1.0, 0.0, 0.0));
        let h = t.intersect(&below, 1e9).unwrap();
        assert!((h.point.x - c.x + big).abs() < 1e-2);
    }
}

#[test]
fn torus_hits_are_the_first_sign_change_of_the_implicit_function() {
    let (c, axis, big, small) = (v(0.5, -0.2, 0.1), v(0.3, 1.0, -0.2).normalize(), 1.0, 0.35);
    let t: Shape = Torus::new(c, axis, big, small).unwrap().into();
    // Signed distance to the tube, written independently.
    let sdf = |p: DVec3| {
        let q = p - c;
        let z = q.dot(axis);
        let rho = (q - axis * z).length();
        (rho - big).hypot(z) - small
    };
    let mut r = rng(7);
    let mut hits = 0;
    for _ in 0..3000 {
        let origin = c + unit(&mut r) * 3.0;
        let target = c + unit(&mut r) * 1.2;
        let ray = Ray::new(origin, target - origin);
        let first_crossing = {
            let n = 20_000;
            let tmax = 6.0;
            (1..=n).map(|i| tmax * i as f64 / n as f64).find(|&s| sdf(ray.at(s)) < 0.0)
        };
        match t.intersect(&ray, f64::INFINITY) {
            Some(h) => {
                hits += 1;
                assert!(sdf(h.point).abs() < 1e-12, "{}", sdf(h.point));
                // No crossing found noticeably before the reported hit.
                if let Some(s) = first_crossing {
                    assert!(s > h.t - 1e-3, "missed an earlier root: {s} < {}", h.t);
                }
            }
            None => assert!(first_crossing.is_none(), "missed a hit at {first_crossing:?}"),
        }
    }
    assert!(hits > 1000);
}

// ---------------------------------------------------------------------------------------------
// Cylinder, disk, prism

#[test]
fn cylinder_open_hits_from_outside_and_inside_and_misses_along_axis() {
    let cyl: Shape = Cylinder::new(v(0.0, 0.0, 0.0), v(0.0, 1.0, 0.0), 2.0, 1.0).unwrap().into();
    let h = cyl.intersect(&Ray::new(v(-5.0, 1.0, 0.0), v(1.0, 0.0, 0.0)), 1e9).unwrap();
    assert!((h.t - 4.0).abs() < 1e-12 && (h.geometric_normal - v(-1.0, 0.0, 0.0)).length() < 1e-12);
    assert!((h.uv.y - 0.5).abs() < 1e-12);
    let h = cyl.intersect(&Ray::new(v(0.0, 1.0, 0.0), v(0.0, 0.0, 1.0)), 1e9).unwrap();
    assert!((h.t - 1.0).abs() < 1e-12 && (h.geometric_normal - v(0.0, 0.0, 1.0)).length() < 1e-12);
    assert!(cyl.intersect(&Ray::new(v(0.0, -5.0, 0.0), v(0.0, 1.0, 0.0)), 1e9).is_none());
    assert!(cyl.intersect(&Ray::new(v(-5.0, 2.5, 0.0), v(1.0, 0.0, 0.0)), 1e9).is_none());
    // Open: a ray through the top opening hits the inside of the wall at the bottom? no, exits.
    assert!(cyl.intersect(&Ray::new(v(0.0, 5.0, 0.0), v(0.0, -1.0, 0.0)), 1e9).is_none());
}

#[test]
fn disk_hits_inside_radius_only() {
    let d: Shape =
        shape(r#"{"type": "Disk", "center": [1, 2, 3], "normal": [0, 0, 2], "radius": 0.5}"#);
    let h = d.intersect(&Ray::new(v(1.2, 2.2, 10.0), v(0.0, 0.0, -1.0)), 1e9).unwrap();
    assert!((h.t - 7.0).abs() < 1e-12 && h.geometric_normal == v(0.0, 0.0, 1.0));
    assert!(d.intersect(&Ray::new(v(1.4, 2.4, 10.0), v(0.0, 0.0, -1.0)), 1e9).is_none());
}

#[test]
fn prism_is_closed_with_outward_normals() {
    let p: Shape = shape(
        r#"{"type": "Prism", "center": [0, 0.5, 0], "side": 0.3, "length": 0.5,
            "transform": {"rotate": {"axis": [0, 1, 0], "degrees": 30}}}"#,
    );
    assert_eq!(p.primitive_count(), 8);
    let world = World::new(vec![p]).unwrap();
    let c = world.bounds().center();
    let mut r = rng(8);
    for _ in 0..2000 {
        let origin = c + unit(&mut r) * 2.0;
        let h = world.intersect(&Ray::new(origin, c - origin), 1e9).unwrap();
        assert!(h.geometric_normal.dot(c - origin) < 0.0, "normal not outward: {h:?}");
        // From inside, every direction hits a face from behind.
        let inner = world.intersect(&Ray::new(c, unit(&mut r)), 1e9).unwrap();
        assert!(inner.geometric_normal.dot(inner.point - c) > 0.0);
    }
}

// ---------------------------------------------------------------------------------------------
// Transforms

#[test]
fn transform_from_rows_is_row_major_and_matches_glam() {
    let rows =
        [[1.0, 2.0, 3.0, 4.0], [0.0, 1.0, 5.0, 6.0], [0.0, 0.0, 2.0, 7.0], [0.0, 0.0, 0.0, 1.0]];
    let t = Transform::from_rows(rows).unwrap();
    let m = DMat4::from_cols_array_2d(&rows).transpose();
    assert_eq!(t.matrix(), m);
    assert_eq!(t.point(DVec3::ZERO), v(4.0, 6.0, 7.0));
    assert_eq!(t.point(v(1.0, 1.0, 1.0)), v(10.0, 12.0, 9.0));
    assert_eq!(t.to_rows(), rows);
    let json: Transform =
        serde_json::from_str(r#"{"matrix": [[1,2,3,4],[0,1,5,6],[0,0,2,7],[0,0,0,1]]}"#).unwrap();
    assert_eq!(json, t);
}

#[test]
fn transform_parts_apply_scale_then_rotate_then_translate() {
    let t: Transform = serde_json::from_str(
        r#"{"translate": [10, 0, 0], "rotate": {"axis": [0, 0, 1], "degrees": 90}, "scale": [2, 1, 1]}"#,
    )
    .unwrap();
    // (1, 0, 0) -> scale (2, 0, 0) -> rotate (0, 2, 0) -> translate (10, 2, 0).
    assert!((t.point(v(1.0, 0.0, 0.0)) - v(10.0, 2.0, 0.0)).length() < 1e-12);
    let u: Transform = serde_json::from_str(r#"{"scale": 3}"#).unwrap();
    assert!((u.point(v(1.0, 1.0, 1.0)) - v(3.0, 3.0, 3.0)).length() < 1e-15);
    let composed = Transform::scale(v(2.0, 1.0, 1.0))
        .unwrap()
        .then(&Transform::rotate(v(0.0, 0.0, 1.0), 90.0).unwrap())
        .then(&Transform::translate(v(10.0, 0.0, 0.0)).unwrap());
    assert!((composed.matrix() - t.matrix()).abs().to_cols_array().iter().all(|x| *x < 1e-12));
}

#[test]
fn transform_normals_stay_perpendicular_under_non_uniform_scale() {
    let t = Transform::scale(v(5.0, 0.2, 1.0))
        .unwrap()
        .then(&Transform::rotate(v(1.0, 1.0, 0.0), 33.0).unwrap())
        .then(&Transform::translate(v(1.0, 2.0, 3.0)).unwrap());
    let mut r = rng(9);
    for _ in 0..1000 {
        let n = unit(&mut r);
        let tangent = n.cross(unit(&mut r)).normalize();
        let (nt, tt) = (t.normal(n).normalize(), t.vector(tangent).normalize());
        assert!(nt.dot(tt).abs() < 1e-12, "{}", nt.dot(tt));
        // The naive transform is generally not perpendicular.
    }
    let naive = t.vector(v(1.0, 1.0, 0.0).normalize()).normalize();
    assert!(naive.dot(t.vector(v(1.0, -1.0, 0.0)).normalize()).abs() > 1e-3);
}

#[test]
fn transform_inverse_round_trips() {
    let t = Transform::from_rows([
        [2.0, 0.5, 0.0, 1.0],
        [0.0, 3.0, 1.0, -2.0],
        [1.0, 0.0, 0.5, 3.0],
        [0.0, 0.0, 0.0, 1.0],
    ])
    .unwrap();
    let mut r = rng(10);
    for _ in 0..1000 {
        let p = unit(&mut r) * r.random_range(0.0..100.0);
        assert!((t.inverse().point(t.point(p)) - p).length() < 1e-12 * (1.0 + p.length()));
        assert!((t.point(t.inverse().point(p)) - p).length() < 1e-12 * (1.0 + p.length()));
    }
    let id = t.then(&t.inverse()).matrix();
    assert!((id - DMat4::IDENTITY).abs().to_cols_array().iter().all(|x| *x < 1e-12));
}

#[test]
fn transform_rejects_singular_non_affine_and_non_finite_naming_the_field() {
    let e = Transform::from_rows([
        [1.0, 0.0, 0.0, 0.0],
        [2.0, 0.0, 0.0, 0.0],
        [0.0, 0.0, 1.0, 0.0],
        [0.0, 0.0, 0.0, 1.0],
    ])
    .unwrap_err();
    assert!(
        e.to_string().contains("Transform.matrix") && e.to_string().contains("singular"),
        "{e}"
    );
    let e = Transform::from_rows([
        [1.0, 0.0, 0.0, 0.0],
        [0.0, 1.0, 0.0, 0.0],
        [0.0, 0.0, 1.0, 0.0],
        [0.0, 0.5, 0.0, 1.0],
    ])
    .unwrap_err();
    assert!(e.to_string().contains("affine"), "{e}");
    let e = Transform::translate(v(f64::NAN, 0.0, 0.0)).unwrap_err();
    assert!(e.to_string().contains("Transform.translate"), "{e}");
    assert!(Transform::scale(v(1.0, 0.0, 1.0)).unwrap_err().to_string().contains("scale"));
    let e = serde_json::from_str::<Transform>(r#"{"rotate": {"axis": [0, 0, 0], "degrees": 3}}"#)
        .unwrap_err();
    assert!(e.to_string().contains("rotate.axis"), "{e}");
    let e = serde_json::from_str::<Transform>(
        r#"{"matrix": [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]], "scale": 2}"#,
    )
    .unwrap_err();
    assert!(e.to_string().contains("not both"), "{e}");
    // Analytic curved shapes accept only similarities.
    let e = shape_err(
        r#"{"type": "Sphere", "center": [0,0,0], "radius": 1, "transform": {"scale": [1, 2, 1]}}"#,
    );
    assert!(e.contains("Sphere.transform") && e.contains("similarity"), "{e}");
}

#[test]
fn transformed_shapes_land_where_the_transform_says() {
    let s = shape(
        r#"{"type": "Sphere", "center": [1, 0, 0], "radius": 1,
        "transform": {"scale": 2, "rotate": {"axis": [0, 0, 1], "degrees": 90}, "translate": [0, 0, 5]}}"#,
    );
    // Centre (1,0,0) -> (2,0,0) -> (0,2,0) -> (0,2,5); radius 2.
    let h = s.intersect(&Ray::new(v(0.0, 2.0, 20.0), v(0.0, 0.0, -1.0)), 1e9).unwrap();
    assert!((h.t - 13.0).abs() < 1e-12, "{}", h.t);
    // A mesh under a mirroring transform keeps outward normals.
    let m = World::new(vec![box_mesh(DVec3::ZERO, 1.0)]).unwrap();
    let mirrored = match &m.shapes()[0] {
        Shape::Mesh(mesh) => {
            mesh.transformed(&Transform::scale(v(-1.0, 1.0, 2.0)).unwrap()).unwrap()
        }
        _ => unreachable!(),
    };
    let w = World::new(vec![mirrored.into()]).unwrap();
    let h = w.intersect(&Ray::new(v(0.1, 0.2, 9.0), v(0.0, 0.0, -1.0)), 1e9).unwrap();
    assert!((h.t - 7.0).abs() < 1e-12 && h.geometric_normal.z > 0.99, "{h:?}");
}

// ---------------------------------------------------------------------------------------------
// Scene-file validation

#[test]
fn every_shape_parses_from_its_documented_json() {
    let shapes: Vec<Shape> = serde_json::from_str(
        r#"[
        {"type": "Sphere", "center": [0, 1, 0], "radius": 0.5},
        {"type": "Rectangle", "corner": [-1, 0, -1], "edge_u": [0, 0, 2], "edge_v": [2, 0, 0]},
        {"type": "Disk", "center": [0, 0, 0], "normal": [0, 1, 0], "radius": 2},
        {"type": "Cylinder", "center": [0, 0, 0], "axis": [0, 0.1, 0], "radius": 1},
        {"type": "Cylinder", "center": [0, 0, 0], "axis": [0, 1, 0], "height": 0.1, "radius": 1},
        {"type": "Torus", "center": [0, 1, 0], "axis": [0, 1, 0], "major_radius": 1, "minor_radius": 0.25},
        {"type": "Mesh", "positions": [[0, 0, 0], [1, 0, 0], [0, 1, 0]], "triangles": [[0, 1, 2]]},
        {"type": "Prism", "side": 0.3, "length": 0.5}
    ]"#,
    )
    .unwrap();
    let world = World::new(shapes.clone()).unwrap();
    assert_eq!(world.primitive_count(), 7 + 8);
    // The rectangle faces +y.
    let h = shapes[1].intersect(&Ray::new(v(0.5, 3.0, 0.5), v(0.0, -1.0, 0.0)), 1e9).unwrap();
    assert_eq!(h.geometric_normal, v(0.0, 1.0, 0.0));
    // Round trip.
    let json = serde_json::to_string(&shapes).unwrap();
    let again: Vec<Shape> = serde_json::from_str(&json).unwrap();
    assert_eq!(again, shapes);
}

#[test]
fn invalid_shapes_are_rejected_naming_the_field() {
    let cases = [
        (r#"{"type": "Sphere", "center": [0, 0, 0], "radius": 0}"#, "Sphere.radius"),
        (r#"{"type": "Sphere", "center": [0, 0, 0], "radius": -1}"#, "Sphere.radius"),
        (r#"{"type": "Sphere", "center": [0, 0, 0], "radius": 1, "colour": 3}"#, "colour"),
        (
            r#"{"type": "Rectangle", "corner": [0, 0, 0], "edge_u": [1, 0, 0], "edge_v": [2, 0, 0]}"#,
            "Rectangle.edge_v",
        ),
        (
            r#"{"type": "Disk", "center": [0, 0, 0], "normal": [0, 0, 0], "radius": 1}"#,
            "Disk.normal",
        ),
        (
            r#"{"type": "Cylinder", "center": [0, 0, 0], "axis": [0, 0, 0], "radius": 1}"#,
            "Cylinder.axis",
        ),
        (
            r#"{"type": "Torus", "center": [0, 0, 0], "axis": [0, 1, 0], "major_radius": 1, "minor_radius": 1}"#,
            "Torus.minor_radius",
        ),
        (
            r#"{"type": "Mesh", "positions": [[0, 0, 0], [1, 0, 0], [0, 1, 0]], "triangles": [[0, 1, 7]]}"#,
            "index 7",
        ),
        (r#"{"type": "Mesh", "positions": [[0, 0, 0]]}"#, "Mesh.triangles"),
        (
            r#"{"type": "Mesh", "positions": [[0, 0, 0], [1, 0, 0], [0, 1, 0]], "triangles": []}"#,
            "Mesh.triangles",
        ),
        (
            r#"{"type": "Prism", "apex_angle_degrees": 180, "side": 1, "length": 1}"#,
            "Prism.apex_angle_degrees",
        ),
        (r#"{"type": "Prism", "side": 1, "length": 0}"#, "Prism.length"),
        (r#"{"type": "Blob", "radius": 1}"#, "Blob"),
    ];
    for (json, field) in cases {
        let e = shape_err(json);
        assert!(e.contains(field), "{json}: {e}");
    }
}

// ---------------------------------------------------------------------------------------------
// OBJ

#[test]
fn obj_file_loads_relative_to_the_base_directory() {
    let dir = std::env::temp_dir().join(format!("spectrace-geometry-obj-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("models")).unwrap();
    let obj = "# unit cube, quads\n\
        v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n\
        f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 4 8 7 3\nf 1 5 8 4\nf 2 3 7 6\n";
    std::fs::write(dir.join("models/cube.obj"), obj).unwrap();
    let shapes: Vec<Shape> = serde_json::from_str(
        r#"[{"type": "Mesh", "obj": "models/cube.obj", "transform": {"translate": [0, 0, -5]}}]"#,
    )
    .unwrap();
    let e = World::new(shapes.clone()).unwrap_err();
    assert!(matches!(e, GeometryError::UnloadedMesh { index: 0, .. }), "{e}");
    let world = World::with_base_dir(shapes.clone(), &dir).unwrap();
    assert_eq!(world.primitive_count(), 12);
    let h = world.intersect(&Ray::new(v(0.2, 0.3, 0.0), v(0.0, 0.0, -1.0)), 1e9).unwrap();
    assert!((h.t - 4.0).abs() < 1e-12 && h.geometric_normal == v(0.0, 0.0, 1.0), "{h:?}");
    assert!(world.bounds().contains(v(1.0, 1.0, -6.0)));
    let missing = World::with_base_dir(shapes, &dir.join("nowhere")).unwrap_err();
    assert!(matches!(missing, GeometryError::Obj { .. }), "{missing}");
    std::fs::remove_dir_all(&dir).unwrap();
}

// ---------------------------------------------------------------------------------------------
// BVH

/// A random scene of every shape type; `far` moves it away from the origin.
fn random_scene(r: &mut Pcg64, far: DVec3) -> Vec<Shape> {
    let mut shapes: Vec<Shape> = Vec::new();
    let p = |r: &mut Pcg64| {
        far + v(r.random_range(-5.0..5.0), r.random_range(-5.0..5.0), r.random_range(-5.0..5.0))
    };
    for _ in 0..6 {
        shapes.push(Sphere::new(p(r), r.random_range(0.1..1.0)).unwrap().into());
        shapes.push(Rectangle::new(p(r), unit(r), unit(r)).unwrap().into());
        shapes.push(Disk::new(p(r), unit(r), r.random_range(0.1..1.0)).unwrap().into());
        shapes.push(Cylinder::new(p(r), unit(r), 1.0, 0.3).unwrap().into());
        shapes.push(Torus::new(p(r), unit(r), 0.8, 0.2).unwrap().into());
    }
    let positions: Vec<DVec3> = (0..200).map(|_| p(r)).collect();
    let triangles: Vec<[u32; 3]> = (0..150)
        .map(|_| [r.random_range(0..200u32), r.random_range(0..200u32), r.random_range(0..200u32)])
        .collect();
    shapes.push(Mesh::from_triangles(positions, triangles).unwrap().into());
    shapes.push(Prism::new(p(r), 45.0, 1.0, 2.0).unwrap().into());
    shapes
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    #[test]
    fn bvh_results_equal_brute_force(seed in any::<u64>(), far_exponent in 0.0f64..5.0) {
        let mut r = rng(seed);
        let far = unit(&mut r) * 10f64.powf(far_exponent);
        let world = World::new(random_scene(&mut r, far)).unwrap();
        for _ in 0..400 {
            let origin = far + unit(&mut r) * r.random_range(0.0..12.0);
            let ray = Ray::new(origin, unit(&mut r));
            let t_max = if r.random_bool(0.2) { r.random_range(0.0..10.0) } else { f64::INFINITY };
            let a = world.intersect(&ray, t_max);
            let b = world.intersect_brute_force(&ray, t_max);
            prop_assert_eq!(a.map(|h| h.t), b.map(|h| h.t), "{:?}", ray);
            // Ties (a ray through a vertex shared by two triangles) may pick either primitive.
            if let (Some(a), Some(b)) = (a, b)
                && (a.primitive, a.triangle) == (b.primitive, b.triangle)
            {
                prop_assert_eq!(a, b);
            }
            prop_assert_eq!(world.occluded(&ray, t_max), b.is_some());
        }
    }
}

#[test]
fn empty_world_hits_nothing() {
    let w = World::new(Vec::new()).unwrap();
    assert!(w.intersect(&Ray::new(DVec3::ZERO, v(1.0, 0.0, 0.0)), f64::INFINITY).is_none());
    assert!(!w.occluded(&Ray::new(DVec3::ZERO, v(1.0, 0.0, 0.0)), f64::INFINITY));
    assert!(w.bounds().is_empty());
}

#[test]
fn shadow_ray_to_a_point_on_another_surface_is_unoccluded() {
    let floor = Rectangle::new(v(-5.0, 0.0, -5.0), v(0.0, 0.0, 10.0), v(10.0, 0.0, 0.0)).unwrap();
    let ball = Sphere::new(v(0.0, 2.0, 0.0), 0.5).unwrap();
    let world = World::new(vec![floor.into(), ball.into()]).unwrap();
    let h = world.intersect(&Ray::new(v(3.0, 5.0, 1.0), v(0.0, -1.0, 0.0)), 1e9).unwrap();
    assert_eq!(h.primitive, 0);
    let (ray, dist) = h.spawn_ray_to(v(3.0, 4.0, 1.0));
    assert!(!world.occluded(&ray, dist));
    let (ray, dist) = h.spawn_ray_to(v(-3.0, 4.0, -1.0));
    assert!(world.occluded(&ray, dist), "the ball is in the way");
}

// ---------------------------------------------------------------------------------------------
// Hostile input: huge, tiny and special files

#[cfg(unix)]
#[test]
fn an_obj_that_is_a_device_is_refused_without_reading_it() {
    let mut shapes: Vec<Shape> =
        serde_json::from_str(r#"[{"type": "Mesh", "obj": "/dev/zero"}]"#).unwrap();
    let e = shapes[0].load(Path::new("/")).unwrap_err().to_string();
    assert!(e.contains("Mesh.obj") && e.contains("not a regular file"), "{e}");
    assert!(e.contains("device"), "{e}");
}

#[test]
fn an_obj_that_is_a_directory_is_refused() {
    let dir = std::env::temp_dir();
    let mut mesh = Mesh::from_obj(".", None);
    let e = mesh.load(&dir).unwrap_err().to_string();
    assert!(e.contains("Mesh.obj") && e.contains("not a regular file (a directory)"), "{e}");
}

#[test]
fn an_obj_naming_a_material_library_loads_without_opening_it() {
    let dir = std::env::temp_dir().join(format!("spectrace-geometry-mtl-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let obj = "mtllib /dev/zero\nmtllib missing.mtl\nusemtl red\n\
        v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    std::fs::write(dir.join("tri.obj"), obj).unwrap();
    let mut mesh = Mesh::from_obj("tri.obj", None);
    mesh.load(&dir).unwrap();
    let world = World::new(vec![mesh.into()]).unwrap();
    assert_eq!(world.primitive_count(), 1);
    std::fs::remove_dir_all(&dir).unwrap();
}

fn transform_err(json: &str) -> String {
    serde_json::from_str::<Transform>(json).unwrap_err().to_string()
}

#[test]
fn a_huge_matrix_is_invertible_and_a_singular_one_is_called_singular() {
    // 1e300 times a rotation: the determinant overflows but the transform is fine.
    let t: Transform = serde_json::from_str(
        r#"{"matrix": [[0, -1e300, 0, 0], [1e300, 0, 0, 0], [0, 0, 1e300, 5], [0, 0, 0, 1]]}"#,
    )
    .unwrap();
    let p = t.inverse().point(t.point(v(1.0, 2.0, 3.0)));
    assert!((p - v(1.0, 2.0, 3.0)).abs().max_element() < 1e-12, "{p}");
    assert!(!t.flips_orientation());
    assert!((t.similarity_scale().unwrap() / 1e300 - 1.0).abs() < 1e-12);
    // Tiny entries are judged relative to their scale too.
    let t: Transform = serde_json::from_str(
        r#"{"matrix": [[1e-300, 0, 0, 0], [0, 1e-300, 0, 0], [0, 0, -1e-300, 0], [0, 0, 0, 1]]}"#,
    )
    .unwrap();
    assert!(t.flips_orientation());
    // Truly singular, at any scale.
    for s in ["1", "1e300", "1e-300"] {
        let e = transform_err(&format!(
            r#"{{"matrix": [[{s}, {s}, 0, 0], [{s}, {s}, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]}}"#
        ));
        assert!(e.contains("Transform.matrix") && e.contains("singular"), "{s}: {e}");
    }
    // An inverse that does not fit in f64: too large, not singular.
    let e = transform_err(
        r#"{"matrix": [[1e-300, 0, 0, 1e300], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]}"#,
    );
    assert!(e.contains("Transform.matrix") && e.contains("inverse overflows"), "{e}");
    assert!(!e.contains("singular"), "{e}");
    let e = transform_err(r#"{"scale": 1e-320}"#);
    assert!(e.contains("Transform.scale") && e.contains("too small"), "{e}");
}

#[test]
fn huge_perpendicular_edges_are_too_large_not_degenerate() {
    let e = shape_err(
        r#"{"type": "Rectangle", "corner": [0, 0, 0], "edge_u": [1e200, 0, 0], "edge_v": [0, 1e200, 0]}"#,
    );
    assert!(e.contains("Rectangle.edge_") && e.contains("too large"), "{e}");
    assert!(!e.contains("degenerate"), "{e}");
    // Large but representable: accepted, and hit where expected.
    let s = shape(
        r#"{"type": "Rectangle", "corner": [0, 0, 0], "edge_u": [1e150, 0, 0], "edge_v": [0, 0, 1e150]}"#,
    );
    assert!(s.intersect(&Ray::new(v(5.0, 1.0, 5.0), v(0.0, -1.0, 0.0)), 1e9).is_some());
    let e = shape_err(
        r#"{"type": "Rectangle", "corner": [0, 0, 0], "edge_u": [1e200, 0, 0], "edge_v": [2e200, 0, 0]}"#,
    );
    assert!(e.contains("Rectangle.edge_v") && e.contains("parallel"), "{e}");
    let e = shape_err(
        r#"{"type": "Rectangle", "corner": [0, 0, 0], "edge_u": [0, 0, 0], "edge_v": [1, 0, 0]}"#,
    );
    assert!(e.contains("Rectangle.edge_u") && e.contains("non-zero"), "{e}");
}

#[test]
fn large_or_tiny_directions_are_accepted_and_zero_is_called_zero() {
    for n in ["[0, 1e300, 1e300]", "[1e-320, 0, 0]", "[-0.0, 1e200, 0]"] {
        let disk = shape(&format!(
            r#"{{"type": "Disk", "center": [0, 0, 0], "normal": {n}, "radius": 1}}"#
        ));
        assert_eq!(disk.primitive_count(), 1);
        let cyl = shape(&format!(
            r#"{{"type": "Cylinder", "center": [0, 0, 0], "axis": {n}, "height": 1, "radius": 1}}"#
        ));
        assert_eq!(cyl.primitive_count(), 1);
    }
    let e =
        shape_err(r#"{"type": "Disk", "center": [0, 0, 0], "normal": [0, -0.0, 0], "radius": 1}"#);
    assert!(e.contains("Disk.normal") && e.contains("non-zero"), "{e}");
    let e = shape_err(
        r#"{"type": "Cylinder", "center": [0, 0, 0], "axis": [1.5e308, 1.5e308, 0], "radius": 1}"#,
    );
    assert!(e.contains("Cylinder.axis") && e.contains("too large"), "{e}");
}

/// The fields each shape type has, as scene files write them.
fn shape_fields(json: &str) -> &'static [&'static str] {
    let ty = serde_json::from_str::<serde_json::Value>(json).unwrap()["type"].clone();
    match ty.as_str().unwrap() {
        "Sphere" => &["center", "radius", "transform"],
        "Rectangle" => &["corner", "edge_u", "edge_v", "transform"],
        "Disk" => &["center", "normal", "radius", "transform"],
        "Cylinder" => &["center", "axis", "height", "radius", "transform"],
        "Torus" => &["center", "axis", "major_radius", "minor_radius", "transform"],
        "Prism" => &["center", "apex_angle_degrees", "side", "length", "transform"],
        _ => &["obj", "positions", "triangles", "normals", "uvs", "transform"],
    }
}

fn extreme() -> impl Strategy<Value = f64> {
    prop::sample::select(vec![
        1e-320,
        -1e-320,
        1e200,
        -1e200,
        1e300,
        -1e300,
        -0.0,
        0.0,
        1.0,
        -1.0,
        0.5,
        f64::MAX,
    ])
}

fn extreme_vec() -> impl Strategy<Value = [f64; 3]> {
    [extreme(), extreme(), extreme()]
}

fn js(x: f64) -> String {
    serde_json::to_string(&x).unwrap()
}

fn jv(a: [f64; 3]) -> String {
    format!("[{}, {}, {}]", js(a[0]), js(a[1]), js(a[2]))
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    /// Extreme finite values never panic, and an error names a field the shape has.
    #[test]
    fn extreme_finite_values_are_accepted_or_refused_naming_a_field(
        kind in 0usize..7,
        a in extreme_vec(),
        b in extreme_vec(),
        c in extreme_vec(),
        x in extreme(),
        y in extreme(),
        s in extreme(),
    ) {
        let json = match kind {
            0 => format!(r#"{{"type": "Sphere", "center": {}, "radius": {}}}"#, jv(a), js(x)),
            1 => format!(r#"{{"type": "Rectangle", "corner": {}, "edge_u": {}, "edge_v": {}}}"#, jv(a), jv(b), jv(c)),
            2 => format!(r#"{{"type": "Disk", "center": {}, "normal": {}, "radius": {}, "transform": {{"scale": {}}}}}"#, jv(a), jv(b), js(x), js(s)),
            3 => format!(r#"{{"type": "Cylinder", "center": {}, "axis": {}, "radius": {}}}"#, jv(a), jv(b), js(x)),
            4 => format!(r#"{{"type": "Torus", "center": {}, "axis": {}, "major_radius": {}, "minor_radius": {}}}"#, jv(a), jv(b), js(x), js(y)),
            5 => format!(r#"{{"type": "Prism", "center": {}, "side": {}, "length": {}, "transform": {{"translate": {}}}}}"#, jv(a), js(x), js(y), jv(c)),
            _ => format!(r#"{{"type": "Mesh", "positions": [{}, {}, {}], "triangles": [[0, 1, 2]], "transform": {{"matrix": [[{}, 0, 0, 0], [0, {}, 0, 0], [0, 0, {}, 0], [0, 0, 0, 1]]}}}}"#, jv(a), jv(b), jv(c), js(x), js(y), js(s)),
        };
        if let Err(e) = serde_json::from_str::<Shape>(&json) {
            let e = e.to_string();
            let fields = shape_fields(&json);
            let named = fields.iter().any(|f| e.contains(&format!(".{f}")))
                || (json.contains("transform") && e.contains("Transform."));
            prop_assert!(named, "{json}: {e}");
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Area sampling (emitting shapes): points on the surface, areas, uniformity

/// The transforms of the area tests: a similarity (for the analytic shapes), and an affine one
/// with shear and non-uniform scale (rectangles and meshes).
const SIMILARITY: &str =
    r#"{"scale": 1.5, "rotate": {"axis": [1, 2, -0.5], "degrees": 37}, "translate": [3, -1, 20]}"#;
const AFFINE: &str =
    r#"{"matrix": [[2, 0.5, 0, 1], [0, 3, 0.25, -2], [0.3, 0, 1.5, 4], [0, 0, 0, 1]]}"#;
const MIRROR: &str = r#"{"scale": [-1, 2, 1.5], "translate": [0, 0, -3]}"#;

fn transform(json: &str) -> Transform {
    serde_json::from_str(json).unwrap()
}

/// Three separate triangles in the untransformed `x` ranges [0, 1], [2, 4], [5, 5.5] (areas
/// 0.5, 1.5, 0.125 before the transform), a zero-area one (collinear), never to be sampled.
const SEPARATE_TRIANGLES: &str = r#""positions": [[0, 0, 0], [1, 0, 0], [0, 1, 0.2],
    [2, 0, 1], [4, 0, 1], [2, 1.5, 0], [5, 0, 0], [5.5, 0, 0], [5, 0.5, 0.5],
    [7, 0, 0], [8, 1, 1], [9, 2, 2]],
    "triangles": [[0, 1, 2], [3, 4, 5], [6, 7, 8], [9, 10, 11]]"#;

/// One shape of each kind, transformed, with its size (the scale of its tolerances).
fn area_shapes() -> Vec<(Shape, f64)> {
    vec![
        (
            shape(&format!(
                r#"{{"type": "Sphere", "center": [1, 2, 3], "radius": 0.5, "transform": {SIMILARITY}}}"#
            )),
            0.75,
        ),
        (
            shape(&format!(
                r#"{{"type": "Rectangle", "corner": [-1, 0, -1], "edge_u": [2, 0, 0], "edge_v": [0, 0, 3], "transform": {AFFINE}}}"#
            )),
            6.0,
        ),
        (
            shape(&format!(
                r#"{{"type": "Disk", "center": [0, 1, 0], "normal": [0, 0, 1], "radius": 2, "transform": {SIMILARITY}}}"#
            )),
            3.0,
        ),
        (
            shape(&format!(
                r#"{{"type": "Cylinder", "center": [0, 0, 1], "axis": [0, 0, 0.5], "radius": 1, "transform": {SIMILARITY}}}"#
            )),
            1.5,
        ),
        (
            shape(&format!(
                r#"{{"type": "Torus", "center": [1, 0, 0], "axis": [0, 0, 1], "major_radius": 1, "minor_radius": 0.3, "transform": {SIMILARITY}}}"#
            )),
            1.95,
        ),
        (
            shape(&format!(r#"{{"type": "Mesh", {SEPARATE_TRIANGLES}, "transform": {AFFINE}}}"#)),
            10.0,
        ),
        (
            shape(&format!(r#"{{"type": "Mesh", {SEPARATE_TRIANGLES}, "transform": {MIRROR}}}"#)),
            10.0,
        ),
        (
            shape(&format!(
                r#"{{"type": "Prism", "center": [0, 0.5, 0], "apex_angle_degrees": 50, "side": 0.3, "length": 0.5, "transform": {SIMILARITY}}}"#
            )),
            0.5,
        ),
    ]
}

/// Checks that `p` lies on `shape` with normal `p.normal`: a ray from `point + 1e-3 size normal`
/// along `-normal` (limited to twice that distance) hits the shape at the point (within 1e-6 of
/// the size) with the same geometric normal (within 1e-9). Returns the hit.
fn assert_on_surface(shape: &Shape, p: SurfacePoint, size: f64) -> Hit {
    assert!(p.point.is_finite(), "{} sampled {p:?}", shape.type_name());
    assert!(
        (p.normal.length() - 1.0).abs() < 1e-12,
        "{} normal not unit: {p:?}",
        shape.type_name()
    );
    let offset = 1e-3 * size;
    let ray = Ray::new(p.point + p.normal * offset, -p.normal);
    let Some(hit) = shape.intersect(&ray, 2.0 * offset) else {
        panic!("{}: the ray towards the sampled point {p:?} misses", shape.type_name());
    };
    let tol = 1e-6 * size;
    assert!((hit.point - p.point).length() < tol, "{}: hit {hit:?} vs {p:?}", shape.type_name());
    assert!((hit.t - offset).abs() < tol, "{}: t {} vs {offset}", shape.type_name(), hit.t);
    assert!(
        (hit.geometric_normal - p.normal).length() < 1e-9,
        "{}: hit normal {} vs sampled {}",
        shape.type_name(),
        hit.geometric_normal,
        p.normal
    );
    hit
}

fn uniforms(r: &mut Pcg64) -> [f64; 3] {
    [r.random::<f64>(), r.random::<f64>(), r.random::<f64>()]
}

#[test]
fn every_shape_samples_points_on_its_surface_with_the_hit_normal() {
    let mut r = rng(71);
    for (s, size) in area_shapes() {
        for _ in 0..5000 {
            assert_on_surface(&s, s.sample_area(uniforms(&mut r)), size);
        }
        // Inputs outside [0, 1) are clamped into it (NaN to 0), never a panic. The clamped
        // values map to the shape's boundary, where a ray may graze past the edge, so these are
        // checked against the in-range samples rather than by a ray.
        let top = 1.0 - f64::EPSILON / 2.0;
        for (bad, good) in [
            (1.0, top),
            (7.0, top),
            (f64::INFINITY, top),
            (f64::NAN, 0.0),
            (-3.0, 0.0),
            (f64::NEG_INFINITY, 0.0),
        ] {
            for w in [0.0, 0.3, top] {
                for (b, g) in [([bad, w, w], [good, w, w]), ([w, bad, w], [w, good, w])] {
                    let p = s.sample_area(b);
                    assert_eq!(p, s.sample_area(g), "{}: {b:?}", s.type_name());
                    assert!(p.point.is_finite() && (p.normal.length() - 1.0).abs() < 1e-12);
                }
                assert_eq!(s.sample_area([w, w, bad]), s.sample_area([w, w, good]));
            }
        }
        // Just inside the edges of the unit square the points are on the surface.
        for a in [1e-9, 0.5, 1.0 - 1e-9] {
            for b in [1e-9, 0.25, 1.0 - 1e-9] {
                assert_on_surface(&s, s.sample_area([a, b, 0.5]), size);
                assert_on_surface(&s, s.sample_area([0.5, a, b]), size);
            }
        }
    }
}

/// Area of the triangle `p0 p1 p2`.
fn tri_area(p: [DVec3; 3]) -> f64 {
    0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length()
}

#[test]
fn areas_match_closed_forms_after_transforms() {
    let close = |s: &Shape, want: f64| {
        let got = s.area();
        assert!((got - want).abs() <= 1e-12 * want, "{}: area {got} vs {want}", s.type_name());
    };
    let shapes = area_shapes();
    close(&shapes[0].0, 4.0 * PI * 0.75 * 0.75);
    let t = transform(AFFINE);
    close(&shapes[1].0, t.vector(v(2.0, 0.0, 0.0)).cross(t.vector(v(0.0, 0.0, 3.0))).length());
    close(&shapes[2].0, PI * 3.0 * 3.0);
    close(&shapes[3].0, 2.0 * PI * 1.5 * 0.75);
    close(&shapes[4].0, 4.0 * PI * PI * 1.5 * 0.45);
    let mesh_area = |t: &Transform| {
        let p: Vec<DVec3> = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.2],
            [2.0, 0.0, 1.0],
            [4.0, 0.0, 1.0],
            [2.0, 1.5, 0.0],
            [5.0, 0.0, 0.0],
            [5.5, 0.0, 0.0],
            [5.0, 0.5, 0.5],
        ]
        .iter()
        .map(|&a| t.point(DVec3::from_array(a)))
        .collect();
        (0..3).map(|i| tri_area([p[3 * i], p[3 * i + 1], p[3 * i + 2]])).sum::<f64>()
    };
    close(&shapes[5].0, mesh_area(&transform(AFFINE)));
    close(&shapes[6].0, mesh_area(&transform(MIRROR)));
    // Prism: two triangular ends (base 2 s sin(a/2), height s cos(a/2)) and three rectangular
    // sides (s, s and the base, times the length); the similarity scales it all by 1.5^2.
    let (s, half, len) = (0.3, 25f64.to_radians(), 0.5);
    let base = 2.0 * s * half.sin();
    let prism = base * s * half.cos() + len * (2.0 * s + base);
    close(&shapes[7].0, prism * 1.5 * 1.5);
    // Untransformed closed forms, for the record.
    close(&Sphere::new(DVec3::ZERO, 2.0).unwrap().into(), 16.0 * PI);
    close(&Torus::new(DVec3::ZERO, DVec3::Y, 2.0, 0.5).unwrap().into(), 4.0 * PI * PI);
    close(&Cylinder::new(DVec3::ZERO, DVec3::X, 3.0, 0.5).unwrap().into(), 3.0 * PI);
    close(&Disk::new(DVec3::ZERO, DVec3::X, 0.5).unwrap().into(), 0.25 * PI);
    close(&Rectangle::new(DVec3::ZERO, v(1.0, 1.0, 0.0), v(0.0, 2.0, 0.0)).unwrap().into(), 2.0);
}

/// Chi-square p-value of `counts` against `expected` (pooling bins under 5); the tests below
/// fail a correct sampler with probability 1e-4 each (alpha).
fn chi_square_p(counts: &[u64], expected: &[f64]) -> f64 {
    spectrace_sampling::stats::chi_square(counts, expected, 5.0).p_value
}

/// `n` samples of `s`, each mapped back to the untransformed (local) frame of `json`.
fn local_samples(s: &Shape, json: &str, n: usize, seed: u64) -> Vec<DVec3> {
    let inv = transform(json).inverse();
    let mut r = rng(seed);
    (0..n).map(|_| inv.point(s.sample_area(uniforms(&mut r)).point)).collect()
}

/// The bin of `x` in `[0, 1)` among `k` equal bins.
fn bin(x: f64, k: usize) -> usize {
    ((x * k as f64).max(0.0) as usize).min(k - 1)
}

/// Azimuth of `(x, y)` over `2 pi`, in `[0, 1)`.
fn turn(x: f64, y: f64) -> f64 {
    let a = y.atan2(x) / (2.0 * PI);
    if a < 0.0 { a + 1.0 } else { a }
}

const N_UNIFORM: usize = 200_000;
const ALPHA: f64 = 1e-4;

#[test]
fn analytic_shapes_sample_uniformly_by_area() {
    let shapes = area_shapes();
    let k = 10;
    let expected = vec![N_UNIFORM as f64 / (k * k) as f64; k * k];
    // Each maps a local point to two coordinates that are uniform in [0, 1)^2 exactly when the
    // sampling is uniform by area (Archimedes for the sphere, rho^2 for the disk).
    type Coordinates = fn(DVec3) -> (f64, f64);
    let cases: [(usize, &str, Coordinates); 4] = [
        (0, SIMILARITY, |q| {
            let q = (q - v(1.0, 2.0, 3.0)) / 0.5;
            ((q.z + 1.0) / 2.0, turn(q.x, q.y))
        }),
        (1, AFFINE, |q| ((q.x + 1.0) / 2.0, (q.z + 1.0) / 3.0)),
        (2, SIMILARITY, |q| {
            let q = q - v(0.0, 1.0, 0.0);
            ((q.x * q.x + q.y * q.y) / 4.0, turn(q.x, q.y))
        }),
        (3, SIMILARITY, |q| ((q.z - 1.0) / 0.5, turn(q.x, q.y))),
    ];
    for (i, json, coords) in cases {
        let mut counts = vec![0u64; k * k];
        for q in local_samples(&shapes[i].0, json, N_UNIFORM, 100 + i as u64) {
            let (a, b) = coords(q);
            assert!((-1e-9..1.0 + 1e-9).contains(&a) && (-1e-9..1.0 + 1e-9).contains(&b), "{q}");
            counts[bin(a, k) * k + bin(b, k)] += 1;
        }
        let p = chi_square_p(&counts, &expected);
        assert!(p > ALPHA, "{}: chi-square p = {p:e}", shapes[i].0.type_name());
    }
}

#[test]
fn torus_samples_weight_the_tube_angle_by_its_distance_from_the_axis() {
    let s = &area_shapes()[4].0;
    let (big_r, r) = (1.0, 0.3);
    let (k_theta, k_phi) = (8, 24);
    let mut counts = vec![0u64; k_theta * k_phi];
    for q in local_samples(s, SIMILARITY, N_UNIFORM, 104) {
        let q = q - v(1.0, 0.0, 0.0);
        let rho = q.x.hypot(q.y);
        assert!(((rho - big_r).hypot(q.z) - r).abs() < 1e-12, "{q}");
        counts[bin(turn(q.x, q.y), k_theta) * k_phi + bin(turn(rho - big_r, q.z), k_phi)] += 1;
    }
    // Area of a band of the tube angle [a, b): proportional to R (b - a) + r (sin b - sin a).
    let band = |j: usize| {
        let (a, b) = (2.0 * PI * j as f64 / k_phi as f64, 2.0 * PI * (j + 1) as f64 / k_phi as f64);
        (big_r * (b - a) + r * (b.sin() - a.sin())) / (2.0 * PI * big_r)
    };
    let n = N_UNIFORM as f64 / k_theta as f64;
    let expected: Vec<f64> = (0..k_theta * k_phi).map(|i| n * band(i % k_phi)).collect();
    let p = chi_square_p(&counts, &expected);
    assert!(p > ALPHA, "torus: chi-square p = {p:e}");
    // The test has the power to see the mistake the weighting avoids: the same samples are far
    // from uniform in the two angles.
    let flat = vec![N_UNIFORM as f64 / (k_theta * k_phi) as f64; k_theta * k_phi];
    assert!(chi_square_p(&counts, &flat) < 1e-12);
}

/// Per-triangle, per-cell counts of `n` samples of a mesh shape: each sample's triangle and
/// barycentric coordinates come from the ray that finds it on the surface; each triangle is cut
/// into `k^2` congruent cells of equal area (by `floor(k b1)`, `floor(k b2)` and which half of
/// the little parallelogram). Returns the counts and the expected counts from the triangle areas.
fn mesh_cell_counts(
    s: &Shape,
    mesh: &Mesh,
    size: f64,
    n: usize,
    seed: u64,
) -> (Vec<u64>, Vec<f64>) {
    let k = 4;
    let cells = k * k;
    let tris = mesh.triangles().len();
    let mut counts = vec![0u64; tris * cells];
    let mut r = rng(seed);
    for _ in 0..n {
        let hit = assert_on_surface(s, s.sample_area(uniforms(&mut r)), size);
        let (b1, b2) = (hit.uv.x * k as f64, hit.uv.y * k as f64);
        let (i, j) = ((b1 as usize).min(k - 1), (b2 as usize).min(k - 1));
        let upper = usize::from(b1.fract() + b2.fract() >= 1.0);
        // Cells of row j: 2 (k - j) - 1, lower and upper alternating; index them all in k^2.
        let row_start: usize = (0..j).map(|jj| 2 * (k - jj) - 1).sum();
        let cell = (row_start + 2 * i + upper).min(cells - 1);
        counts[hit.triangle as usize * cells + cell] += 1;
    }
    let areas: Vec<f64> = mesh
        .triangles()
        .iter()
        .map(|t| tri_area(t.map(|i| mesh.positions()[i as usize])))
        .collect();
    let total: f64 = areas.iter().sum();
    let expected = (0..tris * cells).map(|c| n as f64 * areas[c / cells] / total / cells as f64);
    (counts, expected.collect())
}

#[test]
fn meshes_and_prisms_sample_triangles_by_area_and_uniformly_within() {
    for (s, size) in area_shapes().into_iter().skip(5) {
        let mesh = match &s {
            Shape::Mesh(m) => m.clone(),
            Shape::Prism(p) => p.mesh().clone(),
            _ => unreachable!(),
        };
        let (counts, expected) = mesh_cell_counts(&s, &mesh, size, N_UNIFORM, 105);
        let p = chi_square_p(&counts, &expected);
        assert!(p > ALPHA, "{}: chi-square p = {p:e}", s.type_name());
        if let Shape::Mesh(_) = s {
            // The collinear triangle has no area and is never chosen.
            assert_eq!(counts[3 * 16..].iter().sum::<u64>(), 0);
        }
    }
}

#[test]
fn degenerate_and_unloaded_meshes_sample_without_panicking() {
    let flat = shape(
        r#"{"type": "Mesh", "positions": [[0, 0, 0], [1, 1, 1], [2, 2, 2]], "triangles": [[0, 1, 2], [2, 1, 0]]}"#,
    );
    assert_eq!(flat.area(), 0.0);
    let huge = shape(
        r#"{"type": "Mesh", "positions": [[-1e308, 0, 0], [1e308, 0, 0], [0, 1e308, 0]], "triangles": [[0, 1, 2]]}"#,
    );
    assert_eq!(huge.area(), f64::INFINITY);
    let unloaded = Shape::from(Mesh::from_obj("nowhere.obj", None));
    assert_eq!(unloaded.area(), 0.0);
    let mut r = rng(106);
    for s in [flat, huge, unloaded] {
        for _ in 0..100 {
            let p = s.sample_area(uniforms(&mut r));
            assert!(p.point.is_finite() && (p.normal.length() - 1.0).abs() < 1e-12, "{p:?}");
        }
    }
}

// ---------------------------------------------------------------------------------------------
// The f32 BVH traversal against brute force: meshes and analytic shapes, rays from surfaces,
// far from the origin (where an f32 ulp exceeds the triangles), tiny and huge scales.

/// `{"scale": s, "translate": far}` as JSON.
fn scale_then_move(s: f64, far: DVec3) -> String {
    format!(r#"{{"scale": {}, "translate": {}}}"#, js(s), jv(far.to_array()))
}

/// The benchmark's bumpy UV sphere of radius ~1 (`4 n^2` triangles,
/// `bench_scenes::bumpy_sphere_triangles`) as a Mesh, scaled by `s` and moved to `far`.
fn bumpy_mesh(n: u32, s: f64, far: DVec3) -> Shape {
    let (positions, triangles) = spectrace_geometry::bench_scenes::bumpy_sphere_triangles(n);
    let positions: Vec<String> = positions.into_iter().map(|p| jv(p.to_array())).collect();
    let triangles: Vec<String> = triangles.iter().map(|t| format!("{t:?}")).collect();
    shape(&format!(
        r#"{{"type": "Mesh", "positions": [{}], "triangles": [{}], "transform": {}}}"#,
        positions.join(","),
        triangles.join(","),
        scale_then_move(s, far)
    ))
}

/// Every analytic shape type plus a mesh and a prism, all within `s * 5` of `far`.
fn scaled_scene(r: &mut Pcg64, s: f64, far: DVec3) -> Vec<Shape> {
    let t = scale_then_move(s, far);
    let mut p = || jv([0; 3].map(|_| r.random_range(-4.0..4.0)));
    let mut shapes: Vec<Shape> = Vec::new();
    for k in 0..4 {
        let json = [
            format!(r#"{{"type": "Sphere", "center": {}, "radius": 0.6, "transform": {t}}}"#, p()),
            format!(
                r#"{{"type": "Rectangle", "corner": {}, "edge_u": [1, 0.2, 0], "edge_v": [0, 0.3, 1.5], "transform": {t}}}"#,
                p()
            ),
            format!(
                r#"{{"type": "Disk", "center": {}, "normal": [0.3, 1, 0.2], "radius": 0.7, "transform": {t}}}"#,
                p()
            ),
            format!(
                r#"{{"type": "Cylinder", "center": {}, "axis": [0.2, 1, 0.1], "radius": 0.4, "transform": {t}}}"#,
                p()
            ),
            format!(
                r#"{{"type": "Torus", "center": {}, "axis": [0, 1, 0.4], "major_radius": 0.8, "minor_radius": 0.2, "transform": {t}}}"#,
                p()
            ),
            format!(
                r#"{{"type": "Prism", "center": {}, "side": 1, "length": 1.5, "transform": {t}}}"#,
                p()
            ),
        ];
        shapes.extend(json.iter().map(|j| shape(j)));
        if k == 0 {
            shapes.push(bumpy_mesh(24, s, far));
        }
    }
    shapes
}

/// Asserts `intersect` == `intersect_brute_force` (same `t` to the bit, same hit unless two
/// primitives tie at that `t`) and `occluded` == `is_some`, for one ray.
fn check_ray(world: &World, ray: &Ray, t_max: f64) -> Option<Hit> {
    let a = world.intersect(ray, t_max);
    let b = world.intersect_brute_force(ray, t_max);
    assert_eq!(a.map(|h| h.t), b.map(|h| h.t), "{ray:?} t_max {t_max}");
    if let (Some(a), Some(b)) = (a, b)
        && (a.primitive, a.triangle) == (b.primitive, b.triangle)
    {
        assert_eq!(a, b, "{ray:?}");
    }
    assert_eq!(world.occluded(ray, t_max), b.is_some(), "{ray:?} t_max {t_max}");
    b
}

#[test]
fn f32_bvh_equals_brute_force_from_surfaces_far_away_and_at_tiny_and_huge_scales() {
    let mut r = rng(10);
    // (scale, distance from the origin): 1e6 and 1e7 put f32 ulps (0.06, 1) above the mesh's
    // triangle size (0.13 s); 3e30 (beyond 1e30) takes the f64 fallback.
    let cases = [
        (1.0, 0.0),
        (1.0, 1e6),
        (1.0, 1e7),
        (1e-6, 0.0),
        (1e-6, 1.0),
        (1e-6, 1e3),
        (1e6, 0.0),
        (1e6, 1e9),
        (1e26, 3e30),
    ];
    let mut hits = 0;
    for (s, distance) in cases {
        let far = unit(&mut r) * distance;
        let world = World::new(scaled_scene(&mut r, s, far)).unwrap();
        for _ in 0..600 {
            let origin = far + unit(&mut r) * (s * r.random_range(0.0..9.0));
            let ray = Ray::new(origin, unit(&mut r));
            let t_max =
                if r.random_bool(0.2) { s * r.random_range(0.0..6.0) } else { f64::INFINITY };
            let Some(h) = check_ray(&world, &ray, t_max) else { continue };
            hits += 1;
            // Rays starting on the surface just hit: bounced, transmitted, and towards a point.
            let n = h.geometric_normal;
            for d in [hemisphere(&mut r, n), hemisphere(&mut r, -n), reflect(ray.direction, n)] {
                check_ray(&world, &h.spawn_ray(d), f64::INFINITY);
            }
            let (shadow, dist) = h.spawn_ray_to(far + unit(&mut r) * (s * 3.0));
            check_ray(&world, &shadow, dist);
        }
    }
    assert!(hits > 800, "too few hits to test anything: {hits}");
}

#[test]
fn rays_skimming_a_dense_mesh_far_from_the_origin_match_brute_force() {
    // Triangles of ~0.03 at 1e6 (f32 ulp 0.0625): rays aimed at vertices and edge midpoints.
    let far = v(1e6, -1e6, 5e5);
    let mesh = bumpy_mesh(100, 1.0, far);
    let world = World::new(vec![mesh.clone()]).unwrap();
    let Shape::Mesh(m) = &mesh else { unreachable!() };
    let mut r = rng(11);
    let mut hits = 0;
    for k in 0..3000 {
        let tri = m.triangles()[r.random_range(0..m.triangles().len())];
        let p = tri.map(|i| m.positions()[i as usize]);
        let target = match k % 3 {
            0 => p[0],
            1 => (p[0] + p[1]) * 0.5,
            _ => (p[0] + p[1] + p[2]) / 3.0,
        };
        let origin = if k % 2 == 0 { far + unit(&mut r) * 3.0 } else { far + unit(&mut r) * 0.3 };
        hits += usize::from(
            check_ray(&world, &Ray::new(origin, target - origin), f64::INFINITY).is_some(),
        );
    }
    assert!(hits > 2500, "{hits}");
}

#[test]
fn occluded_equals_intersect_is_some_with_finite_distances() {
    let mut r = rng(12);
    let world = World::new(random_scene(&mut r, DVec3::ZERO)).unwrap();
    let (mut blocked, mut free) = (0, 0);
    for _ in 0..5000 {
        let ray = Ray::new(unit(&mut r) * r.random_range(0.0..8.0), unit(&mut r));
        let t_max = r.random_range(0.0..6.0);
        let o = world.occluded(&ray, t_max);
        assert_eq!(o, world.intersect(&ray, t_max).is_some(), "{ray:?} {t_max}");
        if o { blocked += 1 } else { free += 1 }
    }
    assert!(blocked > 500 && free > 500, "{blocked} {free}");
}

#[test]
fn worlds_of_one_or_two_primitives_tested_directly_equal_brute_force() {
    // Up to two primitives (no torus), the world tests every primitive instead of traversing;
    // with a torus it traverses. Both must be the brute-force search, for rays from anywhere.
    let mut r = rng(31);
    let two_triangles = Mesh::from_triangles(
        vec![v(-1.0, 0.0, -1.0), v(1.0, 0.0, -1.0), v(1.0, 0.0, 1.0), v(-1.0, 0.2, 1.0)],
        vec![[0, 1, 2], [0, 2, 3]],
    )
    .unwrap();
    let worlds: Vec<Vec<Shape>> = vec![
        vec![
            Rectangle::new(v(-1.0, 0.0, -1.0), v(2.0, 0.0, 0.0), v(0.0, 0.0, 2.0)).unwrap().into(),
        ],
        vec![
            Sphere::new(v(0.0, 0.5, 0.0), 0.5).unwrap().into(),
            Disk::new(v(0.0, -0.5, 0.0), DVec3::Y, 1.0).unwrap().into(),
        ],
        vec![two_triangles.into()],
        vec![
            Rectangle::new(v(-1.0, 0.0, -1.0), v(2.0, 0.0, 0.0), v(0.0, 0.0, 2.0)).unwrap().into(),
            Torus::new(v(0.0, 0.5, 0.0), DVec3::Y, 0.6, 0.2).unwrap().into(),
        ],
    ];
    let mut hits = 0;
    for shapes in worlds {
        let world = World::new(shapes).unwrap();
        for _ in 0..2000 {
            let origin = unit(&mut r) * r.random_range(0.0..3.0);
            let ray = Ray::new(origin, unit(&mut r));
            let t_max = if r.random_bool(0.2) { r.random_range(0.0..3.0) } else { f64::INFINITY };
            hits += usize::from(check_ray(&world, &ray, t_max).is_some());
        }
    }
    assert!(hits > 1000, "too few hits to test anything: {hits}");
}
