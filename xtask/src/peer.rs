//! `cargo xtask peer`: the race against Mitsuba 3 (method and results in `docs/peer.md`; with
//! `--throughput-only`, only its samples per second at equal spp, passed on to `peer.py`),
//! `cargo xtask peer --materials`: the materials cross-check (`docs/materials-peer.md`), and
//! `cargo xtask peer --geometry`: the geometry benchmark beside Embree 4 (`docs/peer.md`), and
//! `cargo xtask peer --scene FILE.xml`: one Mitsuba scene file rendered by Mitsuba 3 and by
//! Spectrace and compared in region means (`docs/import.md`, `xtask/peer/scene.py`).
//!
//! The Rust side checks the prerequisites and prepares the tools; the comparison itself (scene
//! translation, renders or ray casts, errors, report) is a Python script in `xtask/peer/`, run in a
//! virtual environment under the target directory (`target/peer-venv`) that holds the pinned
//! peers. Prerequisites, each refused with a message saying what to install when missing:
//! `python3` with its `venv` module, `pip` inside the environment, and, for Mitsuba only, a shared
//! libLLVM of major version 16 or newer (the `llvm_ad_spectral` variant of Mitsuba compiles its
//! kernels with it; Debian: `libllvm19`). The geometry comparison needs neither libLLVM nor
//! Mitsuba: only `embreex` (Embree 4's Python binding, with its own Embree) and numpy.

use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode, Stdio};

/// The Mitsuba release the race is pinned to (PyPI `mitsuba`; it pins its Dr.Jit).
pub(crate) const MITSUBA_VERSION: &str = "3.9.1";

/// The `embreex` release (PyPI; Embree 4's Python binding, which ships Embree) the geometry
/// comparison is pinned to.
pub(crate) const EMBREEX_VERSION: &str = "4.4.0.post1";

/// A Python package a peer's environment must hold: its PyPI (and import) name and the exact
/// version it is pinned to (`None`: any).
#[derive(Debug, PartialEq, Eq)]
struct Pin {
    name: &'static str,
    version: Option<&'static str>,
}

/// What the Mitsuba jobs (the race, the materials cross-check) install.
const MITSUBA_PINS: &[Pin] = &[
    Pin { name: "mitsuba", version: Some(MITSUBA_VERSION) },
    Pin { name: "numpy", version: None },
];

/// What the geometry comparison installs.
const EMBREE_PINS: &[Pin] = &[
    Pin { name: "embreex", version: Some(EMBREEX_VERSION) },
    Pin { name: "numpy", version: None },
];

/// The geometry comparison's Rust side: the release example that times Spectrace's ray casts and
/// dumps the mesh and rays for Embree.
const RAY_RATE: crate::Binary =
    crate::Binary { package: "spectrace-geometry", name: "ray_rate", example: true };

/// The oldest libLLVM major version Dr.Jit's LLVM backend accepts.
pub(crate) const MIN_LLVM: u32 = 16;

/// Folders searched for `libLLVM*.so*` when `DRJIT_LIBLLVM_PATH` is not set.
const LLVM_DIRS: &[&str] = &[
    "/usr/lib/x86_64-linux-gnu",
    "/usr/lib/aarch64-linux-gnu",
    "/usr/lib64",
    "/usr/lib",
    "/usr/local/lib",
];

/// Runs the race; with `--materials` first the materials cross-check, with `--geometry` first
/// the geometry comparison. The other `args` go to the job's script (`peer.py`, `materials.py`,
/// `geometry.py`; see `--help` there).
pub(crate) fn run(args: &[String]) -> ExitCode {
    let (job, args) = job(args);
    let result = match job.peer {
        Peer::Mitsuba => prepare().and_then(|(python, llvm, binary)| {
            let mut command = script(&job, &python, "--spectrace", &binary, args);
            finish(&job, command.env("DRJIT_LIBLLVM_PATH", llvm))
        }),
        Peer::MitsubaScalar => venv(MITSUBA_PINS).and_then(|python| {
            let binary =
                crate::build_spectrace().map_err(|_| "building spectrace failed".to_owned())?;
            finish(&job, &mut script(&job, &python, "--spectrace", &binary, args))
        }),
        Peer::Embree => prepare_geometry().and_then(|(python, example)| {
            finish(&job, &mut script(&job, &python, "--ray-rate", &example, args))
        }),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("cargo xtask peer: {message}");
            ExitCode::FAILURE
        }
    }
}

/// The engine a job compares Spectrace with.
#[derive(Debug, PartialEq, Eq, Clone, Copy)]
enum Peer {
    /// Mitsuba 3 (needs libLLVM and the release `spectrace`).
    Mitsuba,
    /// Embree 4 through `embreex` (needs the release `ray_rate` example only).
    Embree,
    /// Mitsuba 3's scalar variant only (no libLLVM needed): the scene-file comparison.
    MitsubaScalar,
}

/// What `cargo xtask peer` runs: its script in `xtask/peer`, its work folder in the target
/// directory, and the peer it needs.
#[derive(Debug, PartialEq, Eq)]
struct Job {
    script: &'static str,
    work: &'static str,
    peer: Peer,
}

/// The race (`peer.py`, `target/peer`); the materials cross-check (`materials.py`,
/// `target/peer-materials`) when the first argument is `--materials`; the geometry comparison
/// (`geometry.py`, `target/peer-geometry`) when it is `--geometry`; and the arguments left.
fn job(args: &[String]) -> (Job, &[String]) {
    match args.split_first() {
        Some((first, rest)) if first == "--materials" => {
            (Job { script: "materials.py", work: "peer-materials", peer: Peer::Mitsuba }, rest)
        }
        Some((first, _)) if first == "--scene" => {
            (Job { script: "scene.py", work: "peer-scene", peer: Peer::MitsubaScalar }, args)
        }
        Some((first, rest)) if first == "--geometry" => {
            (Job { script: "geometry.py", work: "peer-geometry", peer: Peer::Embree }, rest)
        }
        _ => (Job { script: "peer.py", work: "peer", peer: Peer::Mitsuba }, args),
    }
}

/// Checks the prerequisites and builds what the Mitsuba jobs need: the virtual environment's
/// python, the libLLVM to use and the release `spectrace`.
fn prepare() -> Result<(PathBuf, PathBuf, PathBuf), String> {
    let llvm = find_llvm()?;
    eprintln!("libLLVM: {}", llvm.display());
    let python = venv(MITSUBA_PINS)?;
    let binary = crate::build_spectrace().map_err(|_| "building spectrace failed".to_owned())?;
    Ok((python, llvm, binary))
}

/// Checks the prerequisites and builds what the geometry comparison needs: the virtual
/// environment's python (with `embreex`) and the release `ray_rate` example.
fn prepare_geometry() -> Result<(PathBuf, PathBuf), String> {
    let python = venv(EMBREE_PINS)?;
    let example =
        crate::build_release(&RAY_RATE).map_err(|_| "building the ray_rate example failed")?;
    Ok((python, example))
}

/// The job's script run by the environment's python, given `binary` (as `flag`), the workspace
/// root, its work folder, and then `args`.
fn script(job: &Job, python: &Path, flag: &str, binary: &Path, args: &[String]) -> Command {
    let root = crate::workspace_root();
    let mut command = Command::new(python);
    command
        .arg(root.join("xtask").join("peer").join(job.script))
        .arg(flag)
        .arg(absolute(binary))
        .arg("--root")
        .arg(&root)
        .arg("--work")
        .arg(absolute(&crate::target_dir().join(job.work)))
        .args(args);
    command
}

/// Runs the job's script; an error naming it when it cannot be started or fails.
fn finish(job: &Job, command: &mut Command) -> Result<(), String> {
    let status = command
        .status()
        .map_err(|e| format!("could not run {}: {e}", command.get_program().to_string_lossy()))?;
    if status.success() { Ok(()) } else { Err(format!("{} failed ({status})", job.script)) }
}

/// `path` made absolute against the current directory (unchanged if that cannot be read).
fn absolute(path: &Path) -> PathBuf {
    std::env::current_dir().map_or_else(|_| path.to_path_buf(), |d| d.join(path))
}

/// The libLLVM to use: `DRJIT_LIBLLVM_PATH` if set (it must exist, and be >= 16 when its name
/// shows a version), else the newest `libLLVM*.so*` of version >= 16 in the usual folders.
fn find_llvm() -> Result<PathBuf, String> {
    if let Some(path) = std::env::var_os("DRJIT_LIBLLVM_PATH") {
        let path = PathBuf::from(path);
        if !path.is_file() {
            return Err(format!("DRJIT_LIBLLVM_PATH={} is not a file", path.display()));
        }
        let name = path.file_name().and_then(|n| n.to_str()).unwrap_or_default();
        return match llvm_major(name) {
            Some(v) if v < MIN_LLVM => Err(format!(
                "DRJIT_LIBLLVM_PATH={} is libLLVM {v}; Mitsuba's llvm_ad_spectral variant needs \
                 {MIN_LLVM} or newer",
                path.display()
            )),
            _ => Ok(path),
        };
    }
    find_llvm_in(LLVM_DIRS)
}

/// The newest `libLLVM*.so*` of major version >= [`MIN_LLVM`] in `dirs`, or a message listing the
/// versions found and what to install.
fn find_llvm_in(dirs: &[&str]) -> Result<PathBuf, String> {
    let mut found: Vec<(u32, PathBuf)> = Vec::new();
    for dir in dirs {
        let Ok(entries) = std::fs::read_dir(dir) else { continue };
        for entry in entries.flatten() {
            let name = entry.file_name();
            if let Some(v) = name.to_str().and_then(llvm_major) {
                found.push((v, entry.path()));
            }
        }
    }
    found.sort();
    match found.iter().rev().find(|(v, _)| *v >= MIN_LLVM) {
        Some((_, path)) => Ok(path.clone()),
        None => {
            let seen: Vec<String> = found.iter().map(|(v, _)| v.to_string()).collect();
            Err(format!(
                "no libLLVM of version {MIN_LLVM} or newer found in {} (found: {}); Mitsuba's \
                 llvm_ad_spectral variant needs one: on Debian or Ubuntu `apt-get install \
                 libllvm19`, or set DRJIT_LIBLLVM_PATH to the library",
                dirs.join(", "),
                if seen.is_empty() { "none".to_owned() } else { seen.join(", ") }
            ))
        }
    }
}

/// The major version in a shared libLLVM's file name (`libLLVM-19.so`, `libLLVM.so.19.1`,
/// `libLLVM-14.0.6.so.1`); `None` for other names and for unversioned `libLLVM.so`.
pub(crate) fn llvm_major(name: &str) -> Option<u32> {
    let rest = name.strip_prefix("libLLVM")?;
    let version = if let Some(v) = rest.strip_prefix('-') {
        v.split(['.', '-']).next()?
    } else {
        let after = rest.strip_prefix(".so.")?;
        after.split('.').next()?
    };
    if !rest.contains(".so") {
        return None;
    }
    version.parse().ok()
}

/// The virtual environment's python, created under the target directory on first use and given
/// the `pins` it lacks (one environment serves every job: Mitsuba and `embreex` live side by side).
fn venv(pins: &[Pin]) -> Result<PathBuf, String> {
    let python3 = std::env::var("PYTHON").unwrap_or_else(|_| "python3".to_owned());
    match Command::new(&python3).arg("--version").stdout(Stdio::null()).status() {
        Ok(s) if s.success() => {}
        _ => {
            return Err(format!(
                "`{python3}` not found: `cargo xtask peer` needs Python 3 (3.8 or newer) with venv and \
                 pip, e.g. `apt-get install python3 python3-venv python3-pip` (or set PYTHON)"
            ));
        }
    }
    let dir = absolute(&crate::target_dir().join("peer-venv"));
    let python = dir.join("bin").join("python");
    if !python.is_file() {
        eprintln!("$ {python3} -m venv {}", dir.display());
        let ok = Command::new(&python3).args(["-m", "venv"]).arg(&dir).status();
        if !matches!(ok, Ok(s) if s.success()) || !python.is_file() {
            return Err(format!(
                "`{python3} -m venv {}` failed: install Python's venv module (Debian: \
                 `apt-get install python3-venv`)",
                dir.display()
            ));
        }
    }
    let pip = Command::new(&python).args(["-m", "pip", "--version"]).stdout(Stdio::null()).status();
    if !matches!(pip, Ok(s) if s.success()) {
        return Err(format!(
            "pip is missing in {}: install it (Debian: `apt-get install python3-pip \
             python3-venv`), then delete that folder and run again",
            dir.display()
        ));
    }
    let installed = Command::new(&python)
        .args(["-c", &install_check(pins)])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status();
    if !matches!(installed, Ok(s) if s.success()) {
        let specs = pip_specs(pins);
        eprintln!("$ {} -m pip install {}", python.display(), specs.join(" "));
        let ok = Command::new(&python).args(["-m", "pip", "install"]).args(&specs).status();
        if !matches!(ok, Ok(s) if s.success()) {
            return Err(format!(
                "`pip install {}` failed (it needs network access to PyPI, and a platform the \
                 packages publish wheels for)",
                specs.join(" ")
            ));
        }
    }
    Ok(python)
}

/// A Python program that exits with 0 only if every pinned package imports and has its pinned
/// version (as its installed distribution reports it).
fn install_check(pins: &[Pin]) -> String {
    let mut check = String::from("import importlib.metadata as m, sys\n");
    for pin in pins {
        check.push_str(&format!("import {}\n", pin.name));
        if let Some(version) = pin.version {
            check.push_str(&format!("if m.version('{}') != '{version}': sys.exit(1)\n", pin.name));
        }
    }
    check
}

/// The arguments of `pip install` for `pins` (`name==version`, or the bare name).
fn pip_specs(pins: &[Pin]) -> Vec<String> {
    pins.iter()
        .map(|p| p.version.map_or_else(|| p.name.to_owned(), |v| format!("{}=={v}", p.name)))
        .collect()
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]

    use super::{
        EMBREE_PINS, EMBREEX_VERSION, Job, MITSUBA_PINS, Peer, Pin, find_llvm_in, install_check,
        job, llvm_major, pip_specs,
    };

    #[test]
    fn materials_flag_selects_the_materials_script() {
        let args: Vec<String> = ["--materials", "--spp", "64"].map(String::from).to_vec();
        let (chosen, rest) = job(&args);
        let materials = Job { script: "materials.py", work: "peer-materials", peer: Peer::Mitsuba };
        assert_eq!(chosen, materials);
        assert_eq!(rest, &args[1..]);
        let race: Vec<String> = ["--scenes", "cornell", "--materials"].map(String::from).to_vec();
        let (chosen, rest) = job(&race);
        assert_eq!(chosen, Job { script: "peer.py", work: "peer", peer: Peer::Mitsuba });
        assert_eq!(rest, &race[..]);
        assert_eq!(job(&[]).0.script, "peer.py");
    }

    #[test]
    fn throughput_only_is_the_race_script_s_flag() {
        let args: Vec<String> =
            ["--throughput-only", "--scenes", "cornell"].map(String::from).to_vec();
        let (chosen, rest) = job(&args);
        assert_eq!(chosen, Job { script: "peer.py", work: "peer", peer: Peer::Mitsuba });
        assert_eq!(rest, &args[..]);
    }

    #[test]
    fn geometry_flag_selects_embree_and_the_geometry_script() {
        let args: Vec<String> = ["--geometry", "--rays", "1000"].map(String::from).to_vec();
        let (chosen, rest) = job(&args);
        assert_eq!(
            chosen,
            Job { script: "geometry.py", work: "peer-geometry", peer: Peer::Embree }
        );
        assert_eq!(rest, &args[1..]);
        // Only as the first argument: elsewhere it is the race's (which will refuse it).
        let race: Vec<String> = ["--no-docs", "--geometry"].map(String::from).to_vec();
        assert_eq!(job(&race).0.peer, Peer::Mitsuba);
    }

    #[test]
    fn pins_become_pip_specs_and_a_version_check() {
        assert_eq!(pip_specs(EMBREE_PINS), [format!("embreex=={EMBREEX_VERSION}"), "numpy".into()]);
        assert_eq!(pip_specs(MITSUBA_PINS)[1], "numpy");
        let check = install_check(&[
            Pin { name: "embreex", version: Some("4.4.0.post1") },
            Pin { name: "numpy", version: None },
        ]);
        assert_eq!(
            check,
            "import importlib.metadata as m, sys\nimport embreex\n\
             if m.version('embreex') != '4.4.0.post1': sys.exit(1)\nimport numpy\n"
        );
    }

    #[test]
    fn llvm_versions_are_read_from_file_names() {
        assert_eq!(llvm_major("libLLVM-19.so"), Some(19));
        assert_eq!(llvm_major("libLLVM.so.19.1"), Some(19));
        assert_eq!(llvm_major("libLLVM-14.0.6.so.1"), Some(14));
        assert_eq!(llvm_major("libLLVM-15.so.1"), Some(15));
        assert_eq!(llvm_major("libLLVM.so"), None);
        assert_eq!(llvm_major("libLLVMSupport.a"), None);
        assert_eq!(llvm_major("libLLVM-17.a"), None);
        assert_eq!(llvm_major("libclang-19.so"), None);
    }

    #[test]
    fn only_a_libllvm_of_version_16_or_newer_is_chosen() {
        let dir = std::env::temp_dir().join(format!("xtask-peer-llvm-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        for name in ["libLLVM-14.so.1", "libLLVM-15.so", "libLLVMSupport.a"] {
            std::fs::write(dir.join(name), b"").unwrap();
        }
        let dirs = [dir.to_str().unwrap()];
        let err = find_llvm_in(&dirs).unwrap_err();
        assert!(
            err.contains("found: 14, 15") && err.contains("apt-get install libllvm19"),
            "{err}"
        );
        std::fs::write(dir.join("libLLVM.so.19.1"), b"").unwrap();
        std::fs::write(dir.join("libLLVM-17.so"), b"").unwrap();
        assert_eq!(find_llvm_in(&dirs).unwrap(), dir.join("libLLVM.so.19.1"));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
