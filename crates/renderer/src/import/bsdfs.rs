//! Mitsuba BSDFs as Spectrace materials.
//!
//! Mitsuba's BSDFs reflect on one side (the normal's) unless wrapped in `twosided`; Spectrace's
//! `Diffuse`, `Plastic`, `Conductor` and `RoughConductor` reflect on both. A one-sided one is
//! imported two-sided with a note: the same image unless light reaches a back face.

use serde_json::{Value, json};

use super::Importer;
use super::params::Params;
use super::spectra::{Role, spectrum};
use super::textures::{Use, textured};
use super::xml::{Element, ImportError, error_at};

/// Mitsuba 3's named indices of refraction (its `ior.h`, from the CRC handbook).
const NAMED_IORS: &[(&str, f64)] = &[
    ("vacuum", 1.0),
    ("helium", 1.000_036),
    ("hydrogen", 1.000_132),
    ("air", 1.000_277),
    ("carbon dioxide", 1.000_45),
    ("water", 1.333),
    ("acetone", 1.36),
    ("ethanol", 1.361),
    ("carbon tetrachloride", 1.461),
    ("glycerol", 1.4729),
    ("benzene", 1.501),
    ("silicone oil", 1.520_45),
    ("bromine", 1.661),
    ("water ice", 1.31),
    ("fused quartz", 1.458),
    ("pyrex", 1.47),
    ("acrylic glass", 1.49),
    ("polypropylene", 1.49),
    ("bk7", 1.5046),
    ("sodium chloride", 1.544),
    ("amber", 1.55),
    ("pet", 1.575),
    ("diamond", 2.419),
];

/// Mitsuba's metal names that Spectrace's measured catalog holds, and its names for them.
const METALS: &[(&str, &str)] = &[
    ("Ag", "Ag"),
    ("Al", "Al"),
    ("Au", "Au"),
    ("Cr", "Cr"),
    ("Cu", "Cu"),
    ("Ni_palik", "Ni"),
    ("W", "W"),
];

/// A microfacet `distribution`: `beckmann` (Mitsuba's default) or `ggx`.
fn distribution<'a>(p: &Params<'a>) -> Result<&'a str, ImportError> {
    let distribution = p.string("distribution")?.unwrap_or("beckmann");
    if distribution != "beckmann" && distribution != "ggx" {
        return Err(error_at(
            &p.el.loc,
            format!("distribution \"{distribution}\": ggx or beckmann"),
        ));
    }
    Ok(distribution)
}

impl Importer {
    /// The material of a `<bsdf>` (followed through `<ref>`s); `sided` is whether a `twosided`
    /// wraps it.
    pub(super) fn bsdf(&mut self, el: &Element, two_sided: bool) -> Result<Value, ImportError> {
        let ids = self.ids();
        let el = super::resolve(&ids, el, "bsdf")?;
        let p = Params::new(el);
        let material = match el.kind() {
            "twosided" => {
                let inner = p.nested("bsdf");
                let inner = match inner.as_slice() {
                    [one] => *one,
                    [a, b] => {
                        return Err(error_at(
                            &b.loc,
                            format!(
                                "twosided with two different BSDFs (front {}, back {}) is not supported",
                                a.describe(),
                                b.describe()
                            ),
                        ));
                    }
                    _ => return Err(error_at(&el.loc, "twosided needs one nested <bsdf>")),
                };
                let m = self.bsdf(inner, true)?;
                p.finish()?;
                return Ok(m);
            }
            "diffuse" => {
                self.one_sided(el, two_sided);
                match self.texture_param(&p, "reflectance", Use::Reflectance)? {
                    Some(t) => {
                        textured(json!({"type": "Diffuse", "reflectance": 0.5}), "reflectance", t)
                    }
                    None => {
                        let r = self.reflectance(&p, "reflectance", 0.5)?;
                        json!({"type": "Diffuse", "reflectance": r})
                    }
                }
            }
            "conductor" | "roughconductor" => self.conductor(el, &p, two_sided)?,
            "thindielectric" => {
                let ior = self.ior(&p, "int_ior", 1.5046)? / self.ior(&p, "ext_ior", 1.000_277)?;
                self.unit_scale(&p, "specular_reflectance")?;
                let mut m = json!({"type": "ThinDielectric", "ior": ior});
                if let Some(t) = p.get("specular_transmittance") {
                    m["transmittance"] = spectrum(t, Role::Reflectance)?.reflectance_json();
                }
                m
            }
            "dielectric" | "roughdielectric" => {
                let ior = self.ior(&p, "int_ior", 1.5046)? / self.ior(&p, "ext_ior", 1.000_277)?;
                self.unit_scale(&p, "specular_reflectance")?;
                let mut m = json!({"type": "Dielectric", "ior": ior});
                if let Some(t) = p.get("specular_transmittance") {
                    m["transmittance"] = spectrum(t, Role::Reflectance)?.reflectance_json();
                }
                if el.kind() == "roughdielectric" {
                    m["type"] = json!("RoughDielectric");
                    match self.roughness(&p, &mut m)? {
                        Some(t) => textured(m, "roughness", t),
                        None => m,
                    }
                } else {
                    m
                }
            }
            "plastic" | "roughplastic" => self.plastic(el, &p, two_sided)?,
            other => {
                return Err(error_at(
                    &el.loc,
                    format!(
                        "BSDF type \"{other}\" is not supported (diffuse, conductor, roughconductor, dielectric, \
                     roughdielectric, thindielectric, plastic, roughplastic and twosided are; docs/import.md)"
                    ),
                ));
            }
        };
        p.finish()?;
        Ok(material)
    }

    /// A smooth or rough plastic. Mitsuba's default `nonlinear` false divides the diffuse
    /// term by `1 - F_dr` whatever the base albedo `R`; Spectrace's, physically, by
    /// `1 - R F_dr` (Mitsuba's `nonlinear` true). The linear look is kept exactly (for the
    /// coating's own `F_dr`) by the base albedo `R / (1 - F_dr + R F_dr)`, noted.
    fn plastic(
        &mut self,
        el: &Element,
        p: &Params<'_>,
        two_sided: bool,
    ) -> Result<Value, ImportError> {
        let texture = self.texture_param(p, "diffuse_reflectance", Use::Reflectance)?;
        let base = match p.get("diffuse_reflectance") {
            Some(e) if texture.is_none() => spectrum(e, Role::Reflectance)?,
            _ => super::spectra::Spec::Constant(0.5),
        };
        let ior = self.ior(p, "int_ior", 1.49)? / self.ior(p, "ext_ior", 1.000_277)?;
        self.unit_scale(p, "specular_reflectance")?;
        let mut m = json!({"type": "Plastic", "ior": ior});
        if el.kind() == "roughplastic" {
            let alpha = p.float("alpha", 0.1)?;
            let distribution = distribution(p)?;
            p.get("sample_visible");
            m["roughness"] = json!(alpha);
            m["distribution"] = json!(distribution);
            self.note(el, "rough plastic: Spectrace's rough coating transmits up to 8% differently from Mitsuba's tables (docs/materials-peer.md)");
        }
        let nonlinear = p.boolean("nonlinear", false)?;
        if let Some(t) = texture {
            if !nonlinear {
                self.note(el, "nonlinear=false (Mitsuba's default) with a textured base: rendered with Spectrace's physical diffuse term (Mitsuba's nonlinear=true), whose colours are darker where the base is bright");
            }
            m["reflectance"] = json!(0.5);
            self.one_sided(el, two_sided);
            return Ok(textured(m, "reflectance", t));
        }
        let base = if nonlinear {
            base
        } else {
            let mut white = m.clone();
            white["reflectance"] = json!(1.0);
            if let Some(o) = white.as_object_mut() {
                o.remove("type");
            }
            let white: spectrace_materials::Plastic = serde_json::from_value(white)
                .map_err(|e| error_at(&el.loc, format!("{}: {e}", el.describe())))?;
            self.note(el, "nonlinear=false (Mitsuba's default): rendered with the base albedo R / (1 - F_dr + R F_dr), which gives Mitsuba's linear diffuse term for Spectrace's coating");
            base.map(|lambda, r| {
                let f = white.internal_diffuse_reflectance(lambda);
                r / (1.0 - f + r * f)
            })
        };
        m["reflectance"] = base.reflectance_json();
        self.one_sided(el, two_sided);
        Ok(m)
    }

    /// A smooth or rough conductor.
    fn conductor(
        &mut self,
        el: &Element,
        p: &Params<'_>,
        two_sided: bool,
    ) -> Result<Value, ImportError> {
        let mut m = match p.string("material")? {
            Some("none") => json!({"type": "Mirror", "reflectance": 1.0}),
            Some(name) => {
                let native = METALS.iter().find(|(m, _)| *m == name).map(|(_, n)| *n).ok_or_else(|| {
                    error_at(&el.loc, format!(
                        "metal \"{name}\" is not in Spectrace's measured catalog (Ag, Al, Au, Cr, Cu, Ni_palik, W, none); \
                         give eta and k instead"
                    ))
                })?;
                self.note(el, &format!("metal {name}: Spectrace's measured n, k for {native} (sources in crates/materials/data/metals/, which differ slightly from Mitsuba's)"));
                json!({"type": "Conductor", "metal": native})
            }
            None => match (p.get("eta"), p.get("k")) {
                (Some(eta), Some(k)) => json!({
                    "type": "Conductor",
                    "eta": spectrum(eta, Role::Unbounded)?.table_json(),
                    "k": spectrum(k, Role::Unbounded)?.table_json()
                }),
                (None, None) => json!({"type": "Mirror", "reflectance": 1.0}),
                _ => return Err(error_at(&el.loc, "give both eta and k (or a material name)")),
            },
        };
        if let Some(s) = p.get("specular_reflectance") {
            let r = spectrum(s, Role::Reflectance)?;
            if m["type"] == "Mirror" {
                m["reflectance"] = r.reflectance_json();
            } else {
                m["specular_reflectance"] = r.reflectance_json();
            }
        }
        if p.get("ext_eta").is_some() {
            return Err(error_at(
                &el.loc,
                "conductors inside a medium other than air (ext_eta) are not supported",
            ));
        }
        let mut texture = None;
        if el.kind() == "roughconductor" {
            if m["type"] == "Mirror" {
                return Err(error_at(
                    &el.loc,
                    "a rough perfect mirror (material none, or no eta and k) is not supported; give a metal",
                ));
            }
            m["type"] = json!("RoughConductor");
            texture = self.roughness(p, &mut m)?;
        }
        self.one_sided(el, two_sided);
        Ok(match texture {
            Some(t) => textured(m, "roughness", t),
            None => m,
        })
    }

    /// `alpha` or `alpha_u`/`alpha_v` and `distribution` (default beckmann, Mitsuba's); the
    /// texture when `alpha` is one.
    fn roughness(&mut self, p: &Params<'_>, m: &mut Value) -> Result<Option<Value>, ImportError> {
        let mut texture = None;
        match (p.get("alpha_u"), p.get("alpha_v")) {
            (Some(u), Some(v)) => {
                for e in [u, v] {
                    if self.texture(e, Use::Roughness)?.is_some() {
                        return Err(error_at(
                            &e.loc,
                            "anisotropic roughness textures (alpha_u, alpha_v) are not supported; give one alpha texture",
                        ));
                    }
                }
                m["roughness_u"] = json!(super::values::number(u)?);
                m["roughness_v"] = json!(super::values::number(v)?);
            }
            (None, None) => match p.get("alpha") {
                Some(e) => {
                    texture = self.texture(e, Use::Roughness)?;
                    m["roughness"] =
                        json!(if texture.is_some() { 0.1 } else { super::values::number(e)? });
                }
                None => m["roughness"] = json!(0.1),
            },
            _ => return Err(error_at(&p.el.loc, "give both alpha_u and alpha_v")),
        }
        m["distribution"] = json!(distribution(p)?);
        if !p.boolean("sample_visible", true)? {
            self.note(p.el, "sample_visible=false only changes Mitsuba's sampling, not the image; Spectrace samples visible normals");
        }
        Ok(texture)
    }

    /// Notes that a BSDF Mitsuba renders one-sided is two-sided here (unless a `twosided` wraps it).
    fn one_sided(&mut self, el: &Element, two_sided: bool) {
        if !two_sided {
            self.note(el, "one-sided in Mitsuba; Spectrace's material reflects on both sides (the same image unless light reaches its back)");
        }
    }

    /// Parameter `name` when it is a texture (see [`Importer::texture`]).
    fn texture_param(
        &mut self,
        p: &Params<'_>,
        name: &str,
        role: Use,
    ) -> Result<Option<Value>, ImportError> {
        match p.get(name) {
            Some(e) => self.texture(e, role),
            None => Ok(None),
        }
    }

    /// A reflectance parameter, or the default.
    fn reflectance(
        &mut self,
        p: &Params<'_>,
        name: &str,
        default: f64,
    ) -> Result<Value, ImportError> {
        Ok(match p.get(name) {
            Some(e) => spectrum(e, Role::Reflectance)?.reflectance_json(),
            None => json!(default),
        })
    }

    /// A named or numeric index of refraction.
    fn ior(&mut self, p: &Params<'_>, name: &str, default: f64) -> Result<f64, ImportError> {
        let Some(e) = p.get(name) else { return Ok(default) };
        if e.tag == "string" {
            let v = e.required("value")?;
            return NAMED_IORS.iter().find(|(n, _)| *n == v.to_lowercase()).map(|(_, i)| *i).ok_or_else(|| {
                error_at(&e.loc, format!("unknown IOR name \"{v}\" (Mitsuba 3's names are read: bk7, water, air, diamond, ...)"))
            });
        }
        super::values::number(e)
    }

    /// A `specular_reflectance` that Spectrace cannot scale: only 1 is accepted.
    fn unit_scale(&mut self, p: &Params<'_>, name: &str) -> Result<(), ImportError> {
        if let Some(e) = p.get(name)
            && spectrum(e, Role::Reflectance)?.constant() != Some(1.0)
        {
            return Err(error_at(&e.loc, format!("{name} other than 1 is not supported here")));
        }
        Ok(())
    }
}
