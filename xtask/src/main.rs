//! Spectrace's project automation, run as `cargo xtask <command>` (a cargo alias in
//! `.cargo/config.toml`). It has no dependencies and one function per subcommand; rendering
//! commands build the `spectrace` binary (the accuracy report: `spectrace-lab`) in release mode
//! and run it.
//!
//! Commands today:
//! - `cargo xtask` / `cargo xtask status`: what Spectrace contains so far and how to use it.
//! - `cargo xtask bench`: runs every crate's benchmarks (sampling, spectrum, lights, geometry) in
//!   release mode.
//! - `cargo xtask callgrind [BINARY [OUTFILE]]`: instructions per work item of every estimator,
//!   counted by callgrind (`xtask/scripts/callgrind.sh`): the cost measure of refactors.
//! - `cargo xtask budget [BUDGET]`: how closely the path tracer and BDPT keep a `--time` budget
//!   when one pass takes longer (`xtask/scripts/time-budget.sh`, the Cornell box at 1600 x 1600).
//! - `cargo xtask cluster-test [SCENE]`: a real single-node Slurm (slurmctld and slurmd on
//!   localhost, with munge) runs `docs/cluster`'s array of 8 render shards and its dependent merge
//!   (`xtask/scripts/cluster-test.sh`), then compares the merged outputs with one process's, byte
//!   for byte. Needs root and Debian's `slurm-wlm` and `munge`. Never run by CI.
//! - `cargo xtask ci`: runs `.ci/run` itself (rustfmt, clippy, the tests, the fuzz run, the
//!   status page), so the two can never differ.
//! - `cargo xtask render [SCENE] [options]`: builds the renderer in release mode and renders a
//!   scene (default `scenes/showcase.json`); options go to `spectrace render`.
//! - `cargo xtask estimate SCENE --target-error E [options]`: predicts the render time to E for
//!   each estimator from short pilots (`spectrace estimate`).
//! - `cargo xtask accuracy [SCENES] [options]`: the error-against-time report, `docs/accuracy.md`:
//!   builds `spectrace-lab` in release mode and runs `spectrace-lab accuracy` from the workspace
//!   root.
//! - `cargo xtask fuzz [--cases N] [--seed S]`: a longer run of the scene and part-file fuzzer
//!   (`tests/tests/fuzz.rs`) in release mode.
//! - `cargo xtask peer [options]`: the race against Mitsuba 3 (`docs/peer.md`): builds a Python
//!   virtual environment under the target directory with a pinned Mitsuba, then runs
//!   `xtask/peer/peer.py`: times to 10% and 5%, then samples per second at equal spp beside
//!   Mitsuba's `llvm_ad_spectral` and `scalar_spectral` variants (`--throughput-only`: only
//!   those, about a minute). Needs python3 with venv and pip, network access for the first
//!   install, and a libLLVM of version 16 or newer. Never run by CI.
//! - `cargo xtask peer --materials [options]`: the materials cross-check against Mitsuba 3
//!   (`docs/materials-peer.md`, `xtask/peer/materials.py`), with the same prerequisites.
//! - `cargo xtask peer --geometry [--rays N] [--reps K] [--cpu C] [--no-docs]`: the geometry
//!   benchmark beside Embree 4 (`docs/peer.md`, `xtask/peer/geometry.py`): closest-hit and shadow
//!   rays/s of Spectrace and of Embree (`embreex`, pinned, in the same virtual environment) on the
//!   same mesh and rays, both on one pinned core, and their ratio. Needs python3 with venv and pip
//!   and network access for the first install; no libLLVM. Never run by CI.

use std::process::{Command, ExitCode};

mod peer;

/// One workspace crate as the status page lists it.
struct CrateInfo {
    package: &'static str,
    path: &'static str,
    what: &'static str,
}

/// The crates that exist today, bottom layer first.
const CRATES: &[CrateInfo] = &[
    CrateInfo {
        package: "spectrace-sampling",
        path: "crates/sampling",
        what: "exact inverse-CDF generators: Discrete, AliasTable, PiecewiseConstant, PiecewiseLinear",
    },
    CrateInfo {
        package: "spectrace-spectrum",
        path: "crates/spectrum",
        what: "SPDs (tabulated, binned, blackbody, Gaussian, monochromatic, uniform, mixture, CIE \
               illuminants), reflectance spectra, CIE 1931 XYZ and sRGB",
    },
    CrateInfo {
        package: "spectrace-lights",
        path: "crates/lights",
        what: "LightSource trait, Beam, Laser, Sky, uniform/fading spots, point, rectangle and disk \
               lights, LightSet; third-party lights by typetag",
    },
    CrateInfo {
        package: "spectrace-geometry",
        path: "crates/geometry",
        what: "rays, shapes (mesh/OBJ, sphere, rectangle, disk, cylinder, torus, prism), transforms, \
               obvhs BVH, robust intersection",
    },
    CrateInfo {
        package: "spectrace-materials",
        path: "crates/materials",
        what: "diffuse, mirror, dispersive dielectric (Sellmeier, Cauchy, tables, glass catalog)",
    },
    CrateInfo {
        package: "spectrace-tracer",
        path: "crates/tracer",
        what: "camera (pinhole, thin lens), exact XYZ film, light tracer, path tracer, BDPT, effects analysis",
    },
    CrateInfo {
        package: "spectrace-renderer",
        path: "crates/renderer",
        what: "scene files, EXR/PNG/JSON outputs, sharding and merge, estimator bench; `spectrace`",
    },
    CrateInfo {
        package: "spectrace-lab",
        path: "crates/lab",
        what: "experiment harness: the accuracy report (error against time for every knob, plots); \
               `spectrace-lab`",
    },
];

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let command = args.first().map(String::as_str).unwrap_or("status");
    match command {
        "status" => status(),
        "bench" => run_all(&[
            &["bench", "-p", "spectrace-sampling"],
            &["bench", "-p", "spectrace-spectrum"],
            &["bench", "-p", "spectrace-lights"],
            &["bench", "-p", "spectrace-geometry"],
        ]),
        "ci" => ci(),
        "callgrind" => callgrind(&args[1..]),
        "budget" => budget(&args[1..]),
        "cluster-test" => cluster_test(&args[1..]),
        "help" | "-h" | "--help" => {
            print_help();
            ExitCode::SUCCESS
        }
        "render" => render(&args[1..]),
        "estimate" => estimate(&args[1..]),
        "accuracy" => accuracy(&args[1..]),
        "fuzz" => fuzz(&args[1..]),
        "peer" => peer::run(&args[1..]),
        other => {
            eprintln!("unknown command `{other}`\n");
            print_help();
            ExitCode::from(2)
        }
    }
}

/// The default scene of `cargo xtask render`, relative to the workspace root.
const SHOWCASE: &str = "scenes/showcase.json";

/// The workspace root (the xtask crate's parent directory), so the commands work from any
/// directory of the workspace.
fn workspace_root() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .map_or_else(|| ".".into(), |p| p.to_path_buf())
}

/// `cargo xtask estimate SCENE --target-error E [options]`: builds the renderer in release mode
/// and predicts the time to E per estimator from short pilots (`spectrace estimate`).
fn estimate(args: &[String]) -> ExitCode {
    let mut command: Vec<String> = vec!["estimate".into()];
    command.extend(args.iter().cloned());
    run_spectrace(&command)
}

/// `cargo xtask render [SCENE] [options]`: builds the renderer in release mode and renders the
/// scene (the showcase scene by default); options pass through to `spectrace render`.
fn render(args: &[String]) -> ExitCode {
    let (scene, rest) = match args.first() {
        Some(first) if !first.starts_with('-') => (first.clone(), &args[1..]),
        _ => (workspace_root().join(SHOWCASE).display().to_string(), args),
    };
    let mut command: Vec<String> = vec!["render".into(), scene];
    command.extend(rest.iter().cloned());
    run_spectrace(&command)
}

/// `cargo xtask accuracy [SCENES] [options]`: the error-against-time report (docs/accuracy.md):
/// builds `spectrace-lab` in release mode and runs `spectrace-lab accuracy` from the workspace
/// root (scene paths are relative to it).
fn accuracy(args: &[String]) -> ExitCode {
    let mut command: Vec<String> = vec!["accuracy".into()];
    command.extend(args.iter().cloned());
    run_binary_in(LAB, &command, Some(&workspace_root()))
}

/// A binary of the workspace that the xtask builds and runs: its package and name, and whether
/// it is an example (`cargo build --example`) rather than a binary target.
struct Binary {
    package: &'static str,
    name: &'static str,
    example: bool,
}

/// The renderer's command line.
const SPECTRACE: Binary =
    Binary { package: "spectrace-renderer", name: "spectrace", example: false };

/// The experiment harness's command line (the accuracy report).
const LAB: Binary = Binary { package: "spectrace-lab", name: "spectrace-lab", example: false };

/// `cargo xtask fuzz [--cases N] [--seed S]`: the fuzz tests with N mutants per target (default
/// 5000) from seed S (default: the time), in release mode.
fn fuzz(args: &[String]) -> ExitCode {
    let mut cases = "5000".to_owned();
    let mut seed = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(1, |d| d.as_secs())
        .to_string();
    let mut it = args.iter();
    while let Some(a) = it.next() {
        let value = it.next().filter(|v| v.parse::<u64>().is_ok());
        match (a.as_str(), value) {
            ("--cases", Some(v)) => cases = v.clone(),
            ("--seed", Some(v)) => seed = v.clone(),
            _ => {
                eprintln!("usage: cargo xtask fuzz [--cases N] [--seed S] (whole numbers)");
                return ExitCode::from(2);
            }
        }
    }
    eprintln!("fuzzing with {cases} cases per target, seed {seed}");
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_owned());
    let status = Command::new(&cargo)
        .args(["test", "--release", "-p", "spectrace-tests", "fuzz::", "--", "--nocapture"])
        .env("SPECTRACE_FUZZ_CASES", &cases)
        .env("SPECTRACE_FUZZ_SEED", &seed)
        .current_dir(workspace_root())
        .status();
    match status {
        Ok(s) if s.success() => ExitCode::SUCCESS,
        Ok(_) => {
            eprintln!("the fuzzer found a failure: rerun with --seed {seed} to reproduce it");
            ExitCode::FAILURE
        }
        Err(e) => {
            eprintln!("could not run cargo: {e}");
            ExitCode::FAILURE
        }
    }
}

/// Builds `spectrace` in release mode, then runs it with `args` in the current directory.
fn run_spectrace(args: &[String]) -> ExitCode {
    run_binary_in(SPECTRACE, args, None)
}

/// Builds `binary` in release mode, then runs it with `args` in `dir` (or here).
fn run_binary_in(binary: Binary, args: &[String], dir: Option<&std::path::Path>) -> ExitCode {
    let binary = match build_release(&binary) {
        Ok(binary) => binary,
        Err(code) => return code,
    };
    eprintln!("$ {} {}", binary.display(), args.join(" "));
    let mut command = Command::new(&binary);
    command.args(args);
    if let Some(dir) = dir {
        command.current_dir(dir);
    }
    match command.status() {
        Ok(s) if s.success() => ExitCode::SUCCESS,
        Ok(s) => ExitCode::from(s.code().unwrap_or(1).clamp(1, 255) as u8),
        Err(e) => {
            eprintln!("could not run {}: {e}", binary.display());
            ExitCode::FAILURE
        }
    }
}

/// The target directory: `CARGO_TARGET_DIR`, else `target` (relative to the current directory,
/// as cargo resolves it for `cargo xtask`, which runs from the workspace).
fn target_dir() -> std::path::PathBuf {
    std::env::var_os("CARGO_TARGET_DIR").map_or_else(|| "target".into(), Into::into)
}

/// Builds `spectrace` in release mode; its path, or the exit code of the failure (reported).
fn build_spectrace() -> Result<std::path::PathBuf, ExitCode> {
    build_release(&SPECTRACE)
}

/// Builds `binary` in release mode; its path, or the exit code of the failure (reported).
fn build_release(binary: &Binary) -> Result<std::path::PathBuf, ExitCode> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_owned());
    let kind = if binary.example { "--example" } else { "--bin" };
    let args = ["build", "--release", "-p", binary.package, kind, binary.name];
    eprintln!("$ cargo {}", args.join(" "));
    match Command::new(&cargo).args(args).status() {
        Ok(s) if s.success() => {}
        Ok(s) => {
            eprintln!("building {} failed ({s})", binary.name);
            return Err(ExitCode::FAILURE);
        }
        Err(e) => {
            eprintln!("could not run cargo: {e}");
            return Err(ExitCode::FAILURE);
        }
    }
    let dir = target_dir().join("release");
    let dir = if binary.example { dir.join("examples") } else { dir };
    Ok(dir.join(format!("{}{}", binary.name, std::env::consts::EXE_SUFFIX)))
}

fn print_help() {
    println!(
        "usage: cargo xtask [COMMAND]\n\n\
         commands:\n  \
         status   what Spectrace contains so far (default)\n  \
         render [SCENE] [--integrator auto|light|path|bdpt] [--beams N | --spp N | --time SECS]\n                  [--target-error E] [--out DIR] [--threads N] [--seed S] [--shard K/N]\n           \
                  build in release and render SCENE (default scenes/showcase.json)\n  \
         estimate SCENE --target-error E [--pilot-seconds S] [--integrators light,path,bdpt]\n           \
                  predict the render time to E for each estimator from short pilots\n  \
         accuracy [SCENES] [--max-width W] [--start-beams N] [--steps K] [--reference-beams N]\n           \
                  [--configurations A,B] [--out DIR]\n           \
                  error against time for every knob (docs/accuracy.md; runs spectrace-lab)\n  \
         fuzz [--cases N] [--seed S]  fuzz the scene and part-file loaders (release)\n  \
         peer [--scenes A,B] [--max-seconds S] [--reference-scale F] [--no-docs]\n           \
                  the race against Mitsuba 3 (docs/peer.md); needs python3, pip, libLLVM >= 16\n  \
         peer --throughput-only [--scenes A,B] [--throughput-spp N] [--throughput-reps K] [--no-docs]\n           \
                  only the race's samples/s at equal spp beside Mitsuba's llvm and scalar variants\n  \
         peer --materials [--spp N] [--seeds K] [--cases A,B] [--no-docs]\n           \
                  the materials cross-check against Mitsuba 3 (docs/materials-peer.md)\n  \
         peer --scene FILE.xml [--scene ...] [--spp N] [-D NAME=VALUE]\n           \
                  a Mitsuba scene rendered by Mitsuba 3 and Spectrace, region means compared (docs/import.md)\n  \
         peer --geometry [--rays N] [--reps K] [--cpu C] [--no-docs]\n           \
                  closest-hit and shadow rays/s beside Embree 4 on one core (docs/peer.md)\n  \
         bench    run every crate's benchmarks (release)\n  \
         ci       run .ci/run: rustfmt, clippy -D warnings, tests, fuzz, status\n  \
         callgrind [BINARY [OUT]]  instructions per work item of every estimator (valgrind)\n  \
         budget [SECONDS]  path and bdpt render time under --time when one pass takes longer\n  \
         help     this text"
    );
}

fn status() -> ExitCode {
    println!(
        "Spectrace: a spectral Monte Carlo renderer built around light sources as beam generators.\n"
    );
    println!("Crates in this workspace (bottom layer first):");
    for c in CRATES {
        println!("  {:<20} {:<17} {}", c.package, c.path, c.what);
    }
    println!(
        "\nRender the showcase scene:  cargo xtask render\n\
         Render any scene:           cargo xtask render scenes/NAME.json [--integrator auto|light|path|bdpt] [--beams N | --spp N | --time SECS | --target-error E] [--out DIR] [--threads N] [--seed S]\n\
         Predict the time to 5%:     cargo xtask estimate scenes/NAME.json --target-error 0.05\n\
         Accuracy against time:      cargo xtask accuracy [SCENES]\n\
         Race against Mitsuba 3:     cargo xtask peer (python3, pip, libLLVM >= 16; docs/peer.md)\n\
         Materials vs Mitsuba 3:     cargo xtask peer --materials (docs/materials-peer.md)\n\
         Run every test:             cargo test --workspace\n\
         Run the benchmarks:         cargo xtask bench\n\n\
         Estimators: light tracer, path tracer, BDPT (--integrator auto|light|path|bdpt; auto by default).\n\
         Materials: diffuse, mirror, glass, conductors (measured metals), rough glass, plastic, fluorescent.\n\
         Lighting design: IES and EULUMDAT luminaires, lumens and candela, illuminance sensors\n\
         (scenes/office.json writes workplane.csv/.exr/.png; scenes/README.md, \"sensors\")."
    );
    ExitCode::SUCCESS
}

/// Runs `cargo <args>` for each argument list in turn; stops at the first failure.
/// `cargo xtask callgrind [BINARY [OUTFILE]]`: instructions per work item of every estimator,
/// counted by callgrind (`xtask/scripts/callgrind.sh`), for `BINARY` (default: the `spectrace`
/// release build, built first) into `OUTFILE` (default `target/callgrind.md`).
fn callgrind(args: &[String]) -> ExitCode {
    let root = workspace_root();
    let binary = match args.first() {
        Some(b) => std::path::PathBuf::from(b),
        None => match build_release(&SPECTRACE) {
            Ok(b) => b,
            Err(code) => return code,
        },
    };
    let out =
        args.get(1).map_or_else(|| root.join("target/callgrind.md"), std::path::PathBuf::from);
    let script = root.join("xtask/scripts/callgrind.sh");
    eprintln!("$ bash {} {} {}", script.display(), binary.display(), out.display());
    match Command::new("bash").arg(&script).arg(&binary).arg(&out).status() {
        Ok(s) if s.success() => ExitCode::SUCCESS,
        Ok(s) => {
            eprintln!("the callgrind script failed ({s})");
            ExitCode::FAILURE
        }
        Err(e) => {
            eprintln!("could not run bash: {e}");
            ExitCode::FAILURE
        }
    }
}

/// `cargo xtask budget [BUDGET]`: the path tracer's and BDPT's render time under `--time BUDGET`
/// (default 1 s) on the Cornell box at 1600 x 1600, where one pass takes longer than the budget
/// (`xtask/scripts/time-budget.sh`, with the `spectrace` release build, built first).
fn budget(args: &[String]) -> ExitCode {
    let binary = match build_release(&SPECTRACE) {
        Ok(b) => b,
        Err(code) => return code,
    };
    let script = workspace_root().join("xtask/scripts/time-budget.sh");
    let budget = args.first().map_or("1", String::as_str);
    eprintln!("$ bash {} {} {budget}", script.display(), binary.display());
    match Command::new("bash").arg(&script).arg(&binary).arg(budget).status() {
        Ok(s) if s.success() => ExitCode::SUCCESS,
        Ok(s) => {
            eprintln!("the time-budget script failed ({s})");
            ExitCode::FAILURE
        }
        Err(e) => {
            eprintln!("could not run bash: {e}");
            ExitCode::FAILURE
        }
    }
}

/// `cargo xtask cluster-test [SCENE]`: `xtask/scripts/cluster-test.sh` with the release
/// `spectrace`: a real single-node Slurm run of `docs/cluster`'s recipes (an array of 8 shards
/// and a dependent merge), compared byte for byte with one process. Needs root and Debian's
/// `slurm-wlm` and `munge`; never run by CI.
fn cluster_test(args: &[String]) -> ExitCode {
    let binary = match build_release(&SPECTRACE) {
        Ok(b) => b,
        Err(code) => return code,
    };
    let script = workspace_root().join("xtask/scripts/cluster-test.sh");
    eprintln!("$ bash {} {} {}", script.display(), binary.display(), args.join(" "));
    match Command::new("bash").arg(&script).arg(&binary).args(args).status() {
        Ok(s) if s.success() => ExitCode::SUCCESS,
        Ok(s) => {
            eprintln!("the cluster test failed ({s})");
            ExitCode::FAILURE
        }
        Err(e) => {
            eprintln!("could not run bash: {e}");
            ExitCode::FAILURE
        }
    }
}

/// `cargo xtask ci`: `bash .ci/run` from the workspace root.
fn ci() -> ExitCode {
    let root = workspace_root();
    eprintln!("$ bash .ci/run");
    match Command::new("bash").arg(".ci/run").current_dir(&root).status() {
        Ok(s) if s.success() => ExitCode::SUCCESS,
        Ok(s) => {
            eprintln!("`.ci/run` failed ({s})");
            ExitCode::FAILURE
        }
        Err(e) => {
            eprintln!("could not run bash .ci/run: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run_all(commands: &[&[&str]]) -> ExitCode {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_owned());
    for args in commands {
        eprintln!("$ cargo {}", args.join(" "));
        match Command::new(&cargo).args(*args).status() {
            Ok(s) if s.success() => {}
            Ok(s) => {
                eprintln!("`cargo {}` failed ({s})", args.join(" "));
                return ExitCode::FAILURE;
            }
            Err(e) => {
                eprintln!("could not run cargo: {e}");
                return ExitCode::FAILURE;
            }
        }
    }
    ExitCode::SUCCESS
}
