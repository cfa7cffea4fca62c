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
