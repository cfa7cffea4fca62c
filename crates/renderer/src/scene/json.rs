//! Reading the scene's JSON: syntax first (with its position), then the fields (with their path).

use std::path::{Path, PathBuf};

use super::{LoadOptions, SceneError, SceneFile};
use spectrace_sampling::files::with_scene_folder;

/// The scene's JSON, checked for syntax first so that syntax errors are reported as such, with
/// their position.
pub(super) fn parse_syntax(text: &str, path: &Path) -> Result<serde_json::Value, SceneError> {
    serde_json::from_str(text).map_err(|e| SceneError::Syntax {
        path: path.to_owned(),
        line: e.line(),
        column: e.column(),
        message: strip_position(&e.to_string()),
    })
}

/// The scene file's fields, with errors naming the field path, and the files its lights read.
/// Files named inside the scene (measured luminaires) resolve against its folder `base` while
/// it is deserialised, under the same path policy as OBJ meshes.
pub(super) fn deserialize(
    text: &str,
    path: &Path,
    base: &Path,
    options: LoadOptions,
) -> Result<(SceneFile, Vec<PathBuf>), SceneError> {
    let (file, light_inputs) = with_scene_folder(base, options.restrict_paths, || {
        let mut de = serde_json::Deserializer::from_str(text);
        serde_path_to_error::deserialize::<_, SceneFile>(&mut de)
    });
    let file = file.map_err(|e| {
        let field = e.path().to_string();
        let inner = e.into_inner();
        SceneError::Invalid {
            path: path.to_owned(),
            line: inner.line(),
            column: inner.column(),
            field: if field.is_empty() || field == "." { "(scene)".to_owned() } else { field },
            message: strip_position(&inner.to_string()),
        }
    })?;
    Ok((file, light_inputs))
}

/// serde_json appends " at line L column C"; the position is reported separately.
fn strip_position(message: &str) -> String {
    match message.rfind(" at line ") {
        Some(i) => message[..i].to_owned(),
        None => message.to_owned(),
    }
}
