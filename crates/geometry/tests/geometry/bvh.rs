//! The BVH against brute force: random scenes of every shape, the f32 traversal far from the
//! origin (where an f32 ulp exceeds the triangles), at tiny and huge scales, rays from surfaces,
//! and worlds small enough to be tested without traversal.

use super::*;

/// A random scene of every shape type; `far` moves it away from the origin.
pub(super) fn random_scene(r: &mut Pcg64, far: DVec3) -> Vec<Shape> {
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
// ---------------------------------------------------------------------------------------------
// The f32 BVH traversal against brute force: meshes and analytic shapes, rays from surfaces,
// far from the origin (where an f32 ulp exceeds the triangles), tiny and huge scales.

/// `{"scale": s, "translate": far}` as JSON.
pub(super) fn scale_then_move(s: f64, far: DVec3) -> String {
    format!(r#"{{"scale": {}, "translate": {}}}"#, js(s), jv(far.to_array()))
}

/// The benchmark's bumpy UV sphere of radius ~1 (`4 n^2` triangles,
/// `bench_scenes::bumpy_sphere_triangles`) as a Mesh, scaled by `s` and moved to `far`.
pub(super) fn bumpy_mesh(n: u32, s: f64, far: DVec3) -> Shape {
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
pub(super) fn scaled_scene(r: &mut Pcg64, s: f64, far: DVec3) -> Vec<Shape> {
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
pub(super) fn check_ray(world: &World, ray: &Ray, t_max: f64) -> Option<Hit> {
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
