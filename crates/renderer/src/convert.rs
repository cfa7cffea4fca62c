//! `spectrace convert scene.xml --out scene.json`: a Mitsuba scene written as Spectrace's own
//! JSON scene, its mesh paths relative to the output's folder where they can be, its
//! approximations printed. The output is refused when it is one of the files the scene reads.

use std::path::{Component, Path, PathBuf};
use std::process::ExitCode;

use serde_json::Value;

use crate::files::{check_no_input_replaced, write_atomically};
use crate::say::{say, tell};

/// Runs `spectrace convert`; prints the notes and what was written, or the error.
pub(crate) fn convert_command(scene: &Path, out: &Path, defines: &[(String, String)]) -> ExitCode {
    match convert(scene, out, defines) {
        Ok(notes) => {
            for n in &notes {
                tell!("approximation: {n}");
            }
            say!("wrote {}", out.display());
            ExitCode::SUCCESS
        }
        Err(e) => {
            tell!("error: {e}");
            ExitCode::from(2)
        }
    }
}

/// Converts `scene` into `out`; returns the approximations made.
///
/// # Errors
/// The import's error, an output that is one of the inputs, or a failed write.
pub fn convert(
    scene: &Path,
    out: &Path,
    defines: &[(String, String)],
) -> Result<Vec<String>, String> {
    let imported = crate::import_mitsuba(scene, defines).map_err(|e| e.to_string())?;
    let mut value = imported.scene;
    let out_dir = std::path::absolute(out)
        .map_err(|e| format!("{}: {e}", out.display()))?
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_default();
    let mut inputs = imported.files.clone();
    relativise_meshes(&mut value, &out_dir, &mut inputs);
    check_no_input_replaced(&[out.to_path_buf()], &inputs)?;
    std::fs::create_dir_all(&out_dir).map_err(|e| format!("{}: {e}", out_dir.display()))?;
    let text = serde_json::to_string_pretty(&value).map_err(|e| e.to_string())?;
    write_atomically(out, |tmp| std::fs::write(tmp, text.as_bytes()).map_err(|e| e.to_string()))?;
    Ok(imported.notes.iter().map(ToString::to_string).collect())
}

/// Rewrites every mesh path (`obj`, `ply`, `serialized`), texture and environment file relative
/// to `dir` and
/// collects them in `inputs`.
fn relativise_meshes(scene: &mut Value, dir: &Path, inputs: &mut Vec<PathBuf>) {
    let mut rebase = |p: &mut String| {
        let path = PathBuf::from(&*p);
        inputs.push(path.clone());
        if let Some(rel) = relative(&path, dir) {
            *p = rel.to_string_lossy().into_owned();
        }
    };
    if let Some(Value::String(p)) = scene.get_mut("environment").and_then(|e| e.get_mut("file")) {
        rebase(p);
    }
    let Some(objects) = scene.get_mut("objects").and_then(Value::as_array_mut) else { return };
    for object in objects {
        for key in ["obj", "ply", "serialized"] {
            if let Some(Value::String(p)) = object.get_mut("shape").and_then(|s| s.get_mut(key)) {
                rebase(p);
            }
        }
        for key in ["reflectance", "roughness"] {
            let texture = object.get_mut("material").and_then(|m| m.get_mut(key));
            if let Some(Value::String(p)) = texture.and_then(|t| t.get_mut("file")) {
                rebase(p);
            }
        }
    }
}

/// `path` relative to `dir` (both absolute), through `..` where needed; `None` across roots.
fn relative(path: &Path, dir: &Path) -> Option<PathBuf> {
    let p: Vec<Component<'_>> = path.components().collect();
    let d: Vec<Component<'_>> = dir.components().collect();
    if p.first() != d.first() {
        return None;
    }
    let common = p.iter().zip(&d).take_while(|(a, b)| a == b).count();
    let mut out = PathBuf::new();
    for _ in common..d.len() {
        out.push("..");
    }
    for c in &p[common..] {
        out.push(c);
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::relative;
    use std::path::{Path, PathBuf};

    #[test]
    fn paths_are_made_relative_through_parents() {
        assert_eq!(
            relative(Path::new("/a/b/m.obj"), Path::new("/a/b")),
            Some(PathBuf::from("m.obj"))
        );
        assert_eq!(
            relative(Path::new("/a/b/m.obj"), Path::new("/a/c/d")),
            Some(PathBuf::from("../../b/m.obj"))
        );
    }
}
