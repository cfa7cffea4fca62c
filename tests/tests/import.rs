//! The Mitsuba importer: the real scenes of `../shared/realworld/scenes/` (skipped, with a
//! message, when that folder is absent), the unit conversions of every emitter, errors with
//! file and line for what is not supported, `-D`, `convert`, and PLY meshes.

use std::f64::consts::PI;
use std::path::{Path, PathBuf};

use spectrace_lights::LightSource;
use spectrace_renderer::{
    LoadOptions, RenderOptions, Scene, convert, import_mitsuba, render_in_memory,
};

use crate::rendering::temp_dir;

/// `../shared/realworld/scenes` beside the workspace, if present.
fn realworld_scenes() -> Option<PathBuf> {
    crate::rendering::realworld("scenes")
}

/// Writes `files` (name, text) into a fresh folder and returns the first one's path.
fn write_scene(test: &str, files: &[(&str, &str)]) -> PathBuf {
    let dir = temp_dir(test);
    for (name, text) in files {
        std::fs::write(dir.join(name), text).unwrap();
    }
    dir.join(files[0].0)
}

const SENSOR: &str = r#"<sensor type="perspective"><float name="fov" value="40"/>
    <transform name="to_world"><lookat origin="0,0,5" target="0,0,0" up="0,1,0"/></transform>
    <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="12"/></film></sensor>"#;

fn with_sensor(body: &str) -> String {
    format!("<scene version=\"3.0.0\">\n{SENSOR}\n{body}\n</scene>\n")
}

/// Every XML scene of the real scene folder imports, loads and renders (8 spp, 32 pixels wide
/// where the file lets `-D` set the size) to a finite, lit image; the Cornell boxes' light is the
/// glowing luminaire or rectangle, with the power `pi A integral(L)`.
#[test]
fn the_real_mitsuba_scenes_import_and_render() {
    let Some(dir) = realworld_scenes() else { return };
    let defines: Vec<(String, String)> = [("res", "32"), ("resx", "32"), ("resy", "32")]
        .iter()
        .map(|(k, v)| ((*k).into(), (*v).into()))
        .collect();
    for file in [
        "mitsuba3-cbox/cbox.xml",
        "mitsuba3-cbox/cbox-spectral.xml",
        "mitsuba3-cbox/cbox-rgb.xml",
        "bitterli-cornell-box/scene_v3.xml",
    ] {
        let path = dir.join(file);
        let scene = Scene::import_with(&path, &defines, LoadOptions::default())
            .unwrap_or_else(|e| panic!("{file}: {e}"));
        assert_eq!(scene.camera.width(), 32, "{file}");
        assert_eq!(scene.lights.lights().len(), 1, "{file}");
        assert!(
            scene.inputs.iter().any(|p| p.ends_with(Path::new(file).file_name().unwrap())),
            "{file}"
        );
        let options = RenderOptions { spp: Some(8), threads: Some(2), ..RenderOptions::default() };
        let r = render_in_memory(&scene, &options).unwrap();
        let mean = r.image.iter().map(|p| p.y).sum::<f64>() / r.image.len() as f64;
        assert!(r.image.iter().all(|p| p.is_finite()), "{file}");
        assert!(mean > 0.01, "{file}: mean Y {mean}");
    }
    // The spectral box's luminaire: 130 x 105 mm, radiance table 400:0, 500:8, 600:15.6, 700:18.4.
    let scene = Scene::load(&dir.join("mitsuba3-cbox/cbox.xml")).unwrap();
    let integral =
        100.0 * (0.0 + 8.0) / 2.0 + 100.0 * (8.0 + 15.6) / 2.0 + 100.0 * (15.6 + 18.4) / 2.0;
    let power = scene.lights.power();
    let expected = PI * 130.0 * 105.0 * integral;
    assert!((power / expected - 1.0).abs() < 1e-9, "{power} vs {expected}");
}

/// Emitters in power: an area emitter of constant radiance 2 per nm on Mitsuba's default
/// rectangle (area 4) emits `pi * 4 * 2 * 470` W over 360-830 nm; a point light of intensity 3
/// per nm `4 pi * 3 * 470`; a spot of cutoff 30 and beam width 20 degrees the integral of its
/// linear falloff (checked against a midpoint sum).
#[test]
fn emitter_units_convert_exactly() {
    let area = with_sensor(
        r#"<shape type="rectangle"><emitter type="area"><spectrum name="radiance" value="2"/></emitter></shape>"#,
    );
    let scene = Scene::load(&write_scene("import-area", &[("a.xml", &area)])).unwrap();
    assert!((scene.lights.power() / (PI * 4.0 * 2.0 * 470.0) - 1.0).abs() < 1e-12);

    let point = with_sensor(
        r#"<shape type="sphere"/><emitter type="point"><point name="position" value="0,2,0"/><spectrum name="intensity" value="3"/></emitter>"#,
    );
    let scene = Scene::load(&write_scene("import-point", &[("p.xml", &point)])).unwrap();
    assert!((scene.lights.power() / (4.0 * PI * 3.0 * 470.0) - 1.0).abs() < 1e-12);

    let spot = with_sensor(
        r#"<shape type="sphere"/><emitter type="spot"><float name="cutoff_angle" value="30"/><float name="beam_width" value="20"/>
        <spectrum name="intensity" value="1"/><transform name="to_world"><lookat origin="0,3,0" target="0,0,0" up="0,0,1"/></transform></emitter>"#,
    );
    let scene = Scene::load(&write_scene("import-spot", &[("s.xml", &spot)])).unwrap();
    let (c, b) = (30f64.to_radians(), 20f64.to_radians());
    let n = 100_000;
    let solid: f64 = (0..n)
        .map(|i| {
            let t = c * (i as f64 + 0.5) / n as f64;
            let f = if t <= b { 1.0 } else { (c - t) / (c - b) };
            2.0 * PI * f * t.sin() * c / n as f64
        })
        .sum();
    assert!(
        (scene.lights.power() / (solid * 470.0) - 1.0).abs() < 1e-6,
        "{} vs {}",
        scene.lights.power(),
        solid * 470.0
    );
}

/// A directional emitter of irradiance 2 per nm becomes a `Sky` of 2 * 470 W per m^2 across its
/// beams, whose rectangle, perpendicular to them, lies outside the objects and covers them.
#[test]
fn a_directional_emitter_becomes_a_sky_over_the_scene() {
    let xml = with_sensor(
        r#"<shape type="sphere"><point name="center" value="1,0,0"/><float name="radius" value="0.5"/></shape>
        <emitter type="directional"><vector name="direction" value="0,-1,0"/><spectrum name="irradiance" value="2"/></emitter>"#,
    );
    let imported =
        import_mitsuba(&write_scene("import-directional", &[("d.xml", &xml)]), &[]).unwrap();
    let sky = &imported.scene["lights"][0];
    assert_eq!(sky["type"], "Sky");
    let v = |k: &str| glam::DVec3::from_array(serde_json::from_value(sky[k].clone()).unwrap());
    let (corner, u, w, d) = (v("corner"), v("edge_u"), v("edge_v"), v("direction"));
    let area = u.cross(w).length();
    let power = sky["power"].as_f64().unwrap();
    assert!((power / area / (2.0 * 470.0) - 1.0).abs() < 1e-12);
    assert!(u.dot(d).abs() < 1e-12 && w.dot(d).abs() < 1e-12);
    let centre = corner + (u + w) / 2.0;
    // The rectangle is above the sphere (top at y = 0.5) and its footprint covers it.
    assert!(centre.y > 0.5 && (centre.x - 1.0).abs() < 1e-9 && centre.z.abs() < 1e-9, "{centre}");
    assert!(u.length() > 1.0 && w.length() > 1.0);
}

/// A constant environment of radiance 1 per nm is seen as luminance 1 in every direction
/// (the film's convention: `Y = integral L ybar / integral ybar`): the mean Y of an image that
/// sees only the environment (its one object behind the camera) is 1 within three standard
/// errors of its pixels.
#[test]
fn a_constant_environment_is_seen_as_its_radiance() {
    let xml = with_sensor(
        r#"<shape type="sphere"><point name="center" value="0,0,9"/><float name="radius" value="0.5"/></shape>
        <emitter type="constant"><spectrum name="radiance" value="1"/></emitter>"#,
    );
    let scene = Scene::load(&write_scene("import-constant", &[("c.xml", &xml)])).unwrap();
    let options = RenderOptions { spp: Some(16), threads: Some(2), ..RenderOptions::default() };
    let r = render_in_memory(&scene, &options).unwrap();
    let n = r.image.len() as f64;
    let mean = r.image.iter().map(|p| p.y).sum::<f64>() / n;
    let var = r.image.iter().map(|p| (p.y - mean).powi(2)).sum::<f64>() / (n - 1.0);
    let se = (var / n).sqrt();
    assert!((mean - 1.0).abs() < 3.0 * se + 1e-9, "{mean} +- {se}");
}

/// The shipped Mitsuba scene (`scenes/mitsuba/sky_plastic_gold.xml`) imports with its sky as a
/// glowing sphere (a fourth object) and its sun as a `Sky`, and renders to a finite, lit image.
#[test]
fn the_shipped_mitsuba_scene_imports_and_renders() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/mitsuba/sky_plastic_gold.xml");
    let defines = [("width".to_owned(), "32".to_owned()), ("height".to_owned(), "24".to_owned())];
    let imported = import_mitsuba(&path, &defines).unwrap();
    assert_eq!(imported.scene["objects"].as_array().unwrap().len(), 4);
    assert_eq!(imported.scene["lights"][0]["type"], "Sky");
    assert_eq!(imported.scene["objects"][0]["material"]["distribution"], "beckmann");
    let scene = Scene::import_with(&path, &defines, LoadOptions::default()).unwrap();
    let options = RenderOptions { spp: Some(4), threads: Some(2), ..RenderOptions::default() };
    let r = render_in_memory(&scene, &options).unwrap();
    assert!(r.image.iter().all(|p| p.is_finite()));
    assert!(r.image.iter().map(|p| p.y).sum::<f64>() / r.image.len() as f64 > 0.1);
}

/// Every shipped Mitsuba scene (`scenes/mitsuba/*.xml`) imports without an error, loads and
/// renders (2 spp) to a finite, lit image.
#[test]
fn every_shipped_mitsuba_scene_renders() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/mitsuba");
    let mut count = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "xml") {
            continue;
        }
        let scene = Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
        let options = RenderOptions { spp: Some(2), threads: Some(2), ..RenderOptions::default() };
        let r = render_in_memory(&scene, &options).unwrap();
        assert!(r.image.iter().all(|p| p.is_finite()), "{}", path.display());
        let mean = r.image.iter().map(|p| p.y).sum::<f64>() / r.image.len() as f64;
        assert!(mean > 0.01, "{}: {mean}", path.display());
        count += 1;
    }
    assert!(count >= 3, "the shipped Mitsuba scenes are missing");
}

/// Mitsuba's linear plastic (`nonlinear` false, its default) is imported with the base albedo
/// `R / (1 - F_dr + R F_dr)`, which makes Spectrace's diffuse term `R' / (1 - R' F_dr)` equal
/// Mitsuba's `R / (1 - F_dr)`; with `nonlinear` true the albedo is kept.
#[test]
fn a_linear_plastic_keeps_mitsubas_diffuse_term() {
    for (nonlinear, keep) in [("false", false), ("true", true)] {
        let xml = with_sensor(&format!(
            r#"<shape type="sphere"><bsdf type="plastic"><float name="diffuse_reflectance" value="0.4"/>
            <boolean name="nonlinear" value="{nonlinear}"/><float name="int_ior" value="1.5"/><float name="ext_ior" value="1"/></bsdf>
            <emitter type="area"><spectrum name="radiance" value="1"/></emitter></shape>"#
        ));
        let imported = import_mitsuba(
            &write_scene(&format!("import-plastic-{nonlinear}"), &[("p.xml", &xml)]),
            &[],
        )
        .unwrap();
        let r = imported.scene["objects"][0]["material"]["reflectance"].as_f64().unwrap();
        if keep {
            assert_eq!(r, 0.4);
        } else {
            let white: spectrace_materials::Plastic =
                serde_json::from_str(r#"{"reflectance": 1.0, "ior": 1.5}"#).unwrap();
            let f = white.internal_diffuse_reflectance(550.0);
            assert!(f > 0.5 && f < 0.7, "{f}");
            assert!((r / (1.0 - r * f) - 0.4 / (1.0 - f)).abs() < 1e-12, "{r}");
        }
    }
}

/// What the importer does not support is refused with the file and line and the cause.
#[test]
fn unsupported_elements_are_refused_with_file_and_line() {
    let cases = [
        (
            with_sensor(r#"<shape type="sphere"><bsdf type="principled"/></shape>"#),
            ":5:",
            "principled",
        ),
        (
            with_sensor(r#"<shape type="sphere"><float name="wobble" value="1"/></shape>"#),
            ":5:",
            "wobble",
        ),
        (
            with_sensor(r#"<shape type="sphere"><float name="radius" value="$r"/></shape>"#),
            ":5:",
            "$r",
        ),
        (with_sensor(r#"<shape type="sphere"><ref id="nothing"/></shape>"#), ":5:", "<ref> here"),
        (
            with_sensor(
                r#"<shape type="sphere"><transform name="to_world"><scale x="2"/></transform></shape>"#,
            ),
            ":5:",
            "non-uniform",
        ),
        (with_sensor(r#"<emitter type="sunsky"/>"#), ":5:", "sunsky"),
        (
            with_sensor(
                r#"<emitter type="directional"><spectrum name="irradiance" value="1"/></emitter>"#,
            ),
            ":5:",
            "needs objects",
        ),
        (
            with_sensor(
                r#"<shape type="sphere"><bsdf type="diffuse"><rgb name="reflectance" value="1.5, 0, 0"/></bsdf></shape>"#,
            ),
            ":5:",
            "[0, 1]",
        ),
        ("<scene version=\"3.0.0\"><shape type=\"sphere\"/></scene>".to_owned(), "", "no <sensor>"),
        ("<scene><unclosed></scene>".to_owned(), "", "XML"),
    ];
    for (i, (text, line, cause)) in cases.iter().enumerate() {
        let path = write_scene(&format!("import-bad-{i}"), &[("bad.xml", text)]);
        let e = Scene::load(&path).unwrap_err().to_string();
        assert!(e.contains(&format!("bad.xml{line}")) && e.contains(cause), "case {i}: {e}");
    }
    // An include cycle is refused, not followed forever.
    let a = write_scene(
        "import-cycle",
        &[
            ("a.xml", "<scene version=\"3.0.0\"><include filename=\"b.xml\"/></scene>"),
            ("b.xml", "<scene version=\"3.0.0\"><include filename=\"a.xml\"/></scene>"),
        ],
    );
    let e = import_mitsuba(&a, &[]).unwrap_err().to_string();
    assert!(e.contains("cycle"), "{e}");
}

/// `-D` overrides a `<default>`, includes splice fragments, 0.6's camelCase names read, and an
/// RGB reflectance becomes a table whose colour under D65 is the RGB.
#[test]
fn defaults_includes_legacy_names_and_rgb() {
    let main = "<scene version=\"0.6.0\"><default name=\"fov\" value=\"40\"/><include filename=\"part.xml\"/>\n\
        <sensor type=\"perspective\"><float name=\"fov\" value=\"$fov\"/><string name=\"fovAxis\" value=\"y\"/></sensor></scene>";
    let part = "<scene version=\"0.6.0\"><shape type=\"sphere\"><bsdf type=\"diffuse\"><rgb name=\"reflectance\" value=\"0.6, 0.2, 0.1\"/></bsdf>\n\
        <emitter type=\"area\"><rgb name=\"radiance\" value=\"1\"/></emitter></shape></scene>";
    let path = write_scene("import-defaults", &[("main.xml", main), ("part.xml", part)]);
    let imported = import_mitsuba(&path, &[("fov".to_owned(), "25".to_owned())]).unwrap();
    assert_eq!(imported.scene["camera"]["fov"], 25.0);
    assert_eq!(imported.scene["camera"]["fov_axis"], "vertical");
    assert_eq!(imported.files.len(), 2);
    let r = &imported.scene["objects"][0]["material"]["reflectance"];
    let nm: Vec<f64> = serde_json::from_value(r["nm"].clone()).unwrap();
    let values: Vec<f64> = serde_json::from_value(r["values"].clone()).unwrap();
    let table = spectrace_spectrum::Reflectance::from_table(&nm, &values).unwrap();
    let rgb = spectrace_spectrum::rgb::srgb_under_d65(&|l| table.value(l));
    for (c, want) in rgb.iter().zip([0.6, 0.2, 0.1]) {
        assert!((c - want).abs() < 2e-3, "{rgb:?}");
    }
    let scene = Scene::load(&path).unwrap();
    assert_eq!(scene.camera.width(), 768);
}

/// `convert` writes a native scene that loads (mesh paths relative to its folder), and never
/// writes over the scene it reads.
#[test]
fn convert_writes_a_loadable_native_scene_and_never_replaces_an_input() {
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    let xml = with_sensor(
        r#"<shape type="obj"><string name="filename" value="tri.obj"/><emitter type="area"><rgb name="radiance" value="1,1,1"/></emitter></shape>"#,
    );
    let path = write_scene("import-convert", &[("s.xml", &xml), ("tri.obj", obj)]);
    let out = path.parent().unwrap().join("sub/s.json");
    let notes = convert(&path, &out, &[]).unwrap();
    assert!(notes.iter().all(|n| n.contains("s.xml:")), "{notes:?}");
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(text.contains("\"../tri.obj\""), "{text}");
    Scene::load(&out).unwrap();
    let e = convert(&path, &path, &[]).unwrap_err();
    assert!(e.contains("s.xml"), "{e}");
    assert!(std::fs::read_to_string(&path).unwrap().contains("<scene"));
}

/// A `serialized` shape reads mesh `shape_index` of its file, with smooth vertex normals
/// computed where the file has none (as Mitsuba does) unless `face_normals` is set; an index
/// past the file's meshes is refused naming the count.
#[test]
fn serialized_meshes_import_by_index_with_mitsubas_normals() {
    let tri = |z: f32| (vec![[0.0, 0.0, z], [1.0, 0.0, z], [0.0, 1.0, z]], vec![[0, 1, 2]]);
    let bytes = spectrace_geometry::write_serialized(&[tri(0.0), tri(-1.0)]);
    let dir = temp_dir("import-serialized");
    std::fs::write(dir.join("m.serialized"), bytes).unwrap();
    let shape = |index: u32, face: bool| {
        with_sensor(&format!(
            r#"<shape type="serialized"><string name="filename" value="m.serialized"/><integer name="shape_index" value="{index}"/>
            <boolean name="face_normals" value="{face}"/><emitter type="area"><spectrum name="radiance" value="1"/></emitter></shape>"#
        ))
    };
    std::fs::write(dir.join("s.xml"), shape(1, false)).unwrap();
    let imported = import_mitsuba(&dir.join("s.xml"), &[]).unwrap();
    assert_eq!(imported.scene["objects"][0]["shape"]["shape_index"], 1);
    assert_eq!(imported.scene["objects"][0]["shape"]["vertex_normals"], "computed");
    let scene = Scene::load(&dir.join("s.xml")).unwrap();
    assert!((scene.lights.power() / (PI * 0.5 * 470.0) - 1.0).abs() < 1e-9);
    std::fs::write(dir.join("f.xml"), shape(0, true)).unwrap();
    let imported = import_mitsuba(&dir.join("f.xml"), &[]).unwrap();
    assert_eq!(imported.scene["objects"][0]["shape"]["vertex_normals"], "none");
    std::fs::write(dir.join("bad.xml"), shape(2, false)).unwrap();
    let e = Scene::load(&dir.join("bad.xml")).unwrap_err().to_string();
    assert!(e.contains("2 meshes"), "{e}");
}

/// A `thindielectric` becomes a `ThinDielectric` of index `int_ior / ext_ior` (air by default).
#[test]
fn a_thin_dielectric_keeps_its_relative_index() {
    let xml = with_sensor(
        r#"<shape type="rectangle"><bsdf type="thindielectric"><float name="int_ior" value="1.7"/></bsdf></shape>
        <emitter type="point"><point name="position" value="0,0,1"/><spectrum name="intensity" value="1"/></emitter>"#,
    );
    let imported = import_mitsuba(&write_scene("import-thin", &[("t.xml", &xml)]), &[]).unwrap();
    let m = &imported.scene["objects"][0]["material"];
    assert_eq!(m["type"], "ThinDielectric");
    assert!((m["ior"].as_f64().unwrap() - 1.7 / 1.000_277).abs() < 1e-12);
}

/// `<spectrum filename>` reads `wavelength value` lines (comments skipped) as a table, zero
/// outside it; a malformed line is refused with its number; a `-D` the scene never uses is
/// noted.
#[test]
fn spectrum_files_and_unused_defines() {
    let xml = with_sensor(
        r#"<shape type="sphere"><bsdf type="diffuse"><spectrum name="reflectance" filename="r.spd"/></bsdf></shape>
        <emitter type="point"><point name="position" value="0,2,0"/><spectrum name="intensity" value="1"/></emitter>"#,
    );
    let path = write_scene(
        "import-spd",
        &[("s.xml", &xml), ("r.spd", "# measured\n400 0.2\n500 0.4 # peak\n\n700 0.3\n")],
    );
    let imported = import_mitsuba(&path, &[("unused".to_owned(), "1".to_owned())]).unwrap();
    let r = &imported.scene["objects"][0]["material"]["reflectance"];
    assert_eq!(r["nm"], serde_json::json!([399.999, 400.0, 500.0, 700.0, 700.001]));
    assert_eq!(r["values"], serde_json::json!([0.0, 0.2, 0.4, 0.3, 0.0]));
    assert!(imported.notes.iter().any(|n| n.message.contains("-D unused")), "{:?}", imported.notes);
    std::fs::write(path.parent().unwrap().join("r.spd"), "400 0.2\n500\n").unwrap();
    let e = import_mitsuba(&path, &[]).unwrap_err().to_string();
    assert!(e.contains("r.spd") && e.contains("line 2"), "{e}");
}

/// Every file a Mitsuba scene names goes through the scene's path policy: with
/// `--restrict-paths` an include outside its folder is refused; without it the include and a
/// spectrum file are inputs that `convert` never writes over; whole-number parameters are
/// refused, not rounded, when they are fractions or too small.
#[test]
fn included_files_follow_the_path_policy_and_counts_are_whole() {
    let outside = temp_dir("import-policy-outside");
    std::fs::write(outside.join("part.xml"), "<scene version=\"3.0.0\"></scene>").unwrap();
    std::fs::write(outside.join("r.spd"), "400 0.5\n700 0.5\n").unwrap();
    let xml = with_sensor(&format!(
        r#"<include filename="{}"/><shape type="sphere"><bsdf type="diffuse"><spectrum name="reflectance" filename="{}"/></bsdf>
        <emitter type="area"><spectrum name="radiance" value="1"/></emitter></shape>"#,
        outside.join("part.xml").display(),
        outside.join("r.spd").display()
    ));
    let path = write_scene("import-policy", &[("s.xml", &xml)]);
    let e = Scene::import_with(&path, &[], LoadOptions { restrict_paths: true })
        .unwrap_err()
        .to_string();
    assert!(e.contains("restrict-paths") && e.contains("s.xml:"), "{e}");
    let imported = import_mitsuba(&path, &[]).unwrap();
    assert!(imported.files.iter().any(|f| f.ends_with("r.spd")), "{:?}", imported.files);
    let e = convert(&path, &outside.join("r.spd"), &[]).unwrap_err();
    assert!(e.contains("r.spd"), "{e}");
    assert_eq!(std::fs::read_to_string(outside.join("r.spd")).unwrap(), "400 0.5\n700 0.5\n");
    for (param, bad) in [("sample_count", "2.5"), ("sample_count", "0"), ("seed", "-1")] {
        let xml = with_sensor(
            r#"<integrator type="path"/><shape type="sphere"><emitter type="area"><spectrum name="radiance" value="1"/></emitter></shape>"#
        )
        .replace("</film></sensor>", &format!("</film><sampler type=\"independent\"><integer name=\"{param}\" value=\"{bad}\"/></sampler></sensor>"));
        let path = write_scene(&format!("import-whole-{param}-{bad}"), &[("w.xml", &xml)]);
        let e = import_mitsuba(&path, &[]).unwrap_err().to_string();
        assert!(e.contains(param) && e.contains("whole number"), "{e}");
    }
}

/// The real PLY meshes of Bitterli's Veach bidirectional room load (binary little-endian, with
/// normals and texture coordinates).
#[test]
fn the_real_ply_meshes_load() {
    let Some(dir) = realworld_scenes() else { return };
    let models = dir.join("bitterli-veach-bidir/models");
    let mut triangles = 0;
    for i in 0..12 {
        let mut mesh = spectrace_geometry::Mesh::from_ply(format!("Mesh{i:03}.ply"), None);
        mesh.load(&models).unwrap_or_else(|e| panic!("Mesh{i:03}: {e}"));
        assert!(mesh.triangles().len() >= 10, "Mesh{i:03}");
        triangles += mesh.triangles().len();
    }
    assert!(triangles > 7936, "{triangles}");
}
