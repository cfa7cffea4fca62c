//! A mutation fuzzer for the two kinds of file Spectrace reads from others: scene files and
//! partial films (`--shard` parts). Stable Rust, no external tool: a seeded generator mutates the
//! shipped scenes and a real part file, and every mutant must be either refused with an error or
//! loaded and rendered (a few beams) to an image with only finite values. A panic, abort or a case
//! slower than [`CASE_SECONDS`] fails the test and prints the input, which is then minimised by
//! hand and added to `tests/fuzz-corpus/` (replayed first by every run, so every crash ever found
//! stays a test).
//!
//! Bounded: `SPECTRACE_FUZZ_CASES` mutants per target (default 150, what CI runs in seconds) from
//! seed `SPECTRACE_FUZZ_SEED` (default 1). `cargo xtask fuzz --cases N --seed S` runs a longer
//! campaign in release mode. An abort or an out-of-memory kill cannot be caught in-process:
//! with `SPECTRACE_FUZZ_TRACE=1` every case names itself on standard error before it runs, so
//! the last name printed is the case that killed the run.

use std::panic::AssertUnwindSafe;
use std::path::{Path, PathBuf};
use std::time::Instant;

use rand::{Rng, RngExt, SeedableRng};
use rand_pcg::Pcg64;
use serde_json::Value;
use spectrace_lights::LightSource;
use spectrace_renderer::{
    PartialFilm, RenderOptions, Scene, encode_image, normalisation, plan_with, render_in_memory,
};
use spectrace_tracer::IntegratorChoice;
use spectrace_tracer::render;

/// Slowest acceptable case: loading plus a render of at most [`RENDER_BEAMS`] beams.
const CASE_SECONDS: f64 = 20.0;
/// Beams rendered for a mutant that loads.
const RENDER_BEAMS: u64 = 300;
/// Largest image rendered for a mutant (larger ones are loaded but not rendered, to keep the run
/// bounded; the film-size limit itself is tested elsewhere).
const RENDER_PIXELS: u64 = 1 << 16;

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap().to_owned()
}

fn env_or(name: &str, default: u64) -> u64 {
    std::env::var(name).ok().and_then(|v| v.parse().ok()).unwrap_or(default)
}

/// Runs `f` on `input`; a panic or an over-long case is returned as a failure report.
fn guarded<T>(what: &str, input: &[u8], f: impl FnOnce() -> T) -> Result<T, String> {
    let started = Instant::now();
    let outcome = std::panic::catch_unwind(AssertUnwindSafe(f));
    let seconds = started.elapsed().as_secs_f64();
    let shown = String::from_utf8_lossy(&input[..input.len().min(4000)]).into_owned();
    match outcome {
        Err(_) => Err(format!("{what}: PANIC on input:\n{shown}")),
        Ok(_) if seconds > CASE_SECONDS => {
            Err(format!("{what}: took {seconds:.1} s (limit {CASE_SECONDS} s) on input:\n{shown}"))
        }
        Ok(t) => Ok(t),
    }
}

/// How far a scene mutant got.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Reached {
    Refused,
    Loaded,
    Rendered,
}

/// Loads a scene text (as if it were a file in `scenes/`, so that the shipped scenes' luminaire
/// files resolve); if it loads, renders a few beams and checks the image is finite.
fn exercise_scene(text: &str) -> Reached {
    let path = workspace().join("scenes").join("fuzz.json");
    let Ok(scene) = Scene::from_json(text, &path) else { return Reached::Refused };
    exercise_loaded(&scene)
}

/// Renders a loaded scene (a few beams, when small) and checks every image is finite.
fn exercise_loaded(scene: &Scene) -> Reached {
    let pixels = u64::from(scene.camera.width()) * u64::from(scene.camera.height());
    if pixels > RENDER_PIXELS || scene.settings.max_depth > 256 {
        return Reached::Loaded;
    }
    let options =
        RenderOptions { beams: Some(RENDER_BEAMS), threads: Some(1), ..RenderOptions::default() };
    let Ok(plan) = plan_with(scene, &options, IntegratorChoice::Light) else {
        return Reached::Loaded;
    };
    let effects = spectrace_renderer::decide_effects(scene, None);
    let tracer = spectrace_renderer::tracer_scene(scene);
    let tracer = spectrace_tracer::LightTracer::new(&tracer, scene.tracer_settings(), effects);
    let Ok(output) = render(&tracer, &plan, &|_| {}) else { return Reached::Loaded };
    let image =
        encode_image(&output, normalisation(IntegratorChoice::Light, scene.lights.power(), 1));
    assert!(
        image.rgb.iter().flatten().all(|c| c.is_finite()),
        "non-finite value in the encoded image"
    );
    // The estimator the effects analysis picks (the path tracer for most scenes) as well.
    if let Ok(r) = render_in_memory(scene, &RenderOptions { integrator: None, ..options }) {
        let image =
            encode_image(&r.output, normalisation(r.integrator, scene.lights.power(), pixels));
        assert!(
            image.rgb.iter().flatten().all(|c| c.is_finite()),
            "non-finite value in the {} image",
            r.integrator.name()
        );
    }
    Reached::Rendered
}

/// Decodes part bytes; if they decode, the image they hold must encode to finite values.
fn exercise_part(bytes: &[u8]) {
    if let Ok(part) = PartialFilm::decode(bytes) {
        let (w, h) = (part.output.film.width(), part.output.film.height());
        let norm = normalisation(part.integrator, part.light_power, u64::from(w) * u64::from(h));
        let image = encode_image(&part.output, norm);
        assert!(image.rgb.iter().flatten().all(|c| c.is_finite()), "non-finite value");
    }
}

/// Values a mutation may put in place of any JSON node.
fn extreme(rng: &mut impl Rng) -> Value {
    let numbers = [
        0.0,
        -0.0,
        1.0,
        -1.0,
        0.5,
        1.5,
        1e-320,
        5e-324,
        1e-300,
        1e300,
        -1e300,
        1.7e308,
        4e9,
        2.0f64.powi(53),
        360.0,
        180.0,
        1e43,
        65536.0,
    ];
    match rng.random_range(0..10) {
        0..=4 => serde_json::json!(numbers[rng.random_range(0..numbers.len())]),
        5 => serde_json::json!(u64::MAX),
        6 => Value::String(
            ["", "0.5", "NaN", "../x", "/dev/zero", "Sphere", "\u{feff}"][rng.random_range(0..7)]
                .to_owned(),
        ),
        7 => Value::Null,
        8 => serde_json::json!([]),
        _ => serde_json::json!({}),
    }
}

/// Paths to every node of `v` (object keys and array indices).
fn node_paths(v: &Value, prefix: &mut Vec<Value>, out: &mut Vec<Vec<Value>>) {
    out.push(prefix.clone());
    match v {
        Value::Object(m) => {
            for (k, child) in m {
                prefix.push(Value::String(k.clone()));
                node_paths(child, prefix, out);
                prefix.pop();
            }
        }
        Value::Array(a) => {
            for (i, child) in a.iter().enumerate() {
                prefix.push(serde_json::json!(i));
                node_paths(child, prefix, out);
                prefix.pop();
            }
        }
        _ => {}
    }
}

fn node_mut<'a>(v: &'a mut Value, path: &[Value]) -> Option<&'a mut Value> {
    let mut cur = v;
    for step in path {
        cur = match step {
            Value::String(k) => cur.get_mut(k.as_str())?,
            Value::Number(i) => cur.get_mut(i.as_u64()? as usize)?,
            _ => return None,
        };
    }
    Some(cur)
}

/// One structural mutation of a scene: replace a node, delete an object key, duplicate an array
/// element, or scale a number.
fn mutate_value(v: &mut Value, rng: &mut impl Rng) {
    let mut paths = Vec::new();
    node_paths(v, &mut Vec::new(), &mut paths);
    // Most mutations keep the schema and change a number: those get past the parser and test
    // validation and the renderer; the rest change the structure.
    let numbers: Vec<&Vec<Value>> = paths
        .iter()
        .filter(|p| node_mut(&mut v.clone(), p).is_some_and(|n| n.is_number()))
        .collect();
    if !numbers.is_empty() && rng.random_range(0..10) < 7 {
        let path = numbers[rng.random_range(0..numbers.len())].clone();
        let x = match extreme(rng) {
            Value::Number(n) => Value::Number(n),
            _ => serde_json::json!(
                rng.random_range(-4.0..4.0) * 10f64.powi(rng.random_range(-40..40))
            ),
        };
        if let Some(node) = node_mut(v, &path) {
            *node = x;
        }
        return;
    }
    let path = &paths[rng.random_range(0..paths.len())];
    let replacement = extreme(rng);
    let choice = rng.random_range(0..4);
    let Some(node) = node_mut(v, path) else { return };
    match (choice, node) {
        (1, Value::Object(m)) if !m.is_empty() => {
            let key = m.keys().nth(rng.random_range(0..m.len())).cloned().unwrap_or_default();
            m.remove(&key);
        }
        (2, Value::Array(a)) if !a.is_empty() => {
            let e = a[rng.random_range(0..a.len())].clone();
            a.push(e);
        }
        (3, Value::Number(n)) => {
            let x =
                n.as_f64().unwrap_or(1.0) * [1e-300, -1.0, 1e300, 1e9, 0.0][rng.random_range(0..5)];
            *node_mut(v, path).unwrap() = serde_json::json!(x);
        }
        (_, node) => *node = replacement,
    }
}

/// One byte-level mutation: flip, insert, delete, overwrite with a varint marker, or truncate.
fn mutate_bytes(b: &mut Vec<u8>, rng: &mut impl Rng) {
    if b.is_empty() {
        b.push(rng.random());
        return;
    }
    let i = rng.random_range(0..b.len());
    match rng.random_range(0..6) {
        0 => b[i] ^= 1 << rng.random_range(0..8),
        1 => b.insert(i, rng.random()),
        2 => {
            b.remove(i);
        }
        3 => b[i] = [251, 252, 253, 254, 255, 0][rng.random_range(0..6)],
        4 => b.truncate(i),
        _ => {
            let j = rng.random_range(0..b.len());
            b[i] = b[j];
        }
    }
}

fn shipped_scenes() -> Vec<String> {
    let mut paths: Vec<PathBuf> = std::fs::read_dir(workspace().join("scenes"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "json"))
        .collect();
    paths.sort();
    paths.iter().map(|p| std::fs::read_to_string(p).unwrap()).collect()
}

fn corpus(kind: &str) -> Vec<(PathBuf, Vec<u8>)> {
    let dir = workspace().join("tests/fuzz-corpus").join(kind);
    // A missing folder is an empty corpus (git does not keep empty folders).
    let mut files: Vec<PathBuf> =
        std::fs::read_dir(&dir).map(|r| r.map(|e| e.unwrap().path()).collect()).unwrap_or_default();
    files.sort();
    files
        .into_iter()
        .filter(|p| p.file_name().is_some_and(|n| n != "README.md"))
        .map(|p| {
            let bytes = std::fs::read(&p).unwrap();
            (p, bytes)
        })
        .collect()
}

fn report(failures: Vec<String>) {
    assert!(failures.is_empty(), "{} failing cases; first:\n{}", failures.len(), failures[0]);
}

#[test]
fn fuzz_scene_files() {
    let mut failures = Vec::new();
    // Every crash ever found, first.
    for (path, bytes) in corpus("scenes") {
        let text = String::from_utf8_lossy(&bytes).into_owned();
        failures
            .extend(guarded(&path.display().to_string(), &bytes, || exercise_scene(&text)).err());
    }
    let scenes: Vec<Value> =
        shipped_scenes().iter().map(|s| serde_json::from_str(s).unwrap()).collect();
    let cases = env_or("SPECTRACE_FUZZ_CASES", 150);
    let mut rng = Pcg64::seed_from_u64(env_or("SPECTRACE_FUZZ_SEED", 1));
    let mut reached = Vec::new();
    for case in 0..cases {
        let mut v = scenes[rng.random_range(0..scenes.len())].clone();
        // Keep renders small: a mutant of a shipped scene renders at most 64x64.
        if let Some(cam) = v.get_mut("camera").and_then(Value::as_object_mut) {
            cam.insert("width".to_owned(), serde_json::json!(48));
            cam.insert("height".to_owned(), serde_json::json!(32));
        }
        for _ in 0..rng.random_range(1..3) {
            mutate_value(&mut v, &mut rng);
        }
        let mut text = serde_json::to_string_pretty(&v).unwrap();
        if rng.random_range(0..4) == 0 {
            let mut bytes = text.into_bytes();
            mutate_bytes(&mut bytes, &mut rng);
            text = String::from_utf8_lossy(&bytes).into_owned();
        }
        let what = format!("scene case {case}");
        if std::env::var_os("SPECTRACE_FUZZ_TRACE").is_some() {
            eprintln!("{what}: {}", text.replace('\n', " "));
        }
        match guarded(&what, text.as_bytes(), || exercise_scene(&text)) {
            Ok(r) => reached.push(r),
            Err(f) => failures.push(f),
        }
    }
    report(failures);
    // A fuzzer whose mutants are all refused tests only the parser: most mutants must get
    // through loading, and many through a render.
    let count = |r: Reached| reached.iter().filter(|&&x| x == r).count();
    let (refused, loaded, rendered) =
        (count(Reached::Refused), count(Reached::Loaded), count(Reached::Rendered));
    eprintln!("scene mutants: {refused} refused, {loaded} loaded only, {rendered} rendered");
    assert!(rendered * 5 >= reached.len(), "only {rendered} of {} mutants rendered", reached.len());
    assert!(refused * 10 >= reached.len(), "only {refused} of {} mutants refused", reached.len());
}

#[test]
fn fuzz_part_files() {
    let mut failures = Vec::new();
    for (path, bytes) in corpus("parts") {
        failures
            .extend(guarded(&path.display().to_string(), &bytes, || exercise_part(&bytes)).err());
    }
    // A real part of a small render as the seed input.
    let dir = std::env::temp_dir().join(format!("spectrace-fuzz-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scene_path = dir.join("p.json");
    std::fs::write(
        &scene_path,
        r#"{"camera": {"position": [0, 3, 0.001], "look_at": [0, 0, 0], "up": [0, 0, -1], "fov": 60, "width": 8, "height": 6},
            "objects": [{"shape": {"type": "Rectangle", "corner": [-3, 0, 3], "edge_u": [6, 0, 0], "edge_v": [0, 0, -6]},
                         "material": {"type": "Diffuse", "reflectance": 0.5}}],
            "lights": [{"type": "PointLight", "position": [2.2, 1, 0.2], "power": 100,
                        "spd": {"type": "Uniform", "min_nm": 400, "max_nm": 700}}],
            "settings": {"chunk_beams": 500}}"#,
    )
    .unwrap();
    let scene = Scene::load(&scene_path).unwrap();
    let opts = RenderOptions {
        beams: Some(2000),
        threads: Some(1),
        shard: Some((0, 2)),
        out_dir: dir.clone(),
        ..RenderOptions::default()
    };
    let part_path =
        PathBuf::from(&spectrace_renderer::render_scene(&scene, &opts).unwrap().outputs[0]);
    let seed_bytes = std::fs::read(&part_path).unwrap();
    assert!(PartialFilm::decode(&seed_bytes).is_ok(), "the seed part must decode");
    let cases = env_or("SPECTRACE_FUZZ_CASES", 150) * 4;
    let mut rng = Pcg64::seed_from_u64(env_or("SPECTRACE_FUZZ_SEED", 1));
    for case in 0..cases {
        let mut bytes = seed_bytes.clone();
        for _ in 0..rng.random_range(1..5) {
            mutate_bytes(&mut bytes, &mut rng);
        }
        let what = format!("part case {case}");
        failures.extend(guarded(&what, &bytes, || exercise_part(&bytes)).err());
    }
    report(failures);
}

/// Mitsuba scene files from others go through the importer: mutants of our own Mitsuba scene and
/// of a scene of many features (an include, a PLY and a serialized mesh, every emitter and BSDF
/// the importer maps) are refused with an error or imported, loaded and rendered to finite
/// images; never a panic or a hang. One mutation a case: a byte (as for JSON scenes) or, twice
/// as often, an attribute value replaced by an extreme or an ordinary number.
#[test]
fn fuzz_mitsuba_files() {
    let dir = std::env::temp_dir().join(format!("spectrace-fuzz-xml-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("part.xml"), "<scene version=\"3.0.0\"><bsdf type=\"diffuse\" id=\"grey\"><rgb name=\"reflectance\" value=\"0.5\"/></bsdf></scene>").unwrap();
    std::fs::write(
        dir.join("tri.ply"),
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
         element face 1\nproperty list uchar int vertex_indices\nend_header\n-1 0 -1\n1 0 -1\n0 0 1\n3 0 1 2\n",
    )
    .unwrap();
    let cube = (
        vec![[-0.2, 0.0, -0.2], [0.2, 0.0, -0.2], [-0.2, 0.4, -0.2], [0.2, 0.4, -0.2]],
        vec![[0, 1, 3], [0, 3, 2]],
    );
    std::fs::write(dir.join("m.serialized"), spectrace_geometry::write_serialized(&[cube]))
        .unwrap();
    image::RgbImage::from_fn(3, 2, |x, y| image::Rgb([40 * x as u8, 90 * y as u8, 200]))
        .save(dir.join("t.png"))
        .unwrap();
    let many = r#"<scene version="3.0.0"><default name="w" value="24"/><include filename="part.xml"/>
  <integrator type="path"><integer name="max_depth" value="6"/></integrator>
  <sensor type="thinlens"><float name="fov" value="45"/><float name="aperture_radius" value="0.01"/><float name="focus_distance" value="3"/>
    <transform name="to_world"><lookat origin="0,1,3" target="0,0.3,0" up="0,1,0"/></transform>
    <film type="hdrfilm"><integer name="width" value="$w"/><integer name="height" value="16"/></film></sensor>
  <shape type="ply"><string name="filename" value="tri.ply"/><ref id="grey"/></shape>
  <shape type="serialized"><string name="filename" value="m.serialized"/><bsdf type="roughconductor"><string name="material" value="Cu"/><float name="alpha" value="0.2"/></bsdf></shape>
  <shape type="sphere"><point name="center" value="0.5,0.3,0"/><float name="radius" value="0.2"/><bsdf type="roughdielectric"><float name="alpha" value="0.1"/></bsdf></shape>
  <shape type="cube"><transform name="to_world"><scale value="0.1"/><translate x="-0.5" y="0.1"/></transform><bsdf type="plastic"><srgb name="diffuse_reflectance" value="0.2,0.6,0.3"/></bsdf></shape>
  <shape type="disk"><transform name="to_world"><rotate x="1" angle="90"/><translate y="2"/></transform><emitter type="area"><spectrum name="radiance" value="400:1, 700:3"/></emitter></shape>
  <emitter type="spot"><transform name="to_world"><lookat origin="1,2,1" target="0,0,0"/></transform><spectrum name="intensity" type="blackbody"><float name="temperature" value="3000"/></spectrum></emitter>
  <emitter type="point"><point name="position" value="-1,1,1"/><rgb name="intensity" value="2,1,0.5"/></emitter>
  <emitter type="directional"><vector name="direction" value="0,-1,-1"/><spectrum name="irradiance" type="d65"/></emitter>
  <emitter type="constant"><float name="radiance" value="0.1"/></emitter>
  <shape type="rectangle"><transform name="to_world"><rotate x="1" angle="-90"/><scale value="2"/></transform>
    <bsdf type="diffuse"><texture type="bitmap" name="reflectance"><string name="filename" value="t.png"/>
      <string name="wrap_mode" value="mirror"/><transform name="to_uv"><scale x="3" y="2"/></transform></texture></bsdf></shape>
</scene>"#;
    let own = std::fs::read_to_string(workspace().join("scenes/mitsuba/sky_plastic_gold.xml"))
        .unwrap()
        .replace("value=\"128\"", "value=\"24\"")
        .replace("value=\"96\"", "value=\"16\"");
    let textured = std::fs::read_to_string(workspace().join("scenes/mitsuba/textured.xml"))
        .unwrap()
        .replace("value=\"96\"", "value=\"24\"")
        .replace("value=\"72\"", "value=\"16\"");
    std::fs::copy(workspace().join("scenes/mitsuba/sky.exr"), dir.join("sky.exr")).unwrap();
    let envmap = std::fs::read_to_string(workspace().join("scenes/mitsuba/envmap.xml"))
        .unwrap()
        .replace("value=\"96\"", "value=\"24\"")
        .replace("value=\"72\"", "value=\"16\"");
    let seeds = [many.to_owned(), own, textured, envmap];
    let extremes = [
        "nan",
        "-1",
        "0",
        "1e308",
        "-1e-320",
        "",
        "1,2",
        "$undefined",
        "inf",
        "1e6",
        "0.5",
        "2",
        "3",
        "0.01",
        "1, 1, 1",
        "0, 0, 0",
        "100",
    ];
    let cases = env_or("SPECTRACE_FUZZ_CASES", 150);
    let mut rng = Pcg64::seed_from_u64(env_or("SPECTRACE_FUZZ_SEED", 1));
    let mut failures = Vec::new();
    let mut reached = Vec::new();
    for case in 0..cases {
        let mut text = seeds[rng.random_range(0..seeds.len())].clone();
        {
            let values: Vec<usize> = text.match_indices("value=\"").map(|(i, _)| i + 7).collect();
            if rng.random_range(0..3) != 0 && !values.is_empty() {
                let start = values[rng.random_range(0..values.len())];
                let end = start + text[start..].find('"').unwrap_or(0);
                text.replace_range(start..end, extremes[rng.random_range(0..extremes.len())]);
            } else {
                let mut bytes = text.into_bytes();
                mutate_bytes(&mut bytes, &mut rng);
                text = String::from_utf8_lossy(&bytes).into_owned();
            }
        }
        let path = dir.join("fuzz.xml");
        std::fs::write(&path, &text).unwrap();
        let what = format!("mitsuba case {case}");
        if std::env::var_os("SPECTRACE_FUZZ_TRACE").is_some() {
            eprintln!("{what}: {}", text.replace('\n', " "));
        }
        let outcome = guarded(&what, text.as_bytes(), || match Scene::load(&path) {
            Ok(scene) => exercise_loaded(&scene),
            Err(e) => {
                let e = e.to_string();
                assert!(
                    e.contains("fuzz.xml") || e.contains(".ply") || e.contains(".serialized"),
                    "an error without its file: {e}"
                );
                Reached::Refused
            }
        });
        match outcome {
            Ok(r) => reached.push(r),
            Err(f) => failures.push(f),
        }
    }
    report(failures);
    let rendered = reached.iter().filter(|&&r| r == Reached::Rendered).count();
    let refused = reached.iter().filter(|&&r| r == Reached::Refused).count();
    eprintln!("mitsuba mutants: {refused} refused, {rendered} rendered of {}", reached.len());
    // Most XML byte mutants are not well-formed, and most extreme values are refused: the
    // fuzzer must still get a tenth of its mutants through to a render.
    assert!(
        rendered * 10 >= reached.len() && refused * 10 >= reached.len(),
        "{refused} refused, {rendered} rendered"
    );
}
