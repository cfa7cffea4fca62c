//! Bounded reading of input files, shared by every crate that reads one (OBJ meshes here; scene
//! files and partial films in the renderer): this is the lowest crate all of them depend on.

use std::io::Read;
use std::path::Path;

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
}
