//! [`Conductor`] (a smooth metal) and [`RoughConductor`] (a GGX microfacet metal), with the
//! exact Fresnel reflectance of a complex index `eta + i k` per wavelength.
//!
//! | field | unit | default | meaning |
//! |---|---|---|---|
//! | `metal` | a catalog symbol: `Ag Al Au Cr Cu Ni Pt Ti W` | — | measured `eta`, `k` of that metal (see [`metals`](crate::metals)) |
//! | `eta`, `k` | `{"nm": [...], "values": [...]}`, each value finite and `> 0` | — | the complex index as two tables (instead of `metal`; both required) |
//! | `roughness` | GGX alpha, finite, `>= 0` | required (RoughConductor only) | isotropic roughness; below [`SMOOTH_ALPHA`] (e.g. 0) the metal is smooth |
//! | `roughness_u`, `roughness_v` | GGX alphas, finite, `>= 0` | — | anisotropic roughness along the first / second tangent (instead of `roughness`; both required) |
//! | `distribution` | `"ggx"` or `"beckmann"` | `"ggx"` | the microfacet distribution (RoughConductor only; [`Distribution`]), with the roughness as its `alpha` |
//! | `specular_reflectance` | fraction in `[0, 1]`, a number or `{"nm": [...], "values": [...]}`, or `null` | `null` (= 1) | multiplies the Fresnel reflectance (not physical; a tint or a dimmer) |
//!
//! Exactly one of `metal` or (`eta` and `k`) must be given; for a `RoughConductor` exactly one
//! of `roughness` or (`roughness_u` and `roughness_v`).
//!
//! ```json
//! {"type": "Conductor", "metal": "Au"}
//! {"type": "RoughConductor", "metal": "Cu", "roughness": 0.2}
//! {"type": "RoughConductor", "metal": "Al", "roughness_u": 0.05, "roughness_v": 0.4}
//! {"type": "RoughConductor", "roughness": 0.1,
//!  "eta": {"nm": [400, 700], "values": [1.5, 0.2]}, "k": {"nm": [400, 700], "values": [1.9, 3.9]}}
//! ```
//!
//! **Smooth.** A [`Conductor`] reflects a beam about the normal (a delta lobe) with weight
//! `F(cos, lambda)`, the exact unpolarised reflectance [`fresnel_conductor`](crate::fresnel_conductor) of the index at the
//! beam's wavelength (times `specular_reflectance`). The surrounding medium is vacuum.
//!
//! **Rough.** A [`RoughConductor`] is the single-scattering microfacet model (Walter et al.
//! 2007) with the GGX distribution `D` (or Beckmann's, [`crate::Beckmann`], with `"distribution":
//! "beckmann"`; the albedo figures below are GGX's), Smith's height-correlated masking-shadowing `G` and the
//! same Fresnel term: `f(wi, wo) = D(h) G(wi, wo) F(wi . h) / (4 |cos_i| |cos_o|)`, `h` the
//! half vector. A scattered direction reflects a microfacet normal drawn from the *visible*
//! normals seen from `wi` (Heitz 2018, [`Ggx::sample_visible`]), so the weight is
//! `F G(wi, wo) / G1(wi)` (at most `F`) and the density `D_wi(h) / (4 wi . h)`. Directions that
//! this reflection sends below the surface are absorbed (`None`): `pdf` integrates to less than
//! 1 by exactly their fraction, and the single-scattering model loses that energy: the known
//! microfacet energy loss (light that would scatter again between microfacets). For a perfect
//! reflector the albedo measured at normal incidence is 0.997 / 0.877 / 0.592 / 0.307 for
//! alpha 0.05 / 0.3 / 0.6 / 1, and 0.953 / 0.848 / 0.779 / 0.668 at 80 degrees from the
//! normal; at normal incidence the facets steeper than 45 degrees, a fraction
//! `alpha^2 / (1 + alpha^2)`, reflect below the surface. `roughness` is the GGX alpha itself, not
//! remapped (Mitsuba 3's `alpha`, pbrt-v4's unremapped roughness). Below [`SMOOTH_ALPHA`] in
//! both directions a `RoughConductor` behaves exactly as the [`Conductor`] with the same index
//! (same results for the same uniforms, [`is_specular`](Material::is_specular) true).
//!
//! **Anisotropy and the tangent.** The [`Material`] API carries only the normal, so the first
//! tangent, along which `roughness_u` acts, is
//! `spectrace_sampling::Frame::from_normal(outward_normal).t()`: a fixed direction for a flat
//! shape, but not the texture direction `dp/du` of a mesh (which is not carried).
//!
//! **Two-sided.** A beam arriving from behind the normal sees the same metal: the local frame is
//! built from the outward normal and both directions are mirrored through the surface.
//!
//! Both override [`Material::scatter_bundle`] and [`Material::eval_bundle`]: the direction does
//! not depend on the wavelength, so it is sampled once and only the Fresnel term is evaluated
//! per wavelength (bit for bit what scattering each wavelength gives).

use std::sync::Arc;

use glam::DVec3;
use serde::{Deserialize, Serialize};
use spectrace_sampling::{Frame, clamp_uniform};
use spectrace_spectrum::Reflectance;

use crate::fresnel::reflect;
use crate::metals::ComplexIor;
use crate::microfacet::{Facets, Microfacet, alphas_from_keys, alphas_to_keys, check_alpha};
use crate::vectors::{facing, normalise};
use crate::{
    BundleScattered, Distribution, Ggx, Incoming, Material, MaterialError, ScatterKind, Scattered,
    Transport, scale_bundle,
};

/// The metal itself: its index and an optional reflectance factor (shared by both types).
#[derive(Debug, Clone, PartialEq)]
struct Surface {
    ior: ComplexIor,
    specular_reflectance: Option<Reflectance>,
}

impl Surface {
    /// `F(cos, lambda)` times the specular reflectance.
    #[inline]
    fn fresnel(&self, cos: f64, lambda: f64) -> f64 {
        let f = self.ior.reflectance(cos, lambda);
        match &self.specular_reflectance {
            Some(r) => f * r.value(lambda),
            None => f,
        }
    }

    /// The smooth reflection of a beam along `direction`: the mirror direction on the beam's
    /// own side and the cosine that the Fresnel term takes.
    #[inline]
    fn mirror(direction: DVec3, normal: DVec3) -> (DVec3, f64) {
        let n = facing(direction, normal);
        (reflect(direction, n), -direction.dot(n))
    }

    /// [`Material::scatter`] of the smooth metal.
    fn scatter_smooth(&self, incoming: &Incoming) -> Option<Scattered> {
        let (direction, cos) = Self::mirror(incoming.direction, incoming.normal);
        let weight = self.fresnel(cos, incoming.lambda);
        (weight > 0.0).then_some(Scattered {
            direction,
            weight,
            kind: ScatterKind::Specular,
            pdf: 0.0,
            eta: 1.0,
            transmission: false,
        })
    }

    /// [`Material::scatter_bundle`] of the smooth metal.
    fn scatter_bundle_smooth(
        &self,
        direction: DVec3,
        normal: DVec3,
        lambdas: &[f64],
        weights: &mut [f64],
    ) -> Option<BundleScattered> {
        let (out, cos) = Self::mirror(direction, normal);
        scale_bundle(lambdas, weights, |lambda| self.fresnel(cos, lambda)).then_some(
            BundleScattered {
                direction: out,
                kind: ScatterKind::Specular,
                pdf: 0.0,
                eta: 1.0,
                transmission: false,
            },
        )
    }
}

/// A smooth metal: Fresnel reflection of a complex index, two-sided, one delta lobe.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "ConductorRepr", into = "ConductorRepr")]
pub struct Conductor {
    surface: Surface,
}

impl Conductor {
    /// A smooth conductor with index `ior` and an optional factor on its reflectance.
    pub fn new(ior: ComplexIor, specular_reflectance: Option<Reflectance>) -> Self {
        Self { surface: Surface { ior, specular_reflectance } }
    }

    /// A smooth catalog metal, e.g. `Conductor::metal("Au")`.
    ///
    /// # Errors
    /// [`MaterialError::UnknownMetal`] (field `Conductor.metal`) listing the known symbols.
    pub fn metal(symbol: &str) -> Result<Self, MaterialError> {
        let ior = ComplexIor::metal(symbol).map_err(|e| e.in_material(CONDUCTOR))?;
        Ok(Self::new(ior, None))
    }

    /// The complex index of refraction.
    pub fn ior(&self) -> &ComplexIor {
        &self.surface.ior
    }

    /// The factor on the reflectance (`None`: 1).
    pub fn specular_reflectance(&self) -> Option<&Reflectance> {
        self.surface.specular_reflectance.as_ref()
    }

    /// The reflectance (the weight of a reflection) for light arriving at `cos_i` to the
    /// normal (either side) at `lambda` (nm): Fresnel times the specular reflectance.
    pub fn reflectance(&self, cos_i: f64, lambda: f64) -> f64 {
        self.surface.fresnel(cos_i, lambda)
    }
}

#[typetag::serde]
impl Material for Conductor {
    /// Mirror reflection on the beam's side, weight `F(cos, lambda)`; uses no uniforms.
    fn scatter(&self, incoming: &Incoming, _u: [f64; 3]) -> Option<Scattered> {
        self.surface.scatter_smooth(incoming)
    }

    /// One reflection for the bundle; each live wavelength's weight times its own Fresnel
    /// reflectance.
    fn scatter_bundle(
        &self,
        direction: DVec3,
        normal: DVec3,
        lambdas: &[f64],
        weights: &mut [f64],
        _u: [f64; 3],
        _transport: Transport,
    ) -> Option<BundleScattered> {
        self.surface.scatter_bundle_smooth(direction, normal, lambdas, weights)
    }

    fn eval(&self, _wi: DVec3, _wo: DVec3, _normal: DVec3, _lambda: f64) -> f64 {
        0.0
    }

    fn pdf(&self, _wi: DVec3, _wo: DVec3, _normal: DVec3, _lambda: f64) -> f64 {
        0.0
    }

    fn is_specular(&self) -> bool {
        true
    }

    fn is_dispersive(&self) -> bool {
        false
    }
}

/// A rough metal: GGX microfacets with Smith height-correlated shadowing, visible-normal
/// sampling and the Fresnel reflectance of a complex index; two-sided; optionally anisotropic.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "RoughConductorRepr", into = "RoughConductorRepr")]
pub struct RoughConductor {
    surface: Arc<Surface>,
    alpha_u: f64,
    alpha_v: f64,
    facets: Facets,
}

/// A direction the rough lobe sampled: where it goes, its density, the cosine the Fresnel term
/// takes (`wi . m`), and `G(wi, wo) / G1(wi)`.
struct RoughSample {
    direction: DVec3,
    pdf: f64,
    cos_m: f64,
    shadowing: f64,
}

/// `wi`, `wo` in the local frame of the outward `normal`, mirrored to the upper side when both
/// are below it; `None` unless both lie strictly on the same side.
#[inline]
fn local_pair(wi: DVec3, wo: DVec3, normal: DVec3) -> Option<(DVec3, DVec3)> {
    let frame = Frame::from_normal(normal);
    let (mut a, mut b) = (frame.to_local(wi), frame.to_local(wo));
    if !(a.z * b.z > 0.0) {
        return None;
    }
    if a.z < 0.0 {
        a.z = -a.z;
        b.z = -b.z;
    }
    Some((a, b))
}

/// The unit half vector of two upper-side directions and the cosine it makes with them.
#[inline]
fn half_vector(a: DVec3, b: DVec3) -> Option<(DVec3, f64)> {
    let h = a + b;
    let len = h.length();
    if !(len > 0.0 && len.is_finite()) {
        return None;
    }
    let h = h / len;
    let cos = a.dot(h);
    (cos > 0.0).then_some((h, cos))
}

impl RoughConductor {
    /// A rough conductor with GGX roughness `alpha_u` along the first tangent and `alpha_v`
    /// along the second (equal for an isotropic surface), index `ior` and an optional factor on
    /// the reflectance. Both alphas below [`SMOOTH_ALPHA`](crate::SMOOTH_ALPHA) give the smooth [`Conductor`].
    ///
    /// # Errors
    /// [`MaterialError::Parameter`] naming `roughness_u` or `roughness_v` unless finite and
    /// `>= 0`.
    pub fn new(
        ior: ComplexIor,
        alpha_u: f64,
        alpha_v: f64,
        specular_reflectance: Option<Reflectance>,
    ) -> Result<Self, MaterialError> {
        check_alpha(ROUGH_CONDUCTOR, "roughness_u", alpha_u)?;
        check_alpha(ROUGH_CONDUCTOR, "roughness_v", alpha_v)?;
        Ok(Self::unchecked(ior, alpha_u, alpha_v, specular_reflectance))
    }

    /// An isotropic rough conductor (`roughness` = `alpha`).
    ///
    /// # Errors
    /// [`MaterialError::Parameter`] naming `roughness` unless `alpha` is finite and `>= 0`.
    pub fn isotropic(
        ior: ComplexIor,
        alpha: f64,
        specular_reflectance: Option<Reflectance>,
    ) -> Result<Self, MaterialError> {
        check_alpha(ROUGH_CONDUCTOR, "roughness", alpha)?;
        Ok(Self::unchecked(ior, alpha, alpha, specular_reflectance))
    }

    /// An isotropic rough catalog metal, e.g. `RoughConductor::metal("Cu", 0.2)`.
    ///
    /// # Errors
    /// [`MaterialError::UnknownMetal`] (field `RoughConductor.metal`) or a bad `roughness`.
    pub fn metal(symbol: &str, alpha: f64) -> Result<Self, MaterialError> {
        let ior = ComplexIor::metal(symbol).map_err(|e| e.in_material(ROUGH_CONDUCTOR))?;
        Self::isotropic(ior, alpha, None)
    }

    fn unchecked(
        ior: ComplexIor,
        alpha_u: f64,
        alpha_v: f64,
        specular_reflectance: Option<Reflectance>,
    ) -> Self {
        Self {
            surface: Arc::new(Surface { ior, specular_reflectance }),
            alpha_u,
            alpha_v,
            facets: Facets::new(Distribution::Ggx, alpha_u, alpha_v),
        }
    }

    /// The same metal with the isotropic roughness `alpha` (a texel's; finite, `>= 0`). Shares
    /// the index tables, so it allocates nothing.
    pub(crate) fn with_alpha(&self, alpha: f64) -> Self {
        Self {
            surface: Arc::clone(&self.surface),
            alpha_u: alpha,
            alpha_v: alpha,
            facets: Facets::new(self.facets.kind(), alpha, alpha),
        }
    }

    /// The same conductor with the microfacet distribution `kind` (GGX unless asked).
    pub fn with_distribution(mut self, kind: Distribution) -> Self {
        self.facets = Facets::new(kind, self.alpha_u, self.alpha_v);
        self
    }

    /// The microfacet distribution.
    pub fn distribution(&self) -> Distribution {
        self.facets.kind()
    }

    /// The complex index of refraction.
    pub fn ior(&self) -> &ComplexIor {
        &self.surface.ior
    }

    /// The factor on the reflectance (`None`: 1).
    pub fn specular_reflectance(&self) -> Option<&Reflectance> {
        self.surface.specular_reflectance.as_ref()
    }

    /// The GGX roughness `(alpha_u, alpha_v)` along the first and second tangent, as given.
    pub fn roughness(&self) -> (f64, f64) {
        (self.alpha_u, self.alpha_v)
    }

    /// `true` when both alphas are below [`SMOOTH_ALPHA`](crate::SMOOTH_ALPHA): the surface is the smooth
    /// [`Conductor`].
    pub fn is_smooth(&self) -> bool {
        Ggx::is_smooth_alphas(self.alpha_u, self.alpha_v)
    }

    /// The Fresnel reflectance (times the specular reflectance) for light meeting a microfacet
    /// at `cos` to its normal, at `lambda` (nm).
    pub fn fresnel(&self, cos: f64, lambda: f64) -> f64 {
        self.surface.fresnel(cos, lambda)
    }

    /// Samples the rough lobe for a beam travelling along `direction` (uniforms `u[1]`,
    /// `u[2]`); `None` if the beam is tangent or the reflection leaves below the surface.
    fn sample(&self, direction: DVec3, normal: DVec3, u: [f64; 3]) -> Option<RoughSample> {
        let frame = Frame::from_normal(normal);
        let mut wi = frame.to_local(-direction);
        let flip = wi.z < 0.0;
        if flip {
            wi.z = -wi.z;
        }
        if !(wi.z > 0.0) {
            return None;
        }
        let m = self.facets.sample_visible(wi, [clamp_uniform(u[1]), clamp_uniform(u[2])]);
        let cos_m = wi.dot(m);
        let mut wo = normalise(2.0 * cos_m * m - wi);
        if !(cos_m > 0.0 && wo.z > 0.0) {
            return None;
        }
        let (lambda_i, lambda_o) = (self.facets.lambda(wi), self.facets.lambda(wo));
        let shadowing = (1.0 + lambda_i) / (1.0 + lambda_i + lambda_o);
        let pdf = self.facets.pdf_visible(wi, m) / (4.0 * cos_m);
        if !(shadowing > 0.0 && shadowing <= 1.0 && pdf > 0.0 && pdf.is_finite()) {
            return None;
        }
        if flip {
            wo.z = -wo.z;
        }
        Some(RoughSample { direction: normalise(frame.to_world(wo)), pdf, cos_m, shadowing })
    }

    /// `D G / (4 |cos_i| |cos_o|)` and the cosine for the Fresnel term, or `None` where the
    /// BSDF is 0 (opposite sides, tangent directions).
    fn geometry(&self, wi: DVec3, wo: DVec3, normal: DVec3) -> Option<(f64, f64)> {
        let (a, b) = local_pair(wi, wo, normal)?;
        let (h, cos) = half_vector(a, b)?;
        let value = self.facets.d(h) * self.facets.g(a, b) / (4.0 * a.z * b.z);
        (value > 0.0 && value.is_finite()).then_some((value, cos))
    }
}

#[typetag::serde]
impl Material for RoughConductor {
    /// A visible microfacet normal from `u[1]`, `u[2]` (`u[0]` is unused), the beam reflected
    /// about it; weight `F G / G1`. `None` when the reflection leaves below the surface.
    fn scatter(&self, incoming: &Incoming, u: [f64; 3]) -> Option<Scattered> {
        if self.is_smooth() {
            return self.surface.scatter_smooth(incoming);
        }
        let s = self.sample(incoming.direction, incoming.normal, u)?;
        let weight = self.surface.fresnel(s.cos_m, incoming.lambda) * s.shadowing;
        (weight > 0.0).then_some(Scattered {
            direction: s.direction,
            weight,
            kind: ScatterKind::Diffuse,
            pdf: s.pdf,
            eta: 1.0,
            transmission: false,
        })
    }

    /// One microfacet normal for the bundle; each live wavelength's weight times its own
    /// `F G / G1`.
    fn scatter_bundle(
        &self,
        direction: DVec3,
        normal: DVec3,
        lambdas: &[f64],
        weights: &mut [f64],
        u: [f64; 3],
        _transport: Transport,
    ) -> Option<BundleScattered> {
        if self.is_smooth() {
            return self.surface.scatter_bundle_smooth(direction, normal, lambdas, weights);
        }
        let Some(s) = self.sample(direction, normal, u) else {
            // Every live wavelength is absorbed, as scattering each would find.
            scale_bundle(lambdas, weights, |_| 0.0);
            return None;
        };
        scale_bundle(lambdas, weights, |lambda| self.surface.fresnel(s.cos_m, lambda) * s.shadowing)
            .then_some(BundleScattered {
                direction: s.direction,
                kind: ScatterKind::Diffuse,
                pdf: s.pdf,
                eta: 1.0,
                transmission: false,
            })
    }

    fn eval(&self, wi: DVec3, wo: DVec3, normal: DVec3, lambda: f64) -> f64 {
        if self.is_smooth() {
            return 0.0;
        }
        match self.geometry(wi, wo, normal) {
            Some((value, cos)) => value * self.surface.fresnel(cos, lambda),
            None => 0.0,
        }
    }

    /// The microfacet geometry once; the Fresnel term per wavelength.
    fn eval_bundle(
        &self,
        wi: DVec3,
        wo: DVec3,
        normal: DVec3,
        lambdas: &[f64],
        _transport: Transport,
        out: &mut [f64],
    ) {
        let geometry = if self.is_smooth() { None } else { self.geometry(wi, wo, normal) };
        for (o, &lambda) in out.iter_mut().zip(lambdas) {
            *o = match geometry {
                Some((value, cos)) => value * self.surface.fresnel(cos, lambda),
                None => 0.0,
            };
        }
    }

    fn pdf(&self, wi: DVec3, wo: DVec3, normal: DVec3, _lambda: f64) -> f64 {
        if self.is_smooth() {
            return 0.0;
        }
        let Some((a, b)) = local_pair(wi, wo, normal) else { return 0.0 };
        let Some((h, cos)) = half_vector(a, b) else { return 0.0 };
        let p = self.facets.pdf_visible(a, h) / (4.0 * cos);
        if p.is_finite() { p } else { 0.0 }
    }

    fn is_specular(&self) -> bool {
        self.is_smooth()
    }

    fn is_dispersive(&self) -> bool {
        false
    }
}

// ---------------------------------------------------------------------------------------------
// Validation and scene-file forms.

const CONDUCTOR: &str = "Conductor";
const ROUGH_CONDUCTOR: &str = "RoughConductor";

/// A missing or conflicting key.
fn key_error(material: &'static str, field: &str, value: &str, reason: &str) -> MaterialError {
    MaterialError::Parameter {
        material,
        field: field.to_owned(),
        value: value.to_owned(),
        reason: reason.to_owned(),
    }
}

/// An `eta` or `k` table as written: `{"nm": [...], "values": [...]}`.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct TableRepr {
    nm: Vec<f64>,
    values: Vec<f64>,
}

/// The index as written: `metal`, or `eta` and `k`.
fn ior_from(
    material: &'static str,
    metal: Option<String>,
    eta: Option<TableRepr>,
    k: Option<TableRepr>,
) -> Result<ComplexIor, MaterialError> {
    let either = "give either `metal` or the `eta` and `k` tables, not both";
    match (metal, eta, k) {
        (Some(m), None, None) => ComplexIor::metal(&m).map_err(|e| e.in_material(material)),
        (Some(m), _, _) => Err(key_error(material, "metal", &format!("{m:?}"), either)),
        (None, Some(eta), Some(k)) => ComplexIor::tables(&eta.nm, &eta.values, &k.nm, &k.values)
            .map_err(|e| e.in_material(material)),
        (None, Some(_), None) => Err(key_error(
            material,
            "k",
            "missing",
            "an `eta` table needs a `k` table ({\"nm\": [...], \"values\": [...]})",
        )),
        (None, None, Some(_)) => Err(key_error(
            material,
            "eta",
            "missing",
            "a `k` table needs an `eta` table ({\"nm\": [...], \"values\": [...]})",
        )),
        (None, None, None) => Err(key_error(
            material,
            "metal",
            "missing",
            &format!(
                "give a catalog `metal` ({}) or `eta` and `k` tables",
                crate::metals::known_metals()
            ),
        )),
    }
}

/// The index as it is written back.
fn ior_to(ior: &ComplexIor) -> (Option<String>, Option<TableRepr>, Option<TableRepr>) {
    if let Some(m) = ior.catalog_metal() {
        return (Some(m.symbol.to_owned()), None, None);
    }
    match ior.user_tables() {
        Some(((eta_nm, eta), (k_nm, k))) => (
            None,
            Some(TableRepr { nm: eta_nm.to_vec(), values: eta.to_vec() }),
            Some(TableRepr { nm: k_nm.to_vec(), values: k.to_vec() }),
        ),
        None => (None, None, None),
    }
}

/// Scene-file form of [`Conductor`].
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct ConductorRepr {
    #[serde(default)]
    metal: Option<String>,
    #[serde(default)]
    eta: Option<TableRepr>,
    #[serde(default)]
    k: Option<TableRepr>,
    #[serde(default)]
    specular_reflectance: Option<Reflectance>,
}

impl TryFrom<ConductorRepr> for Conductor {
    type Error = MaterialError;
    fn try_from(r: ConductorRepr) -> Result<Self, MaterialError> {
        let ior = ior_from(CONDUCTOR, r.metal, r.eta, r.k)?;
        Ok(Self::new(ior, r.specular_reflectance))
    }
}

impl From<Conductor> for ConductorRepr {
    fn from(c: Conductor) -> Self {
        let (metal, eta, k) = ior_to(&c.surface.ior);
        Self { metal, eta, k, specular_reflectance: c.surface.specular_reflectance }
    }
}

/// Scene-file form of [`RoughConductor`].
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct RoughConductorRepr {
    #[serde(default)]
    metal: Option<String>,
    #[serde(default)]
    eta: Option<TableRepr>,
    #[serde(default)]
    k: Option<TableRepr>,
    #[serde(default)]
    roughness: Option<f64>,
    #[serde(default)]
    roughness_u: Option<f64>,
    #[serde(default)]
    roughness_v: Option<f64>,
    #[serde(default)]
    specular_reflectance: Option<Reflectance>,
    #[serde(default)]
    distribution: Distribution,
}

impl TryFrom<RoughConductorRepr> for RoughConductor {
    type Error = MaterialError;
    fn try_from(r: RoughConductorRepr) -> Result<Self, MaterialError> {
        let ior = ior_from(ROUGH_CONDUCTOR, r.metal, r.eta, r.k)?;
        let spec = r.specular_reflectance;
        let (u, v) = alphas_from_keys(
            ROUGH_CONDUCTOR,
            r.roughness,
            r.roughness_u,
            r.roughness_v,
            "0 for a smooth metal",
        )?;
        Ok(Self::new(ior, u, v, spec)?.with_distribution(r.distribution))
    }
}

impl From<RoughConductor> for RoughConductorRepr {
    fn from(c: RoughConductor) -> Self {
        let (metal, eta, k) = ior_to(&c.surface.ior);
        let (roughness, roughness_u, roughness_v) = alphas_to_keys(c.alpha_u, c.alpha_v);
        Self {
            metal,
            eta,
            k,
            roughness,
            roughness_u,
            roughness_v,
            specular_reflectance: c.surface.specular_reflectance.clone(),
            distribution: c.facets.kind(),
        }
    }
}
