//! Bounded reading of input files, shared by every crate that reads one (OBJ meshes in the
//! geometry crate, measured luminaires in the lights crate, scene files and partial films in the
//! renderer): this is the lowest crate all of them depend on, though it samples nothing.
//!
//! [`read_bounded`] reads a regular file of at most a given size; [`check_inside`] refuses a file
//! that resolves outside a folder (`--restrict-paths`); [`with_scene_folder`] and
//! [`read_scene_input`] let a type that is deserialised from a scene file (a luminaire naming its
//! photometric file) resolve a path relative to the scene file, under the same policy, without
//! the scene reader knowing the type.

use std::cell::RefCell;
use std::io::Read;
use std::path::{Path, PathBuf};

/// `bytes` written for people: the largest unit that divides it exactly (`"1 GiB"`,
/// `"256 MiB"`), otherwise the largest unit below it with one decimal (`"1.5 KiB"`), or
/// `"100 bytes"`.
pub fn human_bytes(bytes: u64) -> String {
    const UNITS: [(u64, &str); 4] =
        [(1 << 40, "TiB"), (1 << 30, "GiB"), (1 << 20, "MiB"), (1 << 10, "KiB")];
    if let Some(&(unit, name)) =
        UNITS.iter().find(|&&(unit, _)| bytes >= unit && bytes.is_multiple_of(unit))
    {
        return format!("{} {name}", bytes / unit);
    }
    match UNITS.iter().find(|&&(unit, _)| bytes >= unit) {
        Some(&(unit, name)) => format!("{:.1} {name}", bytes as f64 / unit as f64),
        None => format!("{bytes} bytes"),
    }
}

/// Reads the whole of a regular file of at most `limit` bytes; `what` names it in messages
/// ("scene", "OBJ file", "partial film").
///
/// Devices, FIFOs and directories are refused before being opened (opening a FIFO would block,
/// reading `/dev/zero` never ends); the read goes through `take(limit + 1)`, so a file that grows
/// after the size check is refused too, and memory never exceeds the limit.
///
/// # Errors
/// Why, as text: cannot be read, not a regular file (and what it is), or larger than the limit.
pub fn read_bounded(path: &Path, limit: u64, what: &str) -> Result<Vec<u8>, String> {
    let cannot = |e: std::io::Error| format!("cannot read the {what}: {e}");
    let too_large = || format!("the {what} is larger than the {} limit", human_bytes(limit));
    let not_regular = |m: &std::fs::Metadata| {
        let kind = if m.is_dir() { "a directory" } else { "a device, FIFO or socket" };
        format!("cannot read the {what}: not a regular file ({kind})")
    };
    let meta = std::fs::metadata(path).map_err(cannot)?;
    if !meta.is_file() {
        return Err(not_regular(&meta));
    }
    if meta.len() > limit {
        return Err(too_large());
    }
    let file = std::fs::File::open(path).map_err(cannot)?;
    // The path may have been replaced between the check and the open.
    let meta = file.metadata().map_err(cannot)?;
    if !meta.is_file() {
        return Err(not_regular(&meta));
    }
    let mut bytes = Vec::with_capacity(meta.len().min(limit) as usize);
    file.take(limit.saturating_add(1)).read_to_end(&mut bytes).map_err(cannot)?;
    if bytes.len() as u64 > limit {
        return Err(too_large());
    }
    Ok(bytes)
}

/// Refuses `file` unless it resolves (symlinks followed) to a place inside the folder `base`
/// (an empty `base` is the current folder).
///
/// # Errors
/// Why, as text: either cannot be resolved, or where `file` really is.
pub fn check_inside(base: &Path, file: &Path) -> Result<(), String> {
    let base_dir = if base.as_os_str().is_empty() { Path::new(".") } else { base };
    let root = std::fs::canonicalize(base_dir)
        .map_err(|e| format!("cannot resolve the scene's folder {}: {e}", base_dir.display()))?;
    let real = std::fs::canonicalize(file)
        .map_err(|e| format!("{}: cannot resolve: {e}", file.display()))?;
    if real.starts_with(&root) {
        Ok(())
    } else {
        Err(format!(
            "{} resolves to {}, outside the scene's folder {} (refused by --restrict-paths)",
            file.display(),
            real.display(),
            root.display()
        ))
    }
}

/// The folder a scene file is read from, while it is being deserialised on this thread.
struct SceneFolder {
    base: PathBuf,
    restrict: bool,
    read: Vec<PathBuf>,
}

thread_local! {
    static SCENE_FOLDER: RefCell<Vec<SceneFolder>> = const { RefCell::new(Vec::new()) };
}

/// Runs `f` (the deserialisation of a scene) with `base` as the folder that relative input
/// paths named inside it resolve against, and with `restrict` refusing files outside it; returns
/// `f`'s result and every file [`read_scene_input`] read meanwhile (so the caller can keep its
/// outputs from replacing them). Calls nest; the folder applies to this thread only.
pub fn with_scene_folder<R>(
    base: &Path,
    restrict: bool,
    f: impl FnOnce() -> R,
) -> (R, Vec<PathBuf>) {
    SCENE_FOLDER.with(|s| {
        s.borrow_mut().push(SceneFolder { base: base.to_owned(), restrict, read: Vec::new() });
    });
    // Pop the folder even if `f` unwinds, so a later scene never sees this one's folder.
    struct Pop;
    impl Drop for Pop {
        fn drop(&mut self) {
            SCENE_FOLDER.with(|s| {
                s.borrow_mut().pop();
            });
        }
    }
    let pop = Pop;
    let result = f();
    let read = SCENE_FOLDER
        .with(|s| s.borrow_mut().last_mut().map(|f| std::mem::take(&mut f.read)))
        .unwrap_or_default();
    drop(pop);
    (result, read)
}

/// Reads an input file named in a scene file as UTF-8 text of at most `limit` bytes: `name`
/// relative to the folder of [`with_scene_folder`] (the current folder outside one), refused
/// outside that folder when it restricts paths. Returns the resolved path and the text; `what`
/// names the file in messages ("IES file").
///
/// # Errors
/// Why, as text, naming the resolved path: cannot be read, not a regular file, larger than
/// `limit`, not UTF-8, or outside the folder.
pub fn read_scene_input(name: &Path, limit: u64, what: &str) -> Result<(PathBuf, String), String> {
    let (path, bytes) = read_scene_input_bytes(name, limit, what)?;
    let text = String::from_utf8(bytes).map_err(|e| {
        let valid = &e.as_bytes()[..e.utf8_error().valid_up_to()];
        let line = valid.iter().filter(|&&b| b == b'\n').count() + 1;
        format!("{}:{line}: the {what} is not UTF-8 text", path.display())
    })?;
    Ok((path, text))
}

/// [`read_scene_input`] for a binary file (an image): the resolved path and the bytes.
///
/// # Errors
/// As [`read_scene_input`], but for the UTF-8 check.
pub fn read_scene_input_bytes(
    name: &Path,
    limit: u64,
    what: &str,
) -> Result<(PathBuf, Vec<u8>), String> {
    let (base, restrict) = SCENE_FOLDER
        .with(|s| s.borrow().last().map(|f| (f.base.clone(), f.restrict)))
        .unwrap_or_default();
    let path = base.join(name);
    if restrict {
        check_inside(&base, &path)?;
    }
    let bytes = read_bounded(&path, limit, what).map_err(|e| format!("{}: {e}", path.display()))?;
    SCENE_FOLDER.with(|s| {
        if let Some(f) = s.borrow_mut().last_mut() {
            f.read.push(path.clone());
        }
    });
    Ok((path, bytes))
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn byte_sizes_are_written_in_the_largest_exact_unit() {
        assert_eq!(human_bytes(1 << 30), "1 GiB");
        assert_eq!(human_bytes(3 << 20), "3 MiB");
        assert_eq!(human_bytes(1536), "1.5 KiB");
        assert_eq!(human_bytes(1000), "1000 bytes");
    }

    #[test]
    fn bounded_reads_refuse_devices_directories_and_large_files() {
        let d = std::env::temp_dir().join(format!("spectrace-files-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        let f = d.join("f.txt");
        std::fs::write(&f, b"0123456789").unwrap();
        assert_eq!(read_bounded(&f, 10, "scene").unwrap().len(), 10);
        let e = read_bounded(&f, 9, "scene").unwrap_err();
        assert!(e.contains("the scene is larger than the 9 bytes limit"), "{e}");
        let e = read_bounded(&d, 100, "scene").unwrap_err();
        assert!(e.contains("not a regular file (a directory)"), "{e}");
        #[cfg(unix)]
        {
            let e = read_bounded(Path::new("/dev/zero"), 100, "scene").unwrap_err();
            assert!(e.contains("not a regular file (a device"), "{e}");
        }
        let e = read_bounded(&d.join("missing"), 100, "scene").unwrap_err();
        assert!(e.contains("cannot read the scene"), "{e}");
    }

    #[test]
    fn scene_inputs_resolve_against_the_scene_folder_and_are_recorded() {
        let d = std::env::temp_dir().join(format!("spectrace-scene-folder-{}", std::process::id()));
        let inner = d.join("scene");
        std::fs::create_dir_all(&inner).unwrap();
        std::fs::write(inner.join("lum.txt"), "inside").unwrap();
        std::fs::write(d.join("outside.txt"), "outside").unwrap();
        let (text, read) = with_scene_folder(&inner, false, || {
            read_scene_input(Path::new("lum.txt"), 100, "test file").unwrap().1
        });
        assert_eq!(text, "inside");
        assert_eq!(read, vec![inner.join("lum.txt")]);
        // Outside the folder: read without restriction, refused with it.
        let (r, _) = with_scene_folder(&inner, false, || {
            read_scene_input(Path::new("../outside.txt"), 100, "test file")
        });
        assert_eq!(r.unwrap().1, "outside");
        let (r, read) = with_scene_folder(&inner, true, || {
            read_scene_input(Path::new("../outside.txt"), 100, "test file")
        });
        assert!(r.unwrap_err().contains("outside the scene's folder"));
        assert!(read.is_empty());
        // Too large, and not UTF-8, name the resolved path.
        std::fs::write(inner.join("bin.txt"), [b'a', b'\n', 0xff]).unwrap();
        let (r, _) = with_scene_folder(&inner, false, || {
            read_scene_input(Path::new("bin.txt"), 100, "test file")
        });
        let e = r.unwrap_err();
        assert!(e.contains("bin.txt:2: the test file is not UTF-8"), "{e}");
        let (r, _) = with_scene_folder(&inner, false, || {
            read_scene_input(Path::new("lum.txt"), 3, "test file")
        });
        assert!(r.unwrap_err().contains("larger than"));
        std::fs::remove_dir_all(&d).unwrap();
    }
}
