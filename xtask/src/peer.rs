//! `cargo xtask peer`: the race against Mitsuba 3 (method and results in `docs/peer.md`), and
//! `cargo xtask peer --materials`: the materials cross-check (`docs/materials-peer.md`).
//!
//! The Rust side checks the prerequisites and prepares the tools; the race itself (scene
//! translation, renders, errors, report) is `xtask/peer/peer.py`, run in a virtual environment
//! under the target directory (`target/peer-venv`) that holds the pinned Mitsuba. Prerequisites,
//! each refused with a message saying what to install when missing: `python3` with its `venv`
//! module, `pip` inside the environment, and a shared libLLVM of major version 16 or newer (the
//! `llvm_ad_spectral` variant of Mitsuba compiles its kernels with it; Debian: `libllvm19`).

use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode, Stdio};

/// The Mitsuba release the race is pinned to (PyPI `mitsuba`; it pins its Dr.Jit).
pub(crate) const MITSUBA_VERSION: &str = "3.9.1";

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

/// Runs the race, or with `--materials` first the materials cross-check; the other `args` go to
/// `peer.py` (see `--help` there) or `materials.py`.
pub(crate) fn run(args: &[String]) -> ExitCode {
    let (job, args) = job(args);
    match prepare().and_then(|(python, llvm, binary)| race(&job, &python, &llvm, &binary, args)) {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("cargo xtask peer: {message}");
            ExitCode::FAILURE
        }
    }
}

/// What `cargo xtask peer` runs: its script in `xtask/peer` and its work folder in the target
/// directory.
#[derive(Debug, PartialEq, Eq)]
struct Job {
    script: &'static str,
    work: &'static str,
}

/// The race (`peer.py`, `target/peer`), or the materials cross-check (`materials.py`,
/// `target/peer-materials`) when the first argument is `--materials`; and the arguments left.
fn job(args: &[String]) -> (Job, &[String]) {
    match args.split_first() {
        Some((first, rest)) if first == "--materials" => {
            (Job { script: "materials.py", work: "peer-materials" }, rest)
        }
        _ => (Job { script: "peer.py", work: "peer" }, args),
    }
}

/// Checks the prerequisites and builds what the race needs: the virtual environment's python,
/// the libLLVM to use and the release `spectrace`.
fn prepare() -> Result<(PathBuf, PathBuf, PathBuf), String> {
    let llvm = find_llvm()?;
    eprintln!("libLLVM: {}", llvm.display());
    let python = venv()?;
    let binary = crate::build_spectrace().map_err(|_| "building spectrace failed".to_owned())?;
    Ok((python, llvm, binary))
}

/// Runs the job's script with the environment's python.
fn race(
    job: &Job,
    python: &Path,
    llvm: &Path,
    binary: &Path,
    args: &[String],
) -> Result<(), String> {
    let root = crate::workspace_root();
    let script = root.join("xtask").join("peer").join(job.script);
    let work = absolute(&crate::target_dir().join(job.work));
    let status = Command::new(python)
        .arg(&script)
        .arg("--spectrace")
        .arg(absolute(binary))
        .arg("--root")
        .arg(&root)
        .arg("--work")
        .arg(&work)
        .args(args)
        .env("DRJIT_LIBLLVM_PATH", llvm)
        .status()
        .map_err(|e| format!("could not run {}: {e}", python.display()))?;
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

/// The virtual environment's python, created under the target directory and given the pinned
/// Mitsuba (and numpy) on first use.
fn venv() -> Result<PathBuf, String> {
    let python3 = std::env::var("PYTHON").unwrap_or_else(|_| "python3".to_owned());
    match Command::new(&python3).arg("--version").stdout(Stdio::null()).status() {
        Ok(s) if s.success() => {}
        _ => {
            return Err(format!(
                "`{python3}` not found: the race needs Python 3 (3.8 or newer) with venv and \
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
    let check =
        format!("import mitsuba, numpy, sys; sys.exit(mitsuba.__version__ != '{MITSUBA_VERSION}')");
    let installed = Command::new(&python)
        .args(["-c", &check])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status();
    if !matches!(installed, Ok(s) if s.success()) {
        let pin = format!("mitsuba=={MITSUBA_VERSION}");
        eprintln!("$ {} -m pip install {pin} numpy", python.display());
        let ok = Command::new(&python).args(["-m", "pip", "install", &pin, "numpy"]).status();
        if !matches!(ok, Ok(s) if s.success()) {
            return Err(format!(
                "`pip install {pin} numpy` failed (it needs network access to PyPI, and a \
                 platform Mitsuba publishes wheels for)"
            ));
        }
    }
    Ok(python)
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]

    use super::{Job, find_llvm_in, job, llvm_major};

    #[test]
    fn materials_flag_selects_the_materials_script() {
        let args: Vec<String> = ["--materials", "--spp", "64"].map(String::from).to_vec();
        let (chosen, rest) = job(&args);
        assert_eq!(chosen, Job { script: "materials.py", work: "peer-materials" });
        assert_eq!(rest, &args[1..]);
        let race: Vec<String> = ["--scenes", "cornell", "--materials"].map(String::from).to_vec();
        let (chosen, rest) = job(&race);
        assert_eq!(chosen, Job { script: "peer.py", work: "peer" });
        assert_eq!(rest, &race[..]);
        assert_eq!(job(&[]).0.script, "peer.py");
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
