//! The `spectrace` command line: bad numbers get messages that name the option and the cause.
#![allow(clippy::unwrap_used)]

use std::process::Command;

fn spectrace(args: &[&str]) -> (i32, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_spectrace")).args(args).output().unwrap();
    (out.status.code().unwrap_or(-1), String::from_utf8_lossy(&out.stderr).into_owned())
}

#[test]
fn negative_and_malformed_numbers_are_explained() {
    let cases = [
        (&["render", "x.json", "--beams", "-5"][..], "--beams", "whole number"),
        (&["render", "x.json", "--beams", "0"][..], "--beams", "at least 1"),
        (&["render", "x.json", "--beams", "1e6"][..], "--beams", "no sign, no decimals"),
        (&["render", "x.json", "--time", "-1"][..], "--time", "positive"),
        (&["render", "x.json", "--time", "inf"][..], "--time", "finite"),
        (&["render", "x.json", "--threads", "-2"][..], "--threads", "whole number of threads"),
        (&["render", "x.json", "--seed", "-3"][..], "--seed", "whole number"),
        (&["bench", "x.json", "--beams", "-1"][..], "--beams", "whole number"),
        (&["render", "x.json", "--kernel", "simd"][..], "--kernel", "batched or scalar"),
    ];
    for (args, option, cause) in cases {
        let (code, err) = spectrace(args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(err.contains(option) && err.contains(cause), "{args:?}: {err}");
        assert!(!err.contains("unexpected argument"), "{args:?}: {err}");
    }
}

#[test]
fn a_missing_scene_is_named() {
    let (code, err) = spectrace(&["render", "no-such-scene.json", "--out", "/nonexistent-dir-x"]);
    assert_eq!(code, 2);
    assert!(err.contains("no-such-scene.json"), "{err}");
}

/// A closed stdout and stderr (`spectrace render scene.json | head -1` closes stdout after a
/// line) lose the text, not the render: before, `println!` panicked with "failed printing to
/// stdout" and the exit code was 101.
#[test]
fn closed_output_streams_do_not_panic() {
    let scene = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/fading_spot.json");
    let dir = std::env::temp_dir().join(format!("spectrace-closed-pipe-{}", std::process::id()));
    let closed = || {
        let (reader, writer) = std::io::pipe().unwrap();
        drop(reader);
        writer
    };
    let out = Command::new(env!("CARGO_BIN_EXE_spectrace"))
        .args(["render", scene, "--beams", "20000", "--threads", "1", "--out"])
        .arg(&dir)
        .stdout(closed())
        .stderr(closed())
        .status()
        .unwrap();
    let written = dir.join("fading_spot.exr").is_file();
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(out.code(), Some(0), "{out}");
    assert!(written, "the image was not written");
}

/// The largest film the scene format allows, with 4 threads, under a 4 GB address-space limit
/// (`ulimit -v`): the memory plan sees the limit and either renders (without the error
/// estimate's moments, which do not fit) or refuses with the figures; never an abort
/// ("memory allocation of ... failed", exit 134), as before the plan read the limit.
#[test]
fn the_largest_film_under_an_address_space_limit_renders_or_is_refused_never_aborts() {
    let dir = std::env::temp_dir().join(format!("spectrace-ulimit-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let scene = r#"{"camera": {"position": [0, 1, 5], "look_at": [0, 0, 0], "fov": 40,
                               "width": 8192, "height": 4096},
      "objects": [{"shape": {"type": "Rectangle", "corner": [-5, 0, -5], "edge_u": [0, 0, 10],
                   "edge_v": [10, 0, 0]}, "material": {"type": "Diffuse", "reflectance": 0.5}}],
      "lights": [{"type": "PointLight", "position": [0, 2, 0], "power": 100,
                  "spd": {"type": "CieIlluminant", "name": "D65"}}],
      "output": {"png": false}}"#;
    std::fs::write(dir.join("big.json"), scene).unwrap();
    let script = format!(
        "ulimit -v 4000000 && exec {:?} render big.json --beams 20000 --threads 4 \
         --integrator light --quiet --out out",
        env!("CARGO_BIN_EXE_spectrace")
    );
    let out = Command::new("bash").arg("-c").arg(script).current_dir(&dir).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    let _ = std::fs::remove_dir_all(&dir);
    match out.status.code() {
        Some(0) => assert!(err.contains("no error estimate") && err.contains("ulimit -v"), "{err}"),
        Some(2) => assert!(err.contains("ulimit -v") && err.contains("needs"), "{err}"),
        other => panic!("exit {other:?}: {err}"),
    }
}
