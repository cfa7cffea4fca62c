//! [`Textured`]: a material whose colour or roughness varies over the surface, read from a
//! [`Texture`] at each hit's `uv`.
//!
//! | field | meaning |
//! |---|---|
//! | `material` | the material textured: a `Diffuse`, `Plastic`, `RoughConductor` or `RoughDielectric`, written as on its own; its own value of a textured field stands wherever no surface point is known (analyses, the effects report) |
//! | `reflectance` | a [`Texture`] of linear-sRGB colours in `[0, 1]`: the albedo of a `Diffuse`, the base of a `Plastic` |
//! | `roughness` | a [`Texture`] of microfacet alphas `>= 0` (a colour's luminance): of a `RoughConductor` or `RoughDielectric` (isotropic) |
//!
//! ```json
//! {"type": "Textured", "material": {"type": "Diffuse", "reflectance": 0.5},
//!  "reflectance": {"type": "Bitmap", "file": "wood.png"}}
//! {"type": "Textured", "material": {"type": "RoughConductor", "metal": "Au", "roughness": 0.1},
//!  "roughness": {"type": "Checkerboard", "color0": 0.05, "color1": 0.4}}
//! ```
//!
//! A texel's colour becomes a spectrum through [`RgbTable`] (Jakob and Hanika's sigmoid of a
//! quadratic, the table fitted by the project's own solver), so a textured surface is as
//! spectral as any other. At a hit the renderer asks [`Material::texel`] for the material there:
//! a [`Texel`] (the coating or index tables shared, not copied; one small box per textured hit),
//! which it then samples and evaluates like any material ([`MaterialAt`]).

use std::ops::Deref;

use glam::DVec2;
use serde::{Deserialize, Serialize};
use spectrace_spectrum::{Reflectance, RgbTable};

use crate::texture::Texture;
use crate::{
    BundleScattered, Diffuse, Incoming, Material, MaterialError, Plastic, RoughConductor,
    RoughDielectric, Scattered, Transport,
};

/// The materials a [`Textured`] may texture.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(tag = "type")]
enum Base {
    Diffuse(Diffuse),
    Plastic(Plastic),
    RoughConductor(RoughConductor),
    RoughDielectric(RoughDielectric),
}

impl Base {
    fn as_material(&self) -> &dyn Material {
        match self {
            Base::Diffuse(m) => m,
            Base::Plastic(m) => m,
            Base::RoughConductor(m) => m,
            Base::RoughDielectric(m) => m,
        }
    }
}

/// A material with a textured reflectance or roughness (see the module's table).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(try_from = "TexturedRepr", into = "TexturedRepr")]
pub struct Textured {
    material: Base,
    reflectance: Option<Texture>,
    roughness: Option<Texture>,
}

/// Scene-file form of [`Textured`].
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct TexturedRepr {
    material: Base,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    reflectance: Option<Texture>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    roughness: Option<Texture>,
}

const NAME: &str = "Textured";

impl TryFrom<TexturedRepr> for Textured {
    type Error = MaterialError;
    fn try_from(r: TexturedRepr) -> Result<Self, MaterialError> {
        let kind = match r.material {
            Base::Diffuse(_) => "Diffuse",
            Base::Plastic(_) => "Plastic",
            Base::RoughConductor(_) => "RoughConductor",
            Base::RoughDielectric(_) => "RoughDielectric",
        };
        let colour = matches!(r.material, Base::Diffuse(_) | Base::Plastic(_));
        if r.reflectance.is_none() && r.roughness.is_none() {
            return Err(MaterialError::parameter(
                NAME,
                "reflectance",
                "none",
                "give a `reflectance` or `roughness` texture (else use the material itself)",
            ));
        }
        if let Some(t) = &r.reflectance {
            if !colour {
                return Err(MaterialError::parameter(
                    NAME,
                    "reflectance",
                    kind,
                    "a reflectance texture applies to a Diffuse or Plastic only",
                ));
            }
            let (lo, hi) = t.range();
            if !(lo >= 0.0 && hi <= 1.0) {
                return Err(MaterialError::parameter(
                    NAME,
                    "reflectance",
                    [lo, hi],
                    "the texture's values (smallest, largest) must lie in [0, 1] for a reflectance",
                ));
            }
        }
        if let Some(t) = &r.roughness {
            if colour {
                return Err(MaterialError::parameter(
                    NAME,
                    "roughness",
                    kind,
                    "a roughness texture applies to a RoughConductor or RoughDielectric only",
                ));
            }
            let (lo, _) = t.range();
            if !(lo >= 0.0) {
                return Err(MaterialError::parameter(
                    NAME,
                    "roughness",
                    lo,
                    "the texture's values must be >= 0 for a roughness (microfacet alpha)",
                ));
            }
        }
        Ok(Self { material: r.material, reflectance: r.reflectance, roughness: r.roughness })
    }
}

impl From<Textured> for TexturedRepr {
    fn from(t: Textured) -> Self {
        Self { material: t.material, reflectance: t.reflectance, roughness: t.roughness }
    }
}

/// A material resolved at one surface point of a [`Textured`] one.
#[derive(Debug, Clone)]
pub enum Texel {
    /// A textured `Diffuse`.
    Diffuse(Diffuse),
    /// A textured `Plastic`.
    Plastic(Plastic),
    /// A textured `RoughConductor`.
    RoughConductor(RoughConductor),
    /// A textured `RoughDielectric`.
    RoughDielectric(RoughDielectric),
}

impl Texel {
    /// The texel as a material.
    pub fn as_material(&self) -> &(dyn Material + 'static) {
        match self {
            Texel::Diffuse(m) => m,
            Texel::Plastic(m) => m,
            Texel::RoughConductor(m) => m,
            Texel::RoughDielectric(m) => m,
        }
    }
}

/// The material at one surface point: the object's own, or a [`Texel`] of a textured one.
/// Dereferences to `dyn Material`.
#[derive(Debug, Clone)]
pub enum MaterialAt<'a> {
    /// The same material everywhere.
    Shared(&'a (dyn Material + 'static)),
    /// A textured material, resolved here (boxed: the common, untextured case stays two words).
    Texel(Box<Texel>),
}

impl<'a> MaterialAt<'a> {
    /// `material` at the surface point with texture coordinates `uv`.
    #[inline]
    pub fn new(material: &'a (dyn Material + 'static), uv: DVec2) -> Self {
        match material.texel(uv) {
            Some(t) => MaterialAt::Texel(Box::new(t)),
            None => MaterialAt::Shared(material),
        }
    }
}

impl Deref for MaterialAt<'_> {
    type Target = dyn Material;
    #[inline]
    fn deref(&self) -> &(dyn Material + 'static) {
        match self {
            MaterialAt::Shared(m) => *m,
            MaterialAt::Texel(t) => t.as_material(),
        }
    }
}

#[typetag::serde]
impl Material for Textured {
    fn scatter(&self, incoming: &Incoming, u: [f64; 3]) -> Option<Scattered> {
        self.material.as_material().scatter(incoming, u)
    }

    fn scatter_with(
        &self,
        incoming: &Incoming,
        u: [f64; 3],
        transport: Transport,
    ) -> Option<Scattered> {
        self.material.as_material().scatter_with(incoming, u, transport)
    }

    fn eval(&self, wi: glam::DVec3, wo: glam::DVec3, normal: glam::DVec3, lambda: f64) -> f64 {
        self.material.as_material().eval(wi, wo, normal, lambda)
    }

    fn scatter_bundle(
        &self,
        direction: glam::DVec3,
        normal: glam::DVec3,
        lambdas: &[f64],
        weights: &mut [f64],
        u: [f64; 3],
        transport: Transport,
    ) -> Option<BundleScattered> {
        self.material
            .as_material()
            .scatter_bundle(direction, normal, lambdas, weights, u, transport)
    }

    fn pdf(&self, wi: glam::DVec3, wo: glam::DVec3, normal: glam::DVec3, lambda: f64) -> f64 {
        self.material.as_material().pdf(wi, wo, normal, lambda)
    }

    fn is_specular(&self) -> bool {
        self.material.as_material().is_specular()
    }

    fn is_dispersive(&self) -> bool {
        self.material.as_material().is_dispersive()
    }

    fn texel(&self, uv: DVec2) -> Option<Texel> {
        let spectrum = |t: &Texture| -> (Reflectance, f64) {
            let rgb = t.rgb(uv);
            let mean = (rgb.iter().sum::<f64>() / 3.0).clamp(1e-4, 1.0);
            (Reflectance::from_sigmoid(RgbTable::get().spectrum(rgb)), mean)
        };
        let alpha = |t: &Texture| t.value(uv).max(0.0);
        Some(match &self.material {
            Base::Diffuse(_) => {
                Texel::Diffuse(Diffuse::new(spectrum(self.reflectance.as_ref()?).0))
            }
            Base::Plastic(m) => {
                let (r, mean) = spectrum(self.reflectance.as_ref()?);
                Texel::Plastic(m.with_base(r, mean))
            }
            Base::RoughConductor(m) => {
                Texel::RoughConductor(m.with_alpha(alpha(self.roughness.as_ref()?)))
            }
            Base::RoughDielectric(m) => {
                Texel::RoughDielectric(m.with_alpha(alpha(self.roughness.as_ref()?)))
            }
        })
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use spectrace_spectrum::rgb::srgb_under_d65;

    fn textured(json: &str) -> Result<Box<dyn Material>, String> {
        serde_json::from_str(json).map_err(|e| e.to_string())
    }

    /// A texel's reflectance has the texel's colour (RGB -> spectrum -> RGB under D65 within
    /// 1e-3, the table's guarantee), square by square.
    #[test]
    fn a_texel_has_its_texture_colour() {
        let t = textured(
            r#"{"type": "Textured", "material": {"type": "Diffuse", "reflectance": 0.5},
                "reflectance": {"type": "Checkerboard", "color0": [0.7, 0.3, 0.1], "color1": [0.05, 0.2, 0.6]}}"#,
        )
        .unwrap();
        for (uv, want) in [((0.1, 0.1), [0.7, 0.3, 0.1]), ((0.6, 0.1), [0.05, 0.2, 0.6])] {
            let texel = t.texel(DVec2::new(uv.0, uv.1)).unwrap();
            let Texel::Diffuse(d) = &texel else { panic!("{texel:?}") };
            let got = srgb_under_d65(&|l| d.reflectance.value(l));
            for c in 0..3 {
                assert!((got[c] - want[c]).abs() < 1e-3, "{uv:?}: {got:?} vs {want:?}");
            }
        }
        // Untextured materials resolve to themselves.
        let plain: Box<dyn Material> =
            serde_json::from_str(r#"{"type": "Diffuse", "reflectance": 0.5}"#).unwrap();
        assert!(plain.texel(DVec2::ZERO).is_none());
        assert!(matches!(MaterialAt::new(plain.as_ref(), DVec2::ZERO), MaterialAt::Shared(_)));
    }

    /// A roughness texture sets each texel's alpha: the rough lobe's density at the mirror
    /// direction is higher where the texture is smoother.
    #[test]
    fn a_roughness_texture_sets_the_alpha_per_texel() {
        let t = textured(
            r#"{"type": "Textured", "material": {"type": "RoughConductor", "metal": "Au", "roughness": 0.3},
                "roughness": {"type": "Checkerboard", "color0": 0.05, "color1": 0.5}}"#,
        )
        .unwrap();
        let wi = glam::DVec3::new(0.3, 0.0, 1.0).normalize();
        let wo = glam::DVec3::new(-0.3, 0.0, 1.0).normalize();
        let pdf = |u: f64| {
            t.texel(DVec2::new(u, 0.1)).unwrap().as_material().pdf(wi, wo, glam::DVec3::Z, 550.0)
        };
        assert!(pdf(0.1) > 10.0 * pdf(0.6), "{} vs {}", pdf(0.1), pdf(0.6));
    }

    #[test]
    fn textures_go_only_where_they_mean_something() {
        let e = textured(
            r#"{"type": "Textured", "material": {"type": "Diffuse", "reflectance": 0.5}}"#,
        )
        .unwrap_err();
        assert!(e.contains("give a `reflectance` or `roughness` texture"), "{e}");
        let e = textured(
            r#"{"type": "Textured", "material": {"type": "Diffuse", "reflectance": 0.5},
                "roughness": {"type": "Checkerboard"}}"#,
        )
        .unwrap_err();
        assert!(e.contains("RoughConductor or RoughDielectric only"), "{e}");
        let e = textured(
            r#"{"type": "Textured", "material": {"type": "Diffuse", "reflectance": 0.5},
                "reflectance": {"type": "Checkerboard", "color0": 1.5}}"#,
        )
        .unwrap_err();
        assert!(e.contains("must lie in [0, 1]"), "{e}");
        let e = textured(
            r#"{"type": "Textured", "material": {"type": "Mirror", "reflectance": 0.5},
                "reflectance": {"type": "Checkerboard"}}"#,
        )
        .unwrap_err();
        assert!(e.contains("Mirror"), "{e}");
    }
}
