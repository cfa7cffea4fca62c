//! Mitsuba scene files in: `spectrace render scene.xml` and `spectrace convert scene.xml --out
//! scene.json` read Mitsuba 3 XML (and Mitsuba 0.6's, whose names differ only in case) into
//! Spectrace's own scene, the JSON of `scenes/README.md`, which then loads like any scene file.
//!
//! Modules: `xml` (files, includes, `$var`s, places), `values` (numbers, transforms), `spectra`
//! (colours and spectra in Mitsuba's units), `params` (every parameter read or refused),
//! `bsdfs`, `shapes`, `emitters`, and here the scene, sensor and integrator. Every tag or
//! parameter the importer does not support is refused with its file and line; the few it
//! replaces by an approximation are listed as [`ImportNote`]s, which a render prints and writes
//! to its sidecar. `docs/import.md` is the coverage table and the unit conversions.

mod bsdfs;
mod emitters;
mod params;
mod shapes;
mod spectra;
mod textures;
mod values;
mod xml;

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use glam::{DMat4, DVec3};
use serde_json::{Value, json};

use params::Params;
use values::transform;
pub use xml::ImportError;

use xml::{Element, error_at};

/// `el` itself, or the plugin a `<ref id>` names in `ids`, which must be a `tag`.
fn resolve<'a>(
    ids: &'a HashMap<String, Element>,
    el: &'a Element,
    tag: &str,
) -> Result<&'a Element, ImportError> {
    if el.tag != "ref" {
        return Ok(el);
    }
    let id = el.required("id")?;
    let target = ids
        .get(id)
        .ok_or_else(|| error_at(&el.loc, format!("<ref id=\"{id}\">: no element has this id")))?;
    if target.tag != tag {
        return Err(error_at(
            &el.loc,
            format!("<ref id=\"{id}\"> names a <{}>, here a <{tag}> is expected", target.tag),
        ));
    }
    Ok(target)
}

/// An approximation the importer made, and where.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ImportNote {
    /// `file:line` of the element.
    pub at: String,
    /// What was approximated and how.
    pub message: String,
}

impl std::fmt::Display for ImportNote {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}", self.at, self.message)
    }
}

/// A Mitsuba scene as Spectrace's: the native scene JSON, the notes, and every file read.
#[derive(Debug, Clone)]
pub struct Imported {
    /// The scene in Spectrace's JSON form (mesh paths absolute).
    pub scene: Value,
    /// The approximations made.
    pub notes: Vec<ImportNote>,
    /// The XML files read (the scene and its includes).
    pub files: Vec<PathBuf>,
}

/// Whether `path` names a Mitsuba scene file (`.xml`, any case).
pub fn is_mitsuba_scene(path: &Path) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case("xml"))
}

/// Reads the Mitsuba scene file `path`, with `defines` (`-D name=value`) overriding its
/// `<default>`s.
///
/// # Errors
/// [`ImportError`] with the file and line of the first element that cannot be read or is not
/// supported.
pub fn import_mitsuba(path: &Path, defines: &[(String, String)]) -> Result<Imported, ImportError> {
    import_mitsuba_with(path, defines, false)
}

/// As [`import_mitsuba`]; with `restrict_paths` (`--restrict-paths`), every file the scene names
/// (includes, meshes, spectra) must lie inside the scene file's folder, symlinks resolved.
///
/// # Errors
/// As [`import_mitsuba`], and a file outside the folder.
pub fn import_mitsuba_with(
    path: &Path,
    defines: &[(String, String)],
    restrict_paths: bool,
) -> Result<Imported, ImportError> {
    let main_dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let (imported, read) =
        spectrace_sampling::files::with_scene_folder(&main_dir, restrict_paths, || {
            import_in_folder(path, defines, restrict_paths)
        });
    let mut imported = imported?;
    for file in read {
        if !imported.files.contains(&file) {
            imported.files.push(file);
        }
    }
    Ok(imported)
}

/// The import itself, inside the scene folder's path policy.
fn import_in_folder(
    path: &Path,
    defines: &[(String, String)],
    restrict: bool,
) -> Result<Imported, ImportError> {
    let tree = xml::read_scene(path, defines)?;
    let mut importer = Importer {
        main_dir: path.parent().map(Path::to_path_buf),
        restrict,
        ..Importer::default()
    };
    importer.scene(&tree.root)?;
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "image".to_owned());
    let scene = importer.finish(&tree.root, &name)?;
    for name in &tree.unused_defines {
        importer.notes.push(ImportNote {
            at: path.display().to_string(),
            message: format!("-D {name}: the scene never uses ${name}"),
        });
    }
    Ok(Imported { scene, notes: importer.notes, files: tree.files })
}

/// The importer's state: named plugins, and the scene as it is built.
#[derive(Default)]
struct Importer {
    ids: std::rc::Rc<HashMap<String, Element>>,
    objects: Vec<Value>,
    lights: Vec<Value>,
    camera: Option<Value>,
    settings: serde_json::Map<String, Value>,
    notes: Vec<ImportNote>,
    /// The main scene file's folder.
    main_dir: Option<PathBuf>,
    /// Refuse files outside `main_dir` (`--restrict-paths`).
    restrict: bool,
    /// Directional emitters (place, direction, irradiance, spectrum), placed when every object
    /// is known.
    directional: Vec<(xml::Loc, DVec3, f64, Value)>,
    /// Constant environments (place, radiance, spectrum), placed around the objects.
    constant: Vec<(xml::Loc, f64, Value)>,
    /// The `envmap` emitter (place, the native scene's `environment`).
    environment: Option<(xml::Loc, Value)>,
}

impl Importer {
    /// Walks the scene's top-level elements.
    fn scene(&mut self, root: &Element) -> Result<(), ImportError> {
        let mut ids = HashMap::new();
        for el in &root.children {
            if let Some(id) = el.attr("id") {
                ids.insert(id.to_owned(), el.clone());
            }
        }
        self.ids = std::rc::Rc::new(ids);
        for el in &root.children {
            match el.tag.as_str() {
                "integrator" => self.integrator(el)?,
                "sensor" => self.sensor(el)?,
                "shape" => self.shape(el, DMat4::IDENTITY)?,
                "emitter" => self.emitter(el)?,
                "bsdf" | "texture" | "spectrum" | "rgb" => {}
                "medium" => return Err(error_at(&el.loc, "participating media are not supported")),
                other => {
                    return Err(error_at(
                        &el.loc,
                        format!("<{other}> at the top of a scene is not supported"),
                    ));
                }
            }
        }
        Ok(())
    }

    /// The native scene.
    fn finish(&mut self, root: &Element, name: &str) -> Result<Value, ImportError> {
        let camera =
            self.camera.take().ok_or_else(|| error_at(&root.loc, "the scene has no <sensor>"))?;
        let eye: [f64; 3] = serde_json::from_value(camera["position"].clone()).unwrap_or_default();
        self.place_around(DVec3::from_array(eye))?;
        let mut scene = json!({
            "camera": camera,
            "objects": std::mem::take(&mut self.objects),
            "lights": std::mem::take(&mut self.lights),
            "settings": Value::Object(std::mem::take(&mut self.settings)),
            "output": {"name": name},
        });
        if let Some((_, environment)) = self.environment.take() {
            scene["environment"] = environment;
        }
        if scene["settings"].get("integrator").is_none() {
            scene["settings"]["integrator"] = json!("path");
        }
        Ok(scene)
    }

    /// Records an approximation at `el` (once per place and message).
    fn note(&mut self, el: &Element, message: &str) {
        let note = ImportNote { at: el.loc.to_string(), message: message.to_owned() };
        if !self.notes.contains(&note) {
            self.notes.push(note);
        }
    }

    /// The named plugins (shared, so that a plugin can be read while the importer changes).
    fn ids(&self) -> std::rc::Rc<HashMap<String, Element>> {
        self.ids.clone()
    }

    /// Whether the `<ref>` names a `tag`.
    fn is_ref_to(&self, r: &Element, tag: &str) -> bool {
        r.attr("id").and_then(|id| self.ids.get(id)).is_some_and(|t| t.tag == tag)
    }

    /// The `<ref>` children of `p` that name a `tag`.
    fn refs<'a>(&self, p: &Params<'a>, tag: &str) -> Vec<&'a Element> {
        p.el.children.iter().filter(|c| c.tag == "ref" && self.is_ref_to(c, tag)).collect()
    }

    /// A file named in `el`, resolved against the file that names it; absolute.
    fn file_path(&self, el: &Element, name: &str) -> Result<PathBuf, ImportError> {
        // Resolved against the folder of the file that names it, or else (as Mitsuba's file
        // resolver does for included fragments) the main scene's folder.
        let own = el.loc.file.parent().unwrap_or_else(|| Path::new(".")).join(name);
        let path = match &self.main_dir {
            Some(main) if !own.exists() && main.join(name).exists() => main.join(name),
            _ => own,
        };
        if self.restrict {
            let main = self.main_dir.clone().unwrap_or_default();
            spectrace_sampling::files::check_inside(&main, &path)
                .map_err(|e| error_at(&el.loc, e))?;
        }
        std::path::absolute(&path)
            .map_err(|e| error_at(&el.loc, format!("{}: {e}", path.display())))
    }

    /// `<integrator>`: its type and `max_depth`.
    fn integrator(&mut self, el: &Element) -> Result<(), ImportError> {
        let p = Params::new(el);
        let native = match el.kind() {
            "path" | "volpath" | "volpathmis" => "path",
            "ptracer" => "light",
            "bdpt" => "bdpt",
            "direct" => {
                self.settings.insert("max_depth".to_owned(), json!(0));
                "path"
            }
            other => {
                return Err(error_at(
                    &el.loc,
                    format!(
                        "integrator \"{other}\" is not supported (path, volpath, ptracer, bdpt, direct are mapped to Spectrace's)"
                    ),
                ));
            }
        };
        self.settings.insert("integrator".to_owned(), json!(native));
        // Mitsuba counts path vertices (1: emitters seen directly, 2: direct light; -1 unlimited),
        // Spectrace bounces (0: direct light).
        let depth = p.get("max_depth").map_or(Ok(-1), |d| values::whole(d, -1))?;
        if el.kind() != "direct" {
            let bounces = match depth {
                -1 => i64::from(spectrace_tracer::MAX_DEPTH),
                0 | 1 => {
                    return Err(error_at(
                        &el.loc,
                        format!(
                            "max_depth {depth}: Spectrace renders at least direct light (Mitsuba's max_depth 2)"
                        ),
                    ));
                }
                d => (d - 2).min(i64::from(spectrace_tracer::MAX_DEPTH)),
            };
            self.settings.insert("max_depth".to_owned(), json!(bounces));
        }
        if let Some(rr) = p.get("rr_depth") {
            let rr = values::whole(rr, 1)?;
            self.settings.insert("rr_depth".to_owned(), json!(rr - 1));
        }
        for harmless in ["hide_emitters", "samples_per_pass", "timeout"] {
            if p.get(harmless).is_some() {
                self.note(el, &format!("{harmless} is not used by Spectrace"));
            }
        }
        p.finish()
    }

    /// `<sensor>`: the camera, its film's size and its sampler's sample count.
    fn sensor(&mut self, el: &Element) -> Result<(), ImportError> {
        if self.camera.is_some() {
            return Err(error_at(&el.loc, "a second <sensor>: Spectrace renders one camera"));
        }
        let p = Params::new(el);
        if el.kind() != "perspective" && el.kind() != "thinlens" {
            return Err(error_at(
                &el.loc,
                format!("sensor \"{}\": perspective and thinlens are supported", el.kind()),
            ));
        }
        let m = p.get("to_world").map_or(Ok(DMat4::IDENTITY), transform)?;
        let position = m.transform_point3(DVec3::ZERO);
        let forward = m.transform_vector3(DVec3::Z).normalize_or_zero();
        let up = m.transform_vector3(DVec3::Y).normalize_or_zero();
        let left = m.transform_vector3(DVec3::X).normalize_or_zero();
        if left.dot(up.cross(forward)) < 0.0 {
            return Err(error_at(
                &el.loc,
                "the camera's to_world mirrors the image; Spectrace's camera cannot",
            ));
        }
        let (width, height) = self.film(&p)?;
        let fov =
            match (p.get("fov"), p.get("focal_length")) {
                (Some(f), _) => values::number(f)?,
                (None, Some(f)) => {
                    let mm =
                        f.required("value")?.trim_end_matches("mm").trim().parse::<f64>().map_err(
                            |_| error_at(&f.loc, "focal_length: a length like \"50mm\""),
                        )?;
                    2.0 * (36.0 / (2.0 * mm)).atan().to_degrees()
                }
                (None, None) => 2.0 * (36.0 / 100.0f64).atan().to_degrees(),
            };
        let axis = match p.string("fov_axis")?.unwrap_or("x") {
            "x" => "horizontal",
            "y" => "vertical",
            "diagonal" => "diagonal",
            "smaller" => {
                if width <= height {
                    "horizontal"
                } else {
                    "vertical"
                }
            }
            "larger" => {
                if width >= height {
                    "horizontal"
                } else {
                    "vertical"
                }
            }
            other => {
                return Err(error_at(
                    &el.loc,
                    format!("fov_axis \"{other}\": x, y, diagonal, smaller or larger"),
                ));
            }
        };
        let mut camera = json!({
            "position": position.to_array(), "look_at": (position + forward).to_array(), "up": up.to_array(),
            "fov": fov, "fov_axis": axis, "width": width, "height": height,
        });
        if el.kind() == "thinlens" {
            camera["aperture_radius"] = json!(p.float("aperture_radius", 0.1)?);
            camera["focus_distance"] = json!(p.float("focus_distance", 0.0)?);
        } else if p.get("focus_distance").is_some() {
            // A pinhole has no focus; Mitsuba ignores it too.
        }
        for clip in ["near_clip", "far_clip"] {
            if p.get(clip).is_some() {
                self.note(el, &format!("{clip}: Spectrace's camera does not clip (the same image unless geometry lies outside the clip range)"));
            }
        }
        for s in p.nested("sampler") {
            let sp = Params::new(s);
            if let Some(n) = sp.get("sample_count") {
                self.settings.insert("spp".to_owned(), json!(values::whole(n, 1)?));
            }
            if let Some(seed) = sp.get("seed") {
                self.settings.insert("seed".to_owned(), json!(values::whole(seed, 0)?));
            }
            for ignored in ["jitter", "scramble_seed", "dimension"] {
                sp.get(ignored);
            }
            self.note(
                s,
                &format!(
                    "sampler \"{}\": Spectrace chooses its own sample points (settings.sampler)",
                    s.kind()
                ),
            );
            sp.finish()?;
        }
        p.nested("film");
        p.finish()?;
        self.camera = Some(camera);
        Ok(())
    }

    /// The film's width and height (Mitsuba's defaults 768 x 576); its filter and formats are
    /// noted.
    fn film(&mut self, p: &Params<'_>) -> Result<(u32, u32), ImportError> {
        let films = p.nested("film");
        let Some(film) = films.first() else { return Ok((768, 576)) };
        let f = Params::new(film);
        let w = f.get("width").map_or(Ok(768), |e| values::whole(e, 1))?;
        let h = f.get("height").map_or(Ok(576), |e| values::whole(e, 1))?;
        if w > 65536 || h > 65536 {
            return Err(error_at(&film.loc, format!("film size {w} x {h}: each from 1 to 65536")));
        }
        for r in f.nested("rfilter") {
            if r.kind() != "box" {
                self.note(r, &format!(
                    "reconstruction filter \"{}\": Spectrace renders with a box filter (each pixel its own area): the same region means, slightly sharper pixels",
                    r.kind()
                ));
            }
        }
        for harmless in [
            "pixel_format",
            "file_format",
            "component_format",
            "banner",
            "high_quality_edges",
            "rfilter",
        ] {
            f.get(harmless);
        }
        for crop in ["crop_width", "crop_height", "crop_offset_x", "crop_offset_y"] {
            if let Some(c) = f.get(crop) {
                return Err(error_at(&c.loc, "film crops are not supported"));
            }
        }
        f.finish()?;
        Ok((w as u32, h as u32))
    }
}
