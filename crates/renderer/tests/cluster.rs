//! The cluster recipes of `docs/cluster.md`, run as written: the Slurm batch scripts with the
//! environment Slurm gives an array's tasks, and the Kubernetes Jobs' commands with the index an
//! Indexed Job gives its pods. Each fan-out plus merge must give one process's bytes. No real
//! scheduler is started (CI has none).
#![allow(clippy::unwrap_used)]

use std::path::{Path, PathBuf};
use std::process::Command;

/// The folder of the recipes.
fn recipes() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/cluster")
}

/// A small scene with a sensor and an observer, so that every output a merge writes is compared.
const SCENE: &str = r#"{
  "camera": {"position": [0, 1.5, 4], "look_at": [0, 0.5, 0], "fov": 50, "width": 24, "height": 16},
  "objects": [{"shape": {"type": "Rectangle", "corner": [-5, 0, -5], "edge_u": [0, 0, 10],
               "edge_v": [10, 0, 0]}, "material": {"type": "Diffuse", "reflectance": 0.5}}],
  "lights": [{"type": "PointLight", "position": [0.3, 2.5, -0.5], "power": 100,
              "spd": {"type": "CieIlluminant", "name": "D65"}}],
  "sensors": [{"type": "IrradianceSensor", "name": "desk", "corner": [-1, 0.75, -1],
               "edge_u": [0, 0, 2], "edge_v": [2, 0, 0], "cells": [4, 4]}],
  "observers": [{"name": "eye", "position": [0, 1.2, 0], "view": [0, 0, -1]}],
  "settings": {"spp": 4, "sensor_spp": 9, "observer_spp": 50, "seed": 3}
}"#;

/// A fresh folder holding `scene.json`.
fn folder(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("spectrace-cluster-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    std::fs::write(d.join("scene.json"), SCENE).unwrap();
    d
}

/// `PATH` with the `spectrace` binary's folder first.
fn path_with_spectrace() -> std::ffi::OsString {
    let bin = Path::new(env!("CARGO_BIN_EXE_spectrace")).parent().unwrap().to_owned();
    let old = std::env::var_os("PATH").unwrap_or_default();
    std::env::join_paths(std::iter::once(bin).chain(std::env::split_paths(&old))).unwrap()
}

/// Runs `command` and asserts success, showing its output otherwise.
fn run(command: &mut Command) {
    let out = command.output().unwrap();
    assert!(
        out.status.success(),
        "{command:?}: {}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

/// One process's render of the scene in `dir` into `dir/whole`.
fn whole(dir: &Path) {
    run(Command::new(env!("CARGO_BIN_EXE_spectrace")).current_dir(dir).args([
        "render",
        "scene.json",
        "--threads",
        "2",
        "--quiet",
        "--out",
        "whole",
    ]));
}

/// The merged outputs in `merged` are one process's (`dir/whole`), byte for byte (the sidecar's
/// timings aside).
fn assert_same_bytes(dir: &Path, merged: &Path) {
    for file in ["scene.exr", "scene.png", "desk.csv", "desk.exr"] {
        let a = std::fs::read(dir.join("whole").join(file)).unwrap();
        let b = std::fs::read(merged.join(file)).unwrap();
        assert!(a == b, "{file} differs");
    }
    let sidecar = |d: &Path| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(d.join("scene.json")).unwrap()).unwrap()
    };
    let (a, b) = (sidecar(&dir.join("whole")), sidecar(merged));
    assert_eq!(a["sensors"][0]["average_lux"], b["sensors"][0]["average_lux"]);
    assert_eq!(a["observers"][0]["vertical"], b["observers"][0]["vertical"]);
    assert!(b["observers"][0]["vertical"]["lux"].as_f64().unwrap() > 0.0);
}

#[test]
fn the_slurm_scripts_render_eight_shards_and_merge_to_one_processs_bytes() {
    let dir = folder("slurm");
    for script in ["render.sbatch", "merge.sbatch"] {
        std::fs::copy(recipes().join(script), dir.join(script)).unwrap();
    }
    let array: (u64, u64) = (0, 7); // `#SBATCH --array=0-7`
    let text = std::fs::read_to_string(dir.join("render.sbatch")).unwrap();
    assert!(text.contains(&format!("#SBATCH --array={}-{}", array.0, array.1)), "{text}");
    for id in array.0..=array.1 {
        run(Command::new("bash")
            .arg("render.sbatch")
            .current_dir(&dir)
            .env("PATH", path_with_spectrace())
            .env("SCENE", "scene.json")
            .env("SLURM_ARRAY_TASK_ID", id.to_string())
            .env("SLURM_ARRAY_TASK_MIN", array.0.to_string())
            .env("SLURM_ARRAY_TASK_MAX", array.1.to_string())
            .env("SLURM_ARRAY_TASK_COUNT", (array.1 - array.0 + 1).to_string())
            .env("SLURM_CPUS_PER_TASK", "1"));
    }
    for k in 0..8 {
        assert!(dir.join(format!("parts/scene.part-{k}-of-8.bin")).is_file(), "part {k}");
    }
    run(Command::new("bash")
        .arg("merge.sbatch")
        .current_dir(&dir)
        .env("PATH", path_with_spectrace()));
    whole(&dir);
    assert_same_bytes(&dir, &dir.join("out"));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The JSON array after `command:` on each line that has one, in order.
fn commands(yaml: &str) -> Vec<Vec<String>> {
    yaml.lines()
        .filter_map(|l| l.trim().strip_prefix("command:"))
        .map(|c| serde_json::from_str(c.trim()).unwrap())
        .collect()
}

#[test]
fn the_kubernetes_jobs_render_their_indices_and_merge_to_one_processs_bytes() {
    let dir = folder("kubernetes");
    let yaml = std::fs::read_to_string(recipes().join("spectrace-job.yaml")).unwrap();
    let completions: u64 = yaml
        .lines()
        .find_map(|l| l.trim().strip_prefix("completions:"))
        .unwrap()
        .trim()
        .parse()
        .unwrap();
    let [render, merge] = <[Vec<String>; 2]>::try_from(commands(&yaml)).unwrap();
    // The pods mount the shared volume at /work; here it is the test's folder.
    let work = format!("{}/", dir.display());
    let mapped = |args: &[String]| -> Vec<String> {
        args.iter().map(|a| a.replace("/work/", &work)).collect()
    };
    let render = mapped(&render);
    assert_eq!(render[0], "spectrace");
    for index in 0..completions {
        run(Command::new(env!("CARGO_BIN_EXE_spectrace"))
            .args(&render[1..])
            .env("JOB_COMPLETION_INDEX", index.to_string()));
    }
    let merge = mapped(&merge);
    run(Command::new(&merge[0]).args(&merge[1..]).env("PATH", path_with_spectrace()));
    whole(&dir);
    assert_same_bytes(&dir, &dir.join("out"));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The page shows the recipes exactly as the tests run them.
#[test]
fn the_cluster_page_shows_the_tested_recipes_verbatim() {
    let page = std::fs::read_to_string(recipes().join("../cluster.md")).unwrap();
    for file in ["render.sbatch", "merge.sbatch", "submit.sh", "spectrace-job.yaml"] {
        let text = std::fs::read_to_string(recipes().join(file)).unwrap();
        assert!(page.contains(&text), "docs/cluster.md does not show {file} as it is");
    }
}

/// `--shard auto` with no scheduler, or disagreeing with `--shards`, is an error naming why.
#[test]
fn shard_auto_outside_a_job_array_is_refused() {
    let dir = folder("auto");
    let out = Command::new(env!("CARGO_BIN_EXE_spectrace"))
        .current_dir(&dir)
        .args(["render", "scene.json", "--shard", "auto", "--out", "parts"])
        .env_remove("SLURM_ARRAY_TASK_ID")
        .env_remove("JOB_COMPLETION_INDEX")
        .env_remove("AWS_BATCH_JOB_ARRAY_INDEX")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("no scheduler") && err.contains("SLURM_ARRAY_TASK_ID"), "{err}");
    let out = Command::new(env!("CARGO_BIN_EXE_spectrace"))
        .current_dir(&dir)
        .args(["render", "scene.json", "--shard", "auto", "--shards", "3", "--out", "parts"])
        .env("AWS_BATCH_JOB_ARRAY_INDEX", "1")
        .env("AWS_BATCH_JOB_ARRAY_SIZE", "4")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("--shards 3") && err.contains("4 tasks"), "{err}");
    assert!(!dir.join("parts").exists(), "nothing rendered");
    std::fs::remove_dir_all(&dir).unwrap();
}
