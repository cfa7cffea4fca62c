//! Hostile and careless input (issue: "no file written outside the output folder, no input
//! overwritten, no abort, no hang, no silent infinity"): one regression test per failure found.

use std::path::{Path, PathBuf};

use spectrace_renderer::{
    LoadOptions, PartialFilm, RenderOptions, RenderReport, Scene, merge_parts, render_file,
    render_scene,
};
use spectrace_spectrum::Xyz;
use spectrace_tracer::Film;

use crate::rendering::temp_dir;

const PLANE: &str = r#"{
  "camera": {"position": [0, 3, 0.001], "look_at": [0, 0, 0], "up": [0, 0, -1], "fov": 60, "width": 16, "height": 16},
  "objects": [{"shape": {"type": "Rectangle", "corner": [-3, 0, 3], "edge_u": [6, 0, 0], "edge_v": [0, 0, -6]},
               "material": {"type": "Diffuse", "reflectance": 0.5}}],
  "lights": [{"type": "PointLight", "position": [2.2, 1, 0.2], "power": 100,
              "spd": {"type": "Uniform", "min_nm": 400, "max_nm": 700}}],
  "settings": {"chunk_beams": 1000}
}"#;

fn options(out: &Path) -> RenderOptions {
    RenderOptions {
        beams: Some(4000),
        threads: Some(1),
        seed: Some(5),
        out_dir: out.to_owned(),
        // These tests are about files and ranges; the light tracer's beams make the chunk
        // counts they check.
        integrator: Some(spectrace_tracer::IntegratorChoice::Light),
        ..RenderOptions::default()
    }
}

/// Renders `PLANE` in two shards into `dir/parts`; returns the scene path and the part files.
fn two_parts(dir: &Path) -> (PathBuf, Vec<PathBuf>) {
    std::fs::create_dir_all(dir).unwrap();
    let scene_path = dir.join("plane.json");
    std::fs::write(&scene_path, PLANE).unwrap();
    let scene = Scene::load(&scene_path).unwrap();
    let parts = (0..2)
        .map(|k| {
            let o = RenderOptions { shard: Some((k, 2)), ..options(&dir.join("parts")) };
            PathBuf::from(&render_scene(&scene, &o).unwrap().outputs[0])
        })
        .collect();
    (scene_path, parts)
}

fn read_part(path: &Path) -> PartialFilm {
    PartialFilm::read(path).unwrap()
}

fn write_part(path: &Path, part: &PartialFilm) {
    std::fs::write(path, part.encode().unwrap()).unwrap();
}

fn files_in(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .map(|r| r.map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect())
        .unwrap_or_default();
    v.sort();
    v
}

/// Failure 1: a part's stored output name is validated; `merge` never writes outside `--out`.
#[test]
fn merge_refuses_part_names_that_leave_the_output_folder() {
    let dir = temp_dir("merge-names");
    let (_, parts) = two_parts(&dir);
    let escape = dir.join("escaped");
    for name in [escape.display().to_string(), "../x".to_owned(), String::new(), "a\0b".to_owned()]
    {
        let mut part = read_part(&parts[0]);
        part.name = name.clone();
        let forged = dir.join("forged.bin");
        write_part(&forged, &part);
        let e = merge_parts(&[forged, parts[1].clone()], &dir.join("out")).unwrap_err().to_string();
        assert!(e.contains("forged.bin") && e.contains("name"), "{name:?}: {e}");
    }
    assert!(files_in(&dir.join("out")).is_empty(), "{:?}", files_in(&dir.join("out")));
    assert!(!dir.join("x.exr").exists() && !escape.with_extension("exr").exists());
}

/// Failure 2: an output never replaces an input (scene, OBJ mesh, part file).
#[test]
fn outputs_never_replace_the_scene_a_mesh_or_a_part() {
    let dir = temp_dir("replace");
    let scene_path = dir.join("s.json");
    std::fs::write(&scene_path, PLANE).unwrap();
    let e = render_file(&scene_path, &options(&dir)).unwrap_err().to_string();
    assert!(e.contains("would replace the input") && e.contains("s.json"), "{e}");
    assert_eq!(std::fs::read_to_string(&scene_path).unwrap(), PLANE, "the scene was changed");
    assert_eq!(files_in(&dir), ["s.json"], "something was written");
    // An OBJ mesh whose name an output would take.
    std::fs::write(dir.join("floor.png"), "v -3 0 3\nv 3 0 3\nv 3 0 -3\nf 1 2 3\n").unwrap();
    let with_mesh = PLANE
        .replace(
            r#"{"type": "Rectangle", "corner": [-3, 0, 3], "edge_u": [6, 0, 0], "edge_v": [0, 0, -6]}"#,
            r#"{"type": "Mesh", "obj": "floor.png"}"#,
        )
        .replace("\"settings\"", "\"output\": {\"name\": \"floor\"}, \"settings\"");
    let mesh_scene = dir.join("mesh.json");
    std::fs::write(&mesh_scene, with_mesh).unwrap();
    let e = render_file(&mesh_scene, &options(&dir)).unwrap_err().to_string();
    assert!(e.contains("would replace the input") && e.contains("floor.png"), "{e}");
    // A part file renamed to what merge writes.
    let (_, parts) = two_parts(&dir.join("merge"));
    let renamed = dir.join("merge").join("plane.exr");
    std::fs::rename(&parts[0], &renamed).unwrap();
    let before = std::fs::read(&renamed).unwrap();
    let e = merge_parts(&[renamed.clone(), parts[1].clone()], &dir.join("merge"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("would replace the input"), "{e}");
    assert_eq!(std::fs::read(&renamed).unwrap(), before);
}

/// Failure 3: decoding is bounded: a forged length prefix, a device, a huge file.
#[test]
fn forged_lengths_and_endless_files_are_refused_without_allocating() {
    let dir = temp_dir("bounded");
    // The current version, fingerprint 7, then a string whose length prefix claims 2^33 or 2^62
    // bytes (bincode's varint: 253 then 8 little-endian bytes).
    for claimed in [1u64 << 33, 1 << 62, u64::MAX] {
        let mut bytes = vec![spectrace_renderer::PARTIAL_VERSION as u8, 7, 253];
        bytes.extend_from_slice(&claimed.to_le_bytes());
        bytes.extend_from_slice(b"scene.json");
        let e = PartialFilm::decode(&bytes).unwrap_err();
        assert!(e.contains("not a Spectrace partial film"), "{claimed}: {e}");
    }
    #[cfg(unix)]
    {
        let e = merge_parts(&[PathBuf::from("/dev/zero")], &dir).unwrap_err().to_string();
        assert!(e.contains("/dev/zero") && e.contains("not a regular file"), "{e}");
        let e = Scene::load(Path::new("/dev/zero")).unwrap_err().to_string();
        assert!(e.contains("not a regular file"), "{e}");
    }
    let e = Scene::load(&dir).unwrap_err().to_string();
    assert!(e.contains("directory"), "{e}");
}

fn report_of(dir: &Path) -> RenderReport {
    let text = std::fs::read_to_string(dir.join("plane.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

fn exr_values(path: &Path) -> Vec<f32> {
    use exr::prelude::*;
    let image = read_first_rgba_layer_from_file(
        path,
        |res, _| vec![0f32; res.width() * res.height() * 3],
        |buf, pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            let i = (pos.y() * 16 + pos.x()) * 3;
            buf[i] = r;
            buf[i + 1] = g;
            buf[i + 2] = b;
        },
    )
    .unwrap();
    image.layer_data.channel_data.pixels
}

/// Failure 5: an image beyond the range of 32-bit floats is scaled by a recorded power of two,
/// reported, and never written as infinity; a normal image is written unscaled.
#[test]
fn lights_beyond_f32_range_never_write_infinity() {
    let dir = temp_dir("infinity");
    for (power, expect_scaled) in [("100", false), ("1e43", true), ("8e307", true), ("1e-40", true)]
    {
        let out = dir.join(power);
        let json = PLANE.replace("\"power\": 100", &format!("\"power\": {power}"));
        let scene = Scene::from_json(&json, Path::new("plane.json")).unwrap();
        let report = render_scene(&scene, &options(&out)).unwrap();
        let values = exr_values(&out.join("plane.exr"));
        assert!(values.iter().all(|v| v.is_finite()), "{power}: non-finite value in the EXR");
        let largest = values.iter().fold(0f32, |m, v| m.max(v.abs()));
        assert!(largest > 0.0, "{power}: black EXR");
        let sidecar = report_of(&out);
        assert_eq!(sidecar, report);
        if expect_scaled {
            assert_ne!(report.exr_scale_log2, 0, "{power}");
            assert!(report.out_of_range_values > 0, "{power}");
            assert!(
                report.warnings.iter().any(|w| w.contains("2^")),
                "{power}: {:?}",
                report.warnings
            );
            // Scaled so the largest value is in [1, 2).
            assert!((1.0..2.0).contains(&largest), "{power}: largest {largest}");
        } else {
            assert_eq!((report.exr_scale_log2, report.out_of_range_values), (0, 0));
            assert!(report.warnings.is_empty(), "{:?}", report.warnings);
        }
    }
    // The scale is exact: the 1e43 W image is the 100 W image times 1e41, to f32 rounding.
    let normal = exr_values(&dir.join("100").join("plane.exr"));
    let huge = exr_values(&dir.join("1e43").join("plane.exr"));
    let k = report_of(&dir.join("1e43")).exr_scale_log2;
    for (a, b) in normal.iter().zip(&huge) {
        let expected = f64::from(*a) * 1e41 * 2f64.powi(k);
        assert!((f64::from(*b) - expected).abs() <= 1e-6 * expected.abs() + 1e-30, "{a} {b}");
    }
}

/// Failure 7: every field of a part file is validated; a tampered part is refused with the file
/// and the field named.
#[test]
fn tampered_part_files_are_refused_field_by_field() {
    let dir = temp_dir("tampered");
    let (_, parts) = two_parts(&dir);
    let good = read_part(&parts[0]);
    let forged = dir.join("forged.bin");
    let check = |part: &PartialFilm, field: &str| {
        write_part(&forged, part);
        let e = merge_parts(&[forged.clone(), parts[1].clone()], &dir.join("out"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("forged.bin") && e.contains(field), "{field}: {e}");
    };
    for power in [f64::NAN, f64::INFINITY, -1.0, 0.0] {
        check(&PartialFilm { light_power: power, ..good.clone() }, "light_power");
    }
    let mut p = good.clone();
    p.output_settings.exposure = f64::NAN;
    check(&p, "exposure");
    // Negative pixel sums.
    let mut p = good.clone();
    let mut film = Film::new(16, 16).unwrap();
    film.add(3, 3, Xyz::new(-1.0, 0.0, 0.0));
    p.output.film = film;
    check(&p, "negative");
    // A pixel array shorter or longer than width x height.
    for delta in [-1i64, 1] {
        let mut v = serde_json::to_value(&good.output.film).unwrap();
        let sums = v["sums"].as_array_mut().unwrap();
        if delta < 0 {
            sums.pop();
        } else {
            sums.push(sums[0].clone());
        }
        let mut p = good.clone();
        p.output.film = serde_json::from_value(v).unwrap();
        check(&p, "pixels");
    }
    // A 33.5-Mpixel image from a few sums.
    let mut v = serde_json::to_value(&good.output.film).unwrap();
    v["width"] = serde_json::json!(8192);
    v["height"] = serde_json::json!(4096);
    let mut p = good.clone();
    p.output.film = serde_json::from_value(v).unwrap();
    check(&p, "pixels");
    // Beams that would wrap the total, or do not match the chunks.
    let mut p = good.clone();
    p.output.beams = u64::MAX;
    p.output.stats.beams = u64::MAX;
    check(&p, "beams");
    // Chunks out of range, repeated, or unsorted.
    for chunks in [vec![0, 99], vec![0, 0], vec![2, 0]] {
        let mut p = good.clone();
        p.output.chunks = chunks.clone();
        check(&p, "chunks");
    }
    // Trailing bytes.
    let mut bytes = good.encode().unwrap();
    bytes.extend_from_slice(b"junk");
    std::fs::write(&forged, &bytes).unwrap();
    let e = merge_parts(&[forged.clone(), parts[1].clone()], &dir.join("out")).unwrap_err();
    assert!(e.to_string().contains("4 unexpected bytes"), "{e}");
    // Two copies of one chunk are named as such, not counted as coverage.
    let e = merge_parts(&[parts[0].clone(), parts[0].clone()], &dir.join("out")).unwrap_err();
    assert!(e.to_string().contains("is also in"), "{e}");
    let e = merge_parts(&[parts[0].clone()], &dir.join("out")).unwrap_err().to_string();
    assert!(e.contains("cover 2 of 4 chunks; missing e.g. [1, 3]"), "{e}");
    assert!(files_in(&dir.join("out")).is_empty());
    // The untampered parts still merge.
    let merged = merge_parts(&parts, &dir.join("out")).unwrap();
    assert_eq!(merged.beams, 4000);
}

/// Failure 8 (renderer side): a byte-order mark is accepted; `--out` naming a file is refused
/// clearly.
#[test]
fn a_byte_order_mark_is_skipped_and_an_out_file_is_refused() {
    let dir = temp_dir("bom");
    let path = dir.join("bom.json");
    std::fs::write(&path, format!("\u{feff}{PLANE}")).unwrap();
    assert!(Scene::load(&path).is_ok());
    let out_file = dir.join("not-a-folder");
    std::fs::write(&out_file, "x").unwrap();
    let e = render_file(&path, &options(&out_file)).unwrap_err().to_string();
    assert!(e.contains("is a file, not a folder"), "{e}");
    let latin1 = dir.join("latin1.json");
    std::fs::write(&latin1, b"{\n  \"camera\": \"caf\xe9\"}").unwrap();
    let e = Scene::load(&latin1).unwrap_err().to_string();
    assert!(e.contains(":2:") && e.contains("not UTF-8"), "{e}");
}

/// Failure 9: output names are checked before rendering, and no partial output is left behind.
#[test]
fn bad_output_names_are_refused_before_rendering() {
    let dir = temp_dir("names");
    let long = dir.join(format!("{}.json", "n".repeat(240)));
    std::fs::write(&long, PLANE).unwrap();
    let e = render_file(&long, &options(&dir.join("out"))).unwrap_err().to_string();
    assert!(e.contains("output name") && e.contains("240 bytes"), "{e}");
    assert!(files_in(&dir.join("out")).is_empty());
    let nul = PLANE.replace("\"settings\"", "\"output\": {\"name\": \"a\\u0000b\"}, \"settings\"");
    let e = Scene::from_json(&nul, Path::new("x.json")).unwrap_err().to_string();
    assert!(e.contains("output.name") && e.contains("control character"), "{e}");
    // A successful render leaves exactly its outputs: no temporary files.
    render_file(&dir.join("n.json").tap_write(PLANE), &options(&dir.join("ok"))).unwrap();
    assert_eq!(files_in(&dir.join("ok")), ["n.exr", "n.json", "n.png"]);
}

trait TapWrite {
    fn tap_write(self, contents: &str) -> Self;
}

impl TapWrite for PathBuf {
    fn tap_write(self, contents: &str) -> Self {
        std::fs::write(&self, contents).unwrap();
        self
    }
}

/// Failure 6: `max_depth` has a documented upper bound.
#[test]
fn max_depth_beyond_its_bound_is_refused() {
    for (depth, ok) in [(10_000u64, true), (10_001, false), (4_000_000_000, false)] {
        let json = PLANE.replace("\"chunk_beams\": 1000", &format!("\"max_depth\": {depth}"));
        let r = Scene::from_json(&json, Path::new("x.json"));
        assert_eq!(r.is_ok(), ok, "{depth}");
        if let Err(e) = r {
            let e = e.to_string();
            assert!(e.contains("settings.max_depth") && e.contains("at most 10000"), "{e}");
        }
    }
}

/// `--restrict-paths`: meshes outside the scene's folder (by `..`, absolute path or symlink) are
/// refused; without it they load, as a user on their own machine expects.
#[test]
fn restricted_scenes_cannot_reach_outside_their_folder() {
    let dir = temp_dir("restrict");
    std::fs::create_dir_all(dir.join("scene")).unwrap();
    let obj = "v -3 0 3\nv 3 0 3\nv 3 0 -3\nf 1 2 3\n";
    std::fs::write(dir.join("outside.obj"), obj).unwrap();
    std::fs::write(dir.join("scene").join("inside.obj"), obj).unwrap();
    let rect =
        r#"{"type": "Rectangle", "corner": [-3, 0, 3], "edge_u": [6, 0, 0], "edge_v": [0, 0, -6]}"#;
    let with = |obj: &str| {
        let p = dir.join("scene").join("s.json");
        std::fs::write(
            &p,
            PLANE.replace(rect, &format!("{{\"type\": \"Mesh\", \"obj\": {obj:?}}}")),
        )
        .unwrap();
        p
    };
    let restrict = LoadOptions { restrict_paths: true };
    let inside = with("inside.obj");
    assert!(Scene::load_with(&inside, restrict).is_ok());
    let outside_abs = dir.join("outside.obj").display().to_string();
    let mut cases = vec!["../outside.obj".to_owned(), outside_abs];
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink(dir.join("outside.obj"), dir.join("scene").join("link.obj"))
            .unwrap();
        cases.push("link.obj".to_owned());
    }
    for case in cases {
        let p = with(&case);
        assert!(Scene::load(&p).is_ok(), "{case} should load without --restrict-paths");
        let e = Scene::load_with(&p, restrict).unwrap_err().to_string();
        assert!(
            e.contains("objects[0].shape.obj") && e.contains("outside the scene's folder"),
            "{e}"
        );
    }
}
