//! Mitsuba textures (`bitmap`, `checkerboard`) as Spectrace [`Texture`]s, and the `Textured`
//! material that carries them.
//!
//! [`Texture`]: spectrace_materials::Texture

use serde_json::{Value, json};

use super::Importer;
use super::params::Params;
use super::values::{number, numbers, transform};
use super::xml::{Element, ImportError, error_at};

/// What a texture gives a material.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Use {
    /// A reflectance colour (linear sRGB in `[0, 1]`).
    Reflectance,
    /// A microfacet alpha.
    Roughness,
}

impl Importer {
    /// The native texture of `el` when it is a `<texture>` (or a `<ref>` to one); `None` for any
    /// other element (a colour or spectrum, read by the caller).
    pub(super) fn texture(
        &mut self,
        el: &Element,
        role: Use,
    ) -> Result<Option<Value>, ImportError> {
        let el = if el.tag == "ref" {
            let ids = self.ids();
            let id = el.required("id")?;
            match ids.get(id) {
                Some(t) if t.tag == "texture" => t.clone(),
                _ => return Ok(None),
            }
        } else if el.tag == "texture" {
            el.clone()
        } else {
            return Ok(None);
        };
        let p = Params::new(&el);
        let to_uv = match p.get("to_uv") {
            Some(t) => {
                let m = transform(t)?;
                let r = |i: usize| [m.row(i).x, m.row(i).y, m.row(i).w];
                Some([r(0), r(1)])
            }
            None => None,
        };
        let mut t = match el.kind() {
            "bitmap" => self.bitmap(&el, &p)?,
            "checkerboard" => self.checkerboard(&el, &p, role)?,
            other => {
                return Err(error_at(
                    &el.loc,
                    format!(
                        "texture type \"{other}\" is not supported (bitmap and checkerboard are; docs/import.md)"
                    ),
                ));
            }
        };
        if let Some(m) = to_uv {
            t["to_uv"] = json!(m);
        }
        p.finish()?;
        if role == Use::Roughness {
            self.note(&el, "a roughness texture: each point's alpha is the texture's value there (a colour's luminance), isotropic");
        }
        Ok(Some(t))
    }

    /// A `bitmap`: its file (resolved like a mesh's), filter, wrap mode and `raw`.
    fn bitmap(&mut self, el: &Element, p: &Params<'_>) -> Result<Value, ImportError> {
        let name = p
            .string("filename")?
            .ok_or_else(|| error_at(&el.loc, "needs <string name=\"filename\">"))?;
        let path = self.file_path(el, name)?;
        let filter = p.string("filter_type")?.unwrap_or("bilinear");
        let wrap = p.string("wrap_mode")?.unwrap_or("repeat");
        if !matches!(filter, "bilinear" | "nearest") {
            return Err(error_at(
                &el.loc,
                format!("filter_type \"{filter}\": bilinear or nearest"),
            ));
        }
        if !matches!(wrap, "repeat" | "mirror" | "clamp") {
            return Err(error_at(
                &el.loc,
                format!("wrap_mode \"{wrap}\": repeat, mirror or clamp"),
            ));
        }
        let raw = p.boolean("raw", false)?;
        // Storage precision and Mitsuba's lookup acceleration leave the image as it is.
        p.get("format");
        p.get("accel");
        Ok(json!({"type": "Bitmap", "file": path, "raw": raw, "filter": filter, "wrap": wrap}))
    }

    /// A `checkerboard`; read as a number (`role` a roughness), its values swapped as Mitsuba 3
    /// reads them there (its `eval_1` tests the squares the other way round).
    fn checkerboard(
        &mut self,
        el: &Element,
        p: &Params<'_>,
        role: Use,
    ) -> Result<Value, ImportError> {
        let read = |name: &str, default: f64| p.get(name).map_or(Ok(json!(default)), colour);
        let (c0, c1) = (read("color0", 0.4)?, read("color1", 0.2)?);
        Ok(if role == Use::Roughness {
            self.note(el, "a checkerboard read as a number: Mitsuba 3 swaps its two values there (its eval_1), and so does the import");
            json!({"type": "Checkerboard", "color0": c1, "color1": c0})
        } else {
            json!({"type": "Checkerboard", "color0": c0, "color1": c1})
        })
    }
}

/// A checkerboard colour: `<float>`, `<rgb>` (linear) or `<srgb>` (decoded).
fn colour(el: &Element) -> Result<Value, ImportError> {
    match el.tag.as_str() {
        "float" | "integer" => Ok(json!(number(el)?)),
        "rgb" | "srgb" | "color" => {
            let v = numbers(el, el.required("value")?)?;
            let mut c = match v.as_slice() {
                [g] => [*g; 3],
                [r, g, b] => [*r, *g, *b],
                _ => return Err(error_at(&el.loc, "one or three numbers expected")),
            };
            if el.tag == "srgb" {
                c = c.map(spectrace_spectrum::srgb_decode);
            }
            Ok(json!(c))
        }
        _ => Err(error_at(
            &el.loc,
            format!("{}: a checkerboard colour must be a <float>, <rgb> or <srgb>", el.describe()),
        )),
    }
}

/// `material` with `texture` on its `field` (`"reflectance"` or `"roughness"`).
pub(super) fn textured(material: Value, field: &str, texture: Value) -> Value {
    let mut m = json!({"type": "Textured", "material": material});
    m[field] = texture;
    m
}
