//! Transforms, scene-file validation naming the field, and OBJ loading.

use super::*;

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
