//! Files the renderer reads and writes, handled so that hostile or careless input cannot hurt.
//!
//! - Every file read goes through [`read_bounded`] (from `spectrace-sampling`, the lowest crate,
//!   through which OBJ meshes and measured luminaires are read the same way): it must be a regular file (not a device, FIFO or directory) no larger
//!   than a documented limit, checked before and while reading, so `/dev/zero` or a 100 GB file
//!   is refused at once instead of filling memory.
//! - Every output name is checked by [`check_output_name`] before any work starts: a plain file
//!   name, never a path, so nothing lands outside the output folder.
//! - [`check_no_input_replaced`] refuses, before rendering, any output that is the same file as an
//!   input (the scene, an OBJ mesh, a luminaire file, a part file), symlinks and hard links included.
//! - [`write_atomically`] writes each output to a temporary name in the output folder and renames
//!   it into place, so a failed write never leaves a partial file under the final name.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

pub use spectrace_sampling::files::read_bounded;

/// Largest scene file read (256 MiB): inline meshes of a few million triangles fit.
pub const MAX_SCENE_BYTES: u64 = 256 << 20;

/// Largest partial film read (2 GiB): the largest film (2^25 pixels) takes at most about 1.7 GB.
pub const MAX_PART_BYTES: u64 = 2 << 30;

/// Longest output base name in bytes: leaves room for the longest suffix
/// (`.part-K-of-N.bin` with 20-digit numbers) within the 255-byte file-name limit of common file
/// systems.
pub const MAX_OUTPUT_NAME_BYTES: usize = 200;

/// Checks an output base name: a plain, non-empty file name of at most
/// [`MAX_OUTPUT_NAME_BYTES`] bytes, with no directory separator, no NUL or other control
/// character, and not `.` or `..`.
///
/// # Errors
/// What is wrong with the name.
pub fn check_output_name(name: &str) -> Result<(), String> {
    let problem = if name.is_empty() {
        Some("is empty".to_owned())
    } else if name == "." || name == ".." {
        Some("names a directory".to_owned())
    } else if name.contains(['/', '\\']) {
        Some("contains a directory separator: outputs always go into the output folder".to_owned())
    } else if name.chars().any(char::is_control) {
        Some("contains a control character (NUL, newline, ...)".to_owned())
    } else if name.len() > MAX_OUTPUT_NAME_BYTES {
        Some(format!("is {} bytes long, more than {MAX_OUTPUT_NAME_BYTES}", name.len()))
    } else {
        None
    };
    match problem {
        Some(p) => Err(format!("{name:?} {p}; it must be a plain file name")),
        None => Ok(()),
    }
}

/// Prepares the output folder: creates it if needed and refuses a path that is not a directory.
///
/// # Errors
/// What is wrong, naming `--out`.
pub fn prepare_out_dir(dir: &Path) -> Result<(), String> {
    match std::fs::metadata(dir) {
        Ok(m) if m.is_dir() => Ok(()),
        Ok(_) => {
            Err(format!("--out {}: is a file, not a folder; outputs need a folder", dir.display()))
        }
        Err(_) => std::fs::create_dir_all(dir)
            .map_err(|e| format!("--out {}: cannot create the folder: {e}", dir.display())),
    }
}

/// Refuses any output that would replace one of `inputs` (the same file, through any path,
/// symlink or hard link), or that is an existing directory.
///
/// # Errors
/// A message naming the output and the input it would replace.
pub fn check_no_input_replaced(outputs: &[PathBuf], inputs: &[PathBuf]) -> Result<(), String> {
    for out in outputs {
        // An output that does not exist yet cannot be an input (inputs were read, so they exist).
        let Ok(meta) = std::fs::metadata(out) else { continue };
        if meta.is_dir() {
            return Err(format!("output {} is an existing folder", out.display()));
        }
        for input in inputs {
            if same_file(out, input) {
                return Err(format!(
                    "output {} would replace the input {}: choose another --out folder or \
                     output name",
                    out.display(),
                    input.display()
                ));
            }
        }
    }
    Ok(())
}

/// Whether two paths name the same file (same device and inode on Unix; same canonical path
/// elsewhere).
pub fn same_file(a: &Path, b: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        if let (Ok(x), Ok(y)) = (std::fs::metadata(a), std::fs::metadata(b)) {
            return x.dev() == y.dev() && x.ino() == y.ino();
        }
    }
    match (std::fs::canonicalize(a), std::fs::canonicalize(b)) {
        (Ok(x), Ok(y)) => x == y,
        _ => false,
    }
}

/// Writes `path` by calling `write` on a new temporary file in the same folder (it may replace
/// that file) and renaming it into place: readers never see a half-written file, and a failed write leaves nothing behind.
///
/// # Errors
/// The error of `write`, or of the rename.
pub fn write_atomically(
    path: &Path,
    write: impl FnOnce(&Path) -> Result<(), String>,
) -> Result<(), String> {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    // The temporary name is reserved with `create_new`, so an existing file of that name (however
    // unlikely) is never truncated or removed.
    let mut reserved = None;
    for _ in 0..100 {
        let temp = path.with_file_name(format!(
            ".{name}.tmp-{}-{}",
            std::process::id(),
            COUNTER.fetch_add(1, Ordering::Relaxed)
        ));
        match std::fs::OpenOptions::new().write(true).create_new(true).open(&temp) {
            Ok(_) => {
                reserved = Some(temp);
                break;
            }
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {}
            Err(e) => return Err(format!("cannot create a temporary file beside it: {e}")),
        }
    }
    let Some(temp) = reserved else {
        return Err("cannot find a free temporary name beside it".to_owned());
    };
    let result = write(&temp).and_then(|()| {
        std::fs::rename(&temp, path)
            .map_err(|e| format!("cannot move the finished file into place: {e}"))
    });
    if result.is_err() {
        let _ = std::fs::remove_file(&temp);
    }
    result
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    fn temp(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("spectrace-files-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn output_names_are_plain_file_names() {
        assert!(check_output_name("image").is_ok());
        assert!(check_output_name("ünïcode name").is_ok());
        for bad in ["", ".", "..", "../x", "/abs/path", "a\\b", "nul\0byte", "new\nline"] {
            assert!(check_output_name(bad).is_err(), "{bad:?} accepted");
        }
        assert!(check_output_name(&"x".repeat(200)).is_ok());
        let e = check_output_name(&"x".repeat(300)).unwrap_err();
        assert!(e.contains("300 bytes"), "{e}");
    }

    #[test]
    fn outputs_never_replace_inputs() {
        let d = temp("replace");
        let scene = d.join("s.json");
        std::fs::write(&scene, "{}").unwrap();
        let other = d.join("other.json");
        assert!(
            check_no_input_replaced(std::slice::from_ref(&other), std::slice::from_ref(&scene))
                .is_ok()
        );
        // The same file through another spelling of its path.
        let spelled = d.join(".").join("s.json");
        let e = check_no_input_replaced(&[spelled], std::slice::from_ref(&scene)).unwrap_err();
        assert!(e.contains("would replace the input"), "{e}");
        #[cfg(unix)]
        {
            let link = d.join("link.json");
            std::fs::hard_link(&scene, &link).unwrap();
            assert!(check_no_input_replaced(&[link], std::slice::from_ref(&scene)).is_err());
        }
        assert!(
            check_no_input_replaced(std::slice::from_ref(&d), &[]).unwrap_err().contains("folder")
        );
    }

    #[test]
    fn failed_writes_leave_nothing_behind() {
        let d = temp("atomic");
        let target = d.join("out.exr");
        let e = write_atomically(&target, |p| {
            std::fs::write(p, b"partial").unwrap();
            Err("disk full".to_owned())
        });
        assert_eq!(e.unwrap_err(), "disk full");
        assert_eq!(std::fs::read_dir(&d).unwrap().count(), 0, "temporary file left behind");
        write_atomically(&target, |p| std::fs::write(p, b"done").map_err(|e| e.to_string()))
            .unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"done");
        assert_eq!(std::fs::read_dir(&d).unwrap().count(), 1);
    }

    #[test]
    fn an_out_path_that_is_a_file_is_refused() {
        let d = temp("outfile");
        let f = d.join("file");
        std::fs::write(&f, b"x").unwrap();
        let e = prepare_out_dir(&f).unwrap_err();
        assert!(e.contains("is a file, not a folder"), "{e}");
        assert!(prepare_out_dir(&d.join("new/nested")).is_ok());
    }
}
