//! Reading a Mitsuba scene file into an owned element tree: `<include>` spliced in, `<default>`
//! and `-D` values substituted for `$name` in every attribute, Mitsuba 0.6's camelCase names
//! turned into Mitsuba 3's snake_case, and every element tagged with its file and line.

use std::collections::HashMap;
use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::files::MAX_SCENE_BYTES;
use spectrace_sampling::files::read_scene_input;

/// Where an element was written: its file and line.
#[derive(Debug, Clone)]
pub(crate) struct Loc {
    pub(crate) file: Arc<PathBuf>,
    pub(crate) line: u32,
}

impl fmt::Display for Loc {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}", self.file.display(), self.line)
    }
}

/// An error at a place in a scene file.
#[derive(Debug, Clone)]
pub struct ImportError {
    /// `file:line` (or the file alone).
    pub at: String,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for ImportError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.at, self.message)
    }
}

impl std::error::Error for ImportError {}

/// An error at `loc`.
pub(crate) fn error_at(loc: &Loc, message: impl Into<String>) -> ImportError {
    ImportError { at: loc.to_string(), message: message.into() }
}

/// One element of the scene: tag, attributes, children, place.
#[derive(Debug, Clone)]
pub(crate) struct Element {
    pub(crate) tag: String,
    pub(crate) attrs: Vec<(String, String)>,
    pub(crate) children: Vec<Element>,
    pub(crate) loc: Loc,
}

impl Element {
    /// The attribute `key`, if given.
    pub(crate) fn attr(&self, key: &str) -> Option<&str> {
        self.attrs.iter().find(|(k, _)| k == key).map(|(_, v)| v.as_str())
    }

    /// The `type` attribute ("" when missing).
    pub(crate) fn kind(&self) -> &str {
        self.attr("type").unwrap_or("")
    }

    /// The attribute `key`, required.
    pub(crate) fn required(&self, key: &str) -> Result<&str, ImportError> {
        self.attr(key).ok_or_else(|| {
            error_at(&self.loc, format!("<{}> needs the attribute `{key}`", self.tag))
        })
    }

    /// `<tag type="...">` for messages.
    pub(crate) fn describe(&self) -> String {
        match (self.attr("type"), self.attr("name")) {
            (Some(t), Some(n)) => format!("<{} type=\"{t}\" name=\"{n}\">", self.tag),
            (Some(t), None) => format!("<{} type=\"{t}\">", self.tag),
            (None, Some(n)) => format!("<{} name=\"{n}\">", self.tag),
            (None, None) => format!("<{}>", self.tag),
        }
    }
}

/// The most nested `<include>`s (a cycle is refused before this).
const MAX_INCLUDE_DEPTH: usize = 16;

/// A scene read from its files: the root `<scene>` with includes spliced, and the files read.
pub(crate) struct SceneTree {
    pub(crate) root: Element,
    pub(crate) files: Vec<PathBuf>,
    /// The command line's definitions no `$name` in the files used.
    pub(crate) unused_defines: Vec<String>,
}

/// Reads the scene file `path` with the command line's `defines` (`-D name=value`), which take
/// precedence over the file's `<default>`s.
pub(crate) fn read_scene(
    path: &Path,
    defines: &[(String, String)],
) -> Result<SceneTree, ImportError> {
    let mut reader = Reader {
        vars: defines.iter().cloned().collect(),
        from_command_line: defines.iter().map(|(k, _)| k.clone()).collect(),
        files: Vec::new(),
        stack: Vec::new(),
        legacy: false,
        used: std::cell::RefCell::new(Vec::new()),
    };
    let (root, _) = reader.file(path, None)?;
    let used = reader.used.into_inner();
    let unused_defines =
        reader.from_command_line.into_iter().filter(|k| !used.contains(k)).collect();
    Ok(SceneTree { root, files: reader.files, unused_defines })
}

struct Reader {
    vars: HashMap<String, String>,
    from_command_line: Vec<String>,
    files: Vec<PathBuf>,
    stack: Vec<PathBuf>,
    /// Mitsuba 0.6 names (camelCase) are being read.
    legacy: bool,
    /// The variables substituted so far.
    used: std::cell::RefCell<Vec<String>>,
}

impl Reader {
    /// Reads one file's `<scene>`; `from` is the `<include>` that named it.
    fn file(&mut self, path: &Path, from: Option<&Loc>) -> Result<(Element, bool), ImportError> {
        let at = |m: String| match from {
            Some(l) => error_at(l, m),
            None => ImportError { at: path.display().to_string(), message: m },
        };
        // Absolute, so that files named inside resolve the same whatever the current folder.
        let path = &std::path::absolute(path)
            .map_err(|e| at(format!("cannot open {}: {e}", path.display())))?;
        let canonical =
            path.canonicalize().map_err(|e| at(format!("cannot open {}: {e}", path.display())))?;
        if self.stack.contains(&canonical) {
            return Err(at(format!("{} includes itself (an include cycle)", path.display())));
        }
        if self.stack.len() >= MAX_INCLUDE_DEPTH {
            return Err(at(format!("includes nested more than {MAX_INCLUDE_DEPTH} deep")));
        }
        // Through the scene folder's policy (bounded; refused outside it with
        // --restrict-paths; recorded as an input that outputs may never replace).
        let (_, text) = read_scene_input(path, MAX_SCENE_BYTES, "scene").map_err(at)?;
        let doc = roxmltree::Document::parse(&text).map_err(|e| ImportError {
            at: path.display().to_string(),
            message: format!("not well-formed XML: {e}"),
        })?;
        let file = Arc::new(path.to_owned());
        let root = doc.root_element();
        let loc = Loc { file: file.clone(), line: doc.text_pos_at(root.range().start).row };
        if root.tag_name().name() != "scene" {
            return Err(error_at(
                &loc,
                format!("the root element is <{}>, not <scene>", root.tag_name().name()),
            ));
        }
        let version = root.attribute("version").unwrap_or("");
        let legacy = version.starts_with("0.");
        if !version.is_empty()
            && !legacy
            && !version.starts_with("2.")
            && !version.starts_with("3.")
        {
            return Err(error_at(
                &loc,
                format!("scene version \"{version}\": Mitsuba 0.6 and 3 files are read"),
            ));
        }
        let outer = std::mem::replace(&mut self.legacy, legacy);
        self.files.push(path.to_owned());
        self.stack.push(canonical);
        let children = self.children(&doc, root, &file);
        self.stack.pop();
        self.legacy = outer;
        let children = children?;
        Ok((Element { tag: "scene".to_owned(), attrs: Vec::new(), children, loc }, legacy))
    }

    /// The element children of `node`, `<default>` recorded and `<include>` spliced.
    fn children(
        &mut self,
        doc: &roxmltree::Document<'_>,
        node: roxmltree::Node<'_, '_>,
        file: &Arc<PathBuf>,
    ) -> Result<Vec<Element>, ImportError> {
        let mut out = Vec::new();
        for child in node.children().filter(roxmltree::Node::is_element) {
            let loc = Loc { file: file.clone(), line: doc.text_pos_at(child.range().start).row };
            match child.tag_name().name() {
                "default" => {
                    let name = self.attribute(child, "name", &loc)?;
                    let value = self.attribute(child, "value", &loc)?;
                    if !self.from_command_line.contains(&name) {
                        self.vars.entry(name).or_insert(value);
                    }
                }
                "include" => {
                    let name = self.attribute(child, "filename", &loc)?;
                    let dir = file.parent().unwrap_or_else(|| Path::new("."));
                    let (included, _) = self.file(&dir.join(&name), Some(&loc))?;
                    out.extend(included.children);
                }
                _ => out.push(self.element(doc, child, file, loc)?),
            }
        }
        Ok(out)
    }

    /// One element with its attributes substituted and names normalised.
    fn element(
        &mut self,
        doc: &roxmltree::Document<'_>,
        node: roxmltree::Node<'_, '_>,
        file: &Arc<PathBuf>,
        loc: Loc,
    ) -> Result<Element, ImportError> {
        let mut tag = node.tag_name().name().to_owned();
        if self.legacy && tag == "lookAt" {
            tag = "lookat".to_owned();
        }
        let mut attrs = Vec::new();
        for a in node.attributes() {
            let mut value = self.substitute(a.value(), &loc)?;
            if self.legacy && a.name() == "name" {
                value = snake_case(&value);
            }
            attrs.push((a.name().to_owned(), value));
        }
        let children = self.children(doc, node, file)?;
        Ok(Element { tag, attrs, children, loc })
    }

    /// An attribute of `node`, substituted, required.
    fn attribute(
        &self,
        node: roxmltree::Node<'_, '_>,
        key: &str,
        loc: &Loc,
    ) -> Result<String, ImportError> {
        let v = node.attribute(key).ok_or_else(|| {
            error_at(loc, format!("<{}> needs the attribute `{key}`", node.tag_name().name()))
        })?;
        self.substitute(v, loc)
    }

    /// `text` with every `$name` replaced by its value.
    fn substitute(&self, text: &str, loc: &Loc) -> Result<String, ImportError> {
        if !text.contains('$') {
            return Ok(text.to_owned());
        }
        let mut out = String::new();
        let mut rest = text;
        while let Some(i) = rest.find('$') {
            out.push_str(&rest[..i]);
            let after = &rest[i + 1..];
            let len = after
                .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                .unwrap_or(after.len());
            let name = &after[..len];
            let value = self.vars.get(name).ok_or_else(|| {
                error_at(
                    loc,
                    format!(
                        "`${name}` is not defined: give a <default name=\"{name}\" value=\"...\"/> \
                         before it, or -D {name}=VALUE on the command line"
                    ),
                )
            })?;
            out.push_str(value);
            self.used.borrow_mut().push(name.to_owned());
            rest = &after[len..];
        }
        out.push_str(rest);
        Ok(out)
    }
}

/// Mitsuba 0.6's camelCase parameter names in Mitsuba 3's snake_case (`maxDepth` ->
/// `max_depth`, `intIOR` -> `int_ior`, `toWorld` -> `to_world`).
pub(crate) fn snake_case(name: &str) -> String {
    let chars: Vec<char> = name.chars().collect();
    let mut out = String::new();
    for (i, &c) in chars.iter().enumerate() {
        if c.is_ascii_uppercase() {
            let prev_lower =
                i > 0 && (chars[i - 1].is_ascii_lowercase() || chars[i - 1].is_ascii_digit());
            if prev_lower {
                out.push('_');
            }
            out.push(c.to_ascii_lowercase());
        } else {
            out.push(c);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::snake_case;

    #[test]
    fn mitsuba_06_names_become_mitsuba_3_names() {
        assert_eq!(snake_case("maxDepth"), "max_depth");
        assert_eq!(snake_case("intIOR"), "int_ior");
        assert_eq!(snake_case("toWorld"), "to_world");
        assert_eq!(snake_case("sampleCount"), "sample_count");
        assert_eq!(snake_case("fovAxis"), "fov_axis");
        assert_eq!(snake_case("max_depth"), "max_depth");
    }
}
