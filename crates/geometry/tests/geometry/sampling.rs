//! Area sampling for emitting shapes: points on the surface with the hit normal, areas against
//! closed forms, uniformity by chi-square.

use super::*;

/// The transforms of the area tests: a similarity (for the analytic shapes), and an affine one
/// with shear and non-uniform scale (rectangles and meshes).
const SIMILARITY: &str =
    r#"{"scale": 1.5, "rotate": {"axis": [1, 2, -0.5], "degrees": 37}, "translate": [3, -1, 20]}"#;
const AFFINE: &str =
    r#"{"matrix": [[2, 0.5, 0, 1], [0, 3, 0.25, -2], [0.3, 0, 1.5, 4], [0, 0, 0, 1]]}"#;
const MIRROR: &str = r#"{"scale": [-1, 2, 1.5], "translate": [0, 0, -3]}"#;

pub(super) fn transform(json: &str) -> Transform {
    serde_json::from_str(json).unwrap()
}

/// Three separate triangles in the untransformed `x` ranges [0, 1], [2, 4], [5, 5.5] (areas
/// 0.5, 1.5, 0.125 before the transform), a zero-area one (collinear), never to be sampled.
const SEPARATE_TRIANGLES: &str = r#""positions": [[0, 0, 0], [1, 0, 0], [0, 1, 0.2],
    [2, 0, 1], [4, 0, 1], [2, 1.5, 0], [5, 0, 0], [5.5, 0, 0], [5, 0.5, 0.5],
    [7, 0, 0], [8, 1, 1], [9, 2, 2]],
    "triangles": [[0, 1, 2], [3, 4, 5], [6, 7, 8], [9, 10, 11]]"#;

/// One shape of each kind, transformed, with its size (the scale of its tolerances).
pub(super) fn area_shapes() -> Vec<(Shape, f64)> {
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
pub(super) fn assert_on_surface(shape: &Shape, p: SurfacePoint, size: f64) -> Hit {
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

pub(super) fn uniforms(r: &mut Pcg64) -> [f64; 3] {
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
pub(super) fn tri_area(p: [DVec3; 3]) -> f64 {
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
pub(super) fn chi_square_p(counts: &[u64], expected: &[f64]) -> f64 {
    spectrace_sampling::stats::chi_square(counts, expected, 5.0).p_value
}

/// `n` samples of `s`, each mapped back to the untransformed (local) frame of `json`.
pub(super) fn local_samples(s: &Shape, json: &str, n: usize, seed: u64) -> Vec<DVec3> {
    let inv = transform(json).inverse();
    let mut r = rng(seed);
    (0..n).map(|_| inv.point(s.sample_area(uniforms(&mut r)).point)).collect()
}

/// The bin of `x` in `[0, 1)` among `k` equal bins.
pub(super) fn bin(x: f64, k: usize) -> usize {
    ((x * k as f64).max(0.0) as usize).min(k - 1)
}

/// Azimuth of `(x, y)` over `2 pi`, in `[0, 1)`.
pub(super) fn turn(x: f64, y: f64) -> f64 {
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
pub(super) fn mesh_cell_counts(
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
