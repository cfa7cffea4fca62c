//! Hostile input: huge, tiny and special values and files, accepted or refused naming a field.

use super::*;

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

pub(super) fn transform_err(json: &str) -> String {
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
pub(super) fn shape_fields(json: &str) -> &'static [&'static str] {
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

pub(super) fn extreme() -> impl Strategy<Value = f64> {
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

pub(super) fn extreme_vec() -> impl Strategy<Value = [f64; 3]> {
    [extreme(), extreme(), extreme()]
}

pub(super) fn js(x: f64) -> String {
    serde_json::to_string(&x).unwrap()
}

pub(super) fn jv(a: [f64; 3]) -> String {
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
