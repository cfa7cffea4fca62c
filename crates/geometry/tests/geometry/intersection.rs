//! Intersection accuracy: spheres far from the origin and tangent rays, grazing rays and
//! watertight edges, self-intersection after spawning (the closed mirror boxes), the torus, the
//! cylinder, disk and prism.

use super::*;

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
pub(super) fn check_no_acne(shape: Shape, center: DVec3, convex: bool, seed: u64) {
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
pub(super) fn box_rectangles(c: DVec3, h: f64) -> Vec<Shape> {
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
pub(super) fn box_mesh(c: DVec3, h: f64) -> Shape {
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
