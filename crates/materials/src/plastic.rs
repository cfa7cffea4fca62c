//! [`Plastic`]: a dielectric coating (smooth, or rough with GGX or Beckmann microfacets) over a Lambertian base, the classic
//! "plastic" of Weidlich and Wilkie (2007) and Mitsuba's `plastic` / `roughplastic`.
//!
//! | field | unit | default | meaning |
//! |---|---|---|---|
//! | `reflectance` | fraction in `[0, 1]`, a number or `{"nm": [...], "values": [...]}` | required | the base's albedo `R(lambda)` (its colour) |
//! | `ior` | number or law, see [`Ior`] | `1.5` | index of refraction of the coating, `n(lambda)`; the outside is vacuum |
//! | `roughness` | microfacet alpha, finite, `>= 0` | `0` | roughness of the coating; below [`SMOOTH_ALPHA`] (e.g. 0) it is smooth (a delta reflection) |
//! | `distribution` | `"ggx"` or `"beckmann"` | `"ggx"` | the rough coating's microfacet distribution ([`Distribution`]; Mitsuba's `roughplastic` defaults to Beckmann) |
//!
//! ```json
//! {"type": "Plastic", "reflectance": {"nm": [400, 500, 600, 700], "values": [0.05, 0.1, 0.6, 0.8]}}
//! {"type": "Plastic", "reflectance": 0.3, "ior": 1.49, "roughness": 0.2}
//! ```
//!
//! **The model.** With `F(cos)` the exact unpolarised Fresnel reflectance of the coating seen
//! from outside, `S(cos)` the directional albedo of its specular lobe (`S = F` when smooth), and
//! `T = 2 integral_0^1 (1 - S(c)) c dc` the hemispherical transmission of the coating:
//!
//! * specular: a delta reflection with weight `F(cos_i)` (smooth), or the GGX microfacet lobe
//!   `F(wi.m) D(m) G / (4 cos_i cos_o)` (rough);
//! * diffuse: `f_d = (1 - S(cos_i)) (1 - S(cos_o)) R / (pi eta^2 (1 - R F_dr))`, with the
//!   coating's internal diffuse reflectance `F_dr = 1 - T / eta^2` (for a smooth coating this
//!   is the exact identity between internal and external diffuse Fresnel reflectance, by
//!   reciprocity), i.e. `f_d = (1 - S_i)(1 - S_o) R / (pi (eta^2 (1 - R) + R T))`.
//!
//! `f_d` is symmetric in `wi`, `wo`, so the material is reciprocal; its albedo is
//! `(1 - S_i) R T / (eta^2 (1 - R) + R T) <= 1 - S_i`, so energy is never created (a white base
//! and a smooth coating reflect exactly 1). With `ior` = 1 there is no coating: `F = S = 0`,
//! `T = 1` and `f_d = R / pi`, exactly the Lambertian [`Diffuse`](crate::Diffuse).
//!
//! **The rough coating.** The diffuse transmission uses the rough specular lobe's own albedo
//! `S(cos)`, tabulated once in the constructor (33 values of `cos`, each by a 48 x 48 quadrature
//! of the visible-normal sampler; linear interpolation), *not* the smooth Fresnel `1 - F(cos)`
//! of Mitsuba 0.6's `roughplastic` approximation: averaging `F` over tilted microfacets can
//! exceed `F(cos)` (by up to about 5e-4 near alpha 0.1, 45 degrees, ior 1.5), which with a white
//! base would reflect more than 1. With `1 - S` the bound above holds to the table's accuracy
//! (it is Mitsuba 3's approach). The diffuse light's internal reflections use the same
//! smooth-coating identity `F_dr = 1 - T / eta^2`.
//!
//! **Spectral coating.** With a dispersive `ior` the coating's `T` (and, when rough, `S`) are
//! tabulated every 20 nm over 360-830 nm and interpolated linearly in wavelength; the
//! directions never depend on the wavelength, so [`Material::is_dispersive`] is false.
//!
//! **Sampling.** The specular lobe is chosen with probability
//! `p_s = S_i / (S_i + (1 - S_i) R' T / (eta^2 (1 - R') + R' T))`, its albedo against the
//! diffuse term's for `R'` the mean of the base's reflectance values (Mitsuba's
//! `specular_sampling_weight` idea, made angle-dependent); otherwise the direction is
//! cosine-distributed. Smooth: the delta lobe returns [`ScatterKind::Specular`] with pdf 0 and
//! weight `F_i / p_s`; `pdf` and `eval` are the diffuse part only (`pdf` integrates to
//! `1 - p_s`). Rough: both lobes have a density and `pdf` is the mixture
//! `p_s pdf_spec + (1 - p_s) cos_o / pi`. **Two-sided**, like `Diffuse`: a beam from behind the
//! normal sees the same coating (the local `z` of both directions flipped); light never passes
//! through. The GGX frame is `Frame::from_normal(normal)` (isotropic here, so its tangent does
//! not matter).

use std::collections::HashMap;
use std::f64::consts::FRAC_1_PI;
use std::sync::{LazyLock, Mutex};

use std::sync::Arc;

use glam::DVec3;
use serde::{Deserialize, Serialize};
use spectrace_spectrum::Reflectance;

use spectrace_sampling::{Frame, clamp_uniform, sample_cosine_hemisphere};

use crate::fresnel::fresnel_dielectric;
use crate::ior::IorRepr;
use crate::microfacet::{Distribution, Facets, Microfacet, check_alpha};
use crate::vectors::normalise;
use crate::{
    BundleScattered, Ggx, Incoming, Ior, Material, MaterialError, ScatterKind, Scattered,
    Transport, VALID_MAX_NM, VALID_MIN_NM,
};

const NAME: &str = "Plastic";

/// Intervals of the `cos theta` table of the rough specular albedo.
const COS_STEPS: usize = 32;
/// Quadrature points per axis for one entry of that table.
const QUAD: usize = 48;
/// Wavelength step (nm) of the tables of a dispersive coating.
const LAMBDA_STEP: f64 = 20.0;

/// A dielectric coating over a Lambertian base (plastic, varnished paint), two-sided.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "PlasticRepr", into = "PlasticRepr")]
pub struct Plastic {
    reflectance: Reflectance,
    ior: Arc<Ior>,
    alpha: f64,
    /// The coating's microfacet distribution (GGX unless asked).
    distribution: Distribution,
    /// The mean of the base's reflectance values (for the lobe choice).
    mean_reflectance: f64,
    coating: Arc<[Node]>,
}

/// The coating's precomputed quantities at one wavelength.
#[derive(Debug, Clone, PartialEq)]
struct Node {
    lambda: f64,
    /// Hemispherical transmission `T`.
    transmission: f64,
    /// Rough: `S` at `cos = k / COS_STEPS`; empty when smooth.
    albedo: Vec<f64>,
}

/// Scene-file form of [`Plastic`].
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct PlasticRepr {
    reflectance: Reflectance,
    #[serde(default = "default_ior")]
    ior: IorRepr,
    #[serde(default)]
    roughness: f64,
    #[serde(default)]
    distribution: Distribution,
}

fn default_ior() -> IorRepr {
    IorRepr::Constant(1.5)
}

impl TryFrom<PlasticRepr> for Plastic {
    type Error = MaterialError;
    fn try_from(r: PlasticRepr) -> Result<Self, MaterialError> {
        let ior = Ior::try_from(r.ior).map_err(|e| e.within(NAME, "ior"))?;
        Self::with_facets(r.reflectance, ior, r.roughness, r.distribution)
    }
}

impl From<Plastic> for PlasticRepr {
    fn from(p: Plastic) -> Self {
        Self {
            reflectance: p.reflectance,
            ior: (*p.ior).clone().into(),
            roughness: p.alpha,
            distribution: p.distribution,
        }
    }
}

/// A sampled direction, local, beam side up.
struct Sample {
    wo: DVec3,
    specular_delta: bool,
    /// The probability of the specular lobe.
    p_s: f64,
    pdf: f64,
}

impl Plastic {
    /// Plastic with base albedo `reflectance`, coating index `ior` and GGX `roughness`
    /// (0: a smooth coating).
    ///
    /// # Errors
    /// [`MaterialError::Parameter`] naming `roughness` unless it is finite and `>= 0`. (An
    /// [`Ior`] is valid by construction: finite and `>= 1`.)
    pub fn new(reflectance: Reflectance, ior: Ior, roughness: f64) -> Result<Self, MaterialError> {
        Self::with_facets(reflectance, ior, roughness, Distribution::Ggx)
    }

    /// As [`Plastic::new`], with the coating's microfacet distribution `kind` (GGX or
    /// Beckmann; the roughness is its alpha either way).
    ///
    /// # Errors
    /// As [`Plastic::new`].
    pub fn with_facets(
        reflectance: Reflectance,
        ior: Ior,
        roughness: f64,
        kind: Distribution,
    ) -> Result<Self, MaterialError> {
        check_alpha(NAME, "roughness", roughness)?;
        let smooth = Ggx::is_smooth_alphas(roughness, roughness);
        let lambdas: Vec<f64> = if ior.is_dispersive() {
            let steps = ((VALID_MAX_NM - VALID_MIN_NM) / LAMBDA_STEP).ceil() as usize;
            (0..=steps).map(|k| (VALID_MIN_NM + k as f64 * LAMBDA_STEP).min(VALID_MAX_NM)).collect()
        } else {
            vec![0.5 * (VALID_MIN_NM + VALID_MAX_NM)]
        };
        let coating: Vec<Node> = lambdas
            .into_iter()
            .map(|lambda| {
                Node::new(
                    lambda,
                    ior.n(lambda),
                    (!smooth).then(|| Facets::new(kind, roughness, roughness)),
                )
            })
            .collect();
        let values = reflectance_values(&reflectance);
        let mean_reflectance = values.iter().sum::<f64>() / values.len().max(1) as f64;
        Ok(Self {
            reflectance,
            ior: Arc::new(ior),
            alpha: roughness,
            distribution: kind,
            mean_reflectance,
            coating: coating.into(),
        })
    }

    /// The same coating over the base albedo `reflectance` (a texel's), choosing the diffuse
    /// lobe by `mean` (any value in `(0, 1]` keeps the estimate exact; the base's mean is best).
    /// Shares the coating's tables and index, so it allocates nothing.
    pub(crate) fn with_base(&self, reflectance: Reflectance, mean: f64) -> Self {
        Self {
            reflectance,
            ior: Arc::clone(&self.ior),
            alpha: self.alpha,
            distribution: self.distribution,
            mean_reflectance: mean,
            coating: Arc::clone(&self.coating),
        }
    }

    /// A smooth plastic of base albedo `reflectance` and the default coating (ior 1.5).
    ///
    /// # Errors
    /// None in practice (kept fallible like the other constructors).
    pub fn smooth(reflectance: Reflectance) -> Result<Self, MaterialError> {
        let ior = Ior::constant(1.5).map_err(|e| e.within(NAME, "ior"))?;
        Self::new(reflectance, ior, 0.0)
    }

    /// The base's albedo.
    pub fn reflectance(&self) -> &Reflectance {
        &self.reflectance
    }

    /// The coating's index of refraction.
    pub fn ior(&self) -> &Ior {
        &self.ior
    }

    /// The coating's GGX roughness (alpha).
    pub fn roughness(&self) -> f64 {
        self.alpha
    }

    /// `true` for a smooth coating (roughness below [`SMOOTH_ALPHA`](crate::SMOOTH_ALPHA)).
    pub fn is_smooth(&self) -> bool {
        Ggx::is_smooth_alphas(self.alpha, self.alpha)
    }

    /// The coating's microfacet distribution.
    pub fn distribution(&self) -> Distribution {
        self.distribution
    }

    fn facets(&self) -> Facets {
        Facets::new(self.distribution, self.alpha, self.alpha)
    }

    /// The two table nodes around `lambda` and the weight of the second.
    fn nodes(&self, lambda: f64) -> (&Node, &Node, f64) {
        let first = &self.coating[0];
        let last = &self.coating[self.coating.len() - 1];
        if self.coating.len() == 1 || !(lambda > first.lambda) {
            return (first, first, 0.0);
        }
        if lambda >= last.lambda {
            return (last, last, 0.0);
        }
        let i = self.coating.partition_point(|n| n.lambda <= lambda).max(1) - 1;
        let (a, b) = (&self.coating[i], &self.coating[i + 1]);
        (a, b, (lambda - a.lambda) / (b.lambda - a.lambda))
    }

    /// The coating's hemispherical transmission `T` at `lambda`.
    fn transmission(&self, lambda: f64) -> f64 {
        let (a, b, t) = self.nodes(lambda);
        a.transmission * (1.0 - t) + b.transmission * t
    }

    /// The specular lobe's directional albedo `S(cos)` at `lambda` (`F` when smooth).
    fn specular_albedo(&self, cos: f64, eta: f64, lambda: f64) -> f64 {
        if self.is_smooth() {
            return fresnel_dielectric(cos, eta);
        }
        let (a, b, t) = self.nodes(lambda);
        a.albedo_at(cos) * (1.0 - t) + b.albedo_at(cos) * t
    }

    /// The internal-reflection denominator `eta^2 (1 - R) + R T` of the diffuse term.
    fn diffuse_denominator(eta: f64, r: f64, transmission: f64) -> f64 {
        eta * eta * (1.0 - r) + r * transmission
    }

    /// The probability of choosing the specular lobe for a beam at local `cos_i`.
    fn specular_probability(&self, cos_i: f64, lambda: f64) -> f64 {
        let eta = self.ior.n(lambda);
        let s = self.specular_albedo(cos_i, eta, lambda);
        let r = self.mean_reflectance;
        let t = self.transmission(lambda);
        let den = Self::diffuse_denominator(eta, r, t);
        let d = if den > 0.0 { (1.0 - s) * r * t / den } else { 0.0 };
        let total = s + d;
        if total > 0.0 { (s / total).clamp(0.0, 1.0) } else { 0.0 }
    }

    /// The BSDF for local `wi`, `wo` both with `z > 0`: the rough specular lobe (if any) plus
    /// the diffuse term.
    fn f_local(&self, wi: DVec3, wo: DVec3, lambda: f64) -> f64 {
        if !(wi.z > 0.0 && wo.z > 0.0) {
            return 0.0;
        }
        let eta = self.ior.n(lambda);
        let r = self.reflectance.value(lambda);
        let t = self.transmission(lambda);
        let den = Self::diffuse_denominator(eta, r, t);
        let mut f = 0.0;
        if r > 0.0 && den > 0.0 {
            let si = self.specular_albedo(wi.z, eta, lambda);
            let so = self.specular_albedo(wo.z, eta, lambda);
            f += (1.0 - si) * (1.0 - so) * r * FRAC_1_PI / den;
        }
        if !self.is_smooth() {
            f += self.specular_f(wi, wo, eta);
        }
        if f.is_finite() { f.max(0.0) } else { 0.0 }
    }

    /// The rough specular lobe `F(wi.m) D(m) G / (4 cos_i cos_o)`.
    fn specular_f(&self, wi: DVec3, wo: DVec3, eta: f64) -> f64 {
        let h = wi + wo;
        let len2 = h.length_squared();
        if !(len2 > 0.0) {
            return 0.0;
        }
        let m = h / len2.sqrt();
        let ggx = self.facets();
        let v = fresnel_dielectric(wi.dot(m), eta) * ggx.d(m) * ggx.g(wo, wi) / (4.0 * wi.z * wo.z);
        if v.is_finite() { v } else { 0.0 }
    }

    /// The density of the rough specular lobe's sampler (visible normals, reflected).
    fn specular_pdf(&self, wi: DVec3, wo: DVec3) -> f64 {
        let h = wi + wo;
        let len2 = h.length_squared();
        if !(len2 > 0.0) {
            return 0.0;
        }
        let m = h / len2.sqrt();
        let cos = wi.dot(m);
        if !(cos > 0.0) {
            return 0.0;
        }
        let p = self.facets().pdf_visible(wi, m) / (4.0 * cos);
        if p.is_finite() { p } else { 0.0 }
    }

    /// The density of `scatter` for local `wi`, `wo` (both `z > 0`), with specular
    /// probability `p_s`: the non-delta part only.
    fn pdf_local(&self, wi: DVec3, wo: DVec3, p_s: f64) -> f64 {
        if !(wi.z > 0.0 && wo.z > 0.0) {
            return 0.0;
        }
        let diffuse = (1.0 - p_s) * wo.z * FRAC_1_PI;
        if self.is_smooth() { diffuse } else { p_s * self.specular_pdf(wi, wo) + diffuse }
    }

    /// Samples a direction for a beam from local `wi` (`wi.z > 0`), the lobe chosen at `lambda`.
    fn sample_local(&self, wi: DVec3, lambda: f64, u: [f64; 3]) -> Option<Sample> {
        let p_s = self.specular_probability(wi.z, lambda);
        let specular = clamp_uniform(u[0]) < p_s;
        if specular && self.is_smooth() {
            let wo = DVec3::new(-wi.x, -wi.y, wi.z);
            return Some(Sample { wo, specular_delta: true, p_s, pdf: 0.0 });
        }
        let uv = [clamp_uniform(u[1]), clamp_uniform(u[2])];
        let wo = if specular {
            let m = self.facets().sample_visible(wi, uv);
            normalise(2.0 * wi.dot(m) * m - wi)
        } else {
            sample_cosine_hemisphere(uv)
        };
        if !(wo.z > 0.0) {
            return None; // a microfacet reflection below the surface: absorbed
        }
        let pdf = self.pdf_local(wi, wo, p_s);
        (pdf > 0.0 && pdf.is_finite()).then_some(Sample { wo, specular_delta: false, p_s, pdf })
    }

    /// The weight of `sample` at `lambda`.
    fn weight(&self, wi: DVec3, sample: &Sample, lambda: f64) -> f64 {
        let w = if sample.specular_delta {
            fresnel_dielectric(wi.z, self.ior.n(lambda)) / sample.p_s
        } else {
            self.f_local(wi, sample.wo, lambda) * sample.wo.z / sample.pdf
        };
        if w.is_finite() { w.max(0.0) } else { 0.0 }
    }

    /// The frame, whether the side was flipped, and the local `wi` (turned up) for a beam along
    /// world `direction`; `None` for a tangent beam.
    fn local_incoming(direction: DVec3, normal: DVec3) -> Option<(Frame, bool, DVec3)> {
        let frame = Frame::from_normal(normal);
        let mut wi = frame.to_local(-direction);
        if wi.z == 0.0 || !wi.is_finite() {
            return None;
        }
        let flip = wi.z < 0.0;
        if flip {
            wi.z = -wi.z;
        }
        Some((frame, flip, normalise(wi)))
    }

    /// Local `wi`, `wo` turned so that `wi.z > 0`; `None` unless strictly on the same side.
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

    /// The world direction of a local sample.
    fn to_world(frame: &Frame, flip: bool, mut wo: DVec3) -> DVec3 {
        if flip {
            wo.z = -wo.z;
        }
        normalise(frame.to_world(wo))
    }

    /// The fraction `F_dr` of diffuse light inside the coating that it reflects back to the
    /// base at `lambda`: `1 - T / n^2`, `T` the coating's hemispherical transmission from
    /// outside (`(1 - R F_dr)` is the internal-reflection series' denominator of the diffuse
    /// term). Mitsuba's linear plastic (`nonlinear` false) divides by `1 - F_dr` instead: an
    /// importer matches it with the base albedo `R / (1 - F_dr + R F_dr)`.
    pub fn internal_diffuse_reflectance(&self, lambda: f64) -> f64 {
        let n = self.ior.n(lambda);
        1.0 - self.transmission(lambda) / (n * n)
    }

    /// The specular lobe's directional albedo `S(cos)` of this coating at `lambda`, the
    /// quantity the diffuse transmission `1 - S` uses (the exact Fresnel `F(cos)` when smooth,
    /// the tabulated microfacet albedo when rough).
    pub fn coating_albedo(&self, cos: f64, lambda: f64) -> f64 {
        self.specular_albedo(cos.abs().min(1.0), self.ior.n(lambda), lambda)
    }
}

impl Node {
    /// The tables at `lambda` for index `eta`, with the rough lobe `ggx` (`None`: smooth).
    fn new(lambda: f64, eta: f64, ggx: Option<Facets>) -> Self {
        match ggx {
            None => {
                // T = 2 integral_0^1 (1 - F(c)) c dc, midpoint rule.
                let n = 4096;
                let sum: f64 = (0..n)
                    .map(|k| {
                        let c = (k as f64 + 0.5) / n as f64;
                        (1.0 - fresnel_dielectric(c, eta)) * c
                    })
                    .sum();
                Self { lambda, transmission: 2.0 * sum / n as f64, albedo: Vec::new() }
            }
            Some(ggx) => {
                let albedo = rough_albedo_table(&ggx, eta);
                // T = 2 integral (1 - S(c)) c dc, exact for the piecewise-linear S.
                let h = 1.0 / COS_STEPS as f64;
                let mut integral = 0.0;
                for k in 0..COS_STEPS {
                    let (c0, c1) = (k as f64 * h, (k + 1) as f64 * h);
                    let (s0, s1) = (1.0 - albedo[k], 1.0 - albedo[k + 1]);
                    integral += h / 6.0 * (s0 * (2.0 * c0 + c1) + s1 * (c0 + 2.0 * c1));
                }
                Self { lambda, transmission: 2.0 * integral, albedo }
            }
        }
    }

    /// The tabulated `S(cos)`, linear between the nodes.
    fn albedo_at(&self, cos: f64) -> f64 {
        let x = cos.clamp(0.0, 1.0) * COS_STEPS as f64;
        let k = (x.floor() as usize).min(COS_STEPS - 1);
        let t = x - k as f64;
        match (self.albedo.get(k), self.albedo.get(k + 1)) {
            (Some(a), Some(b)) => a * (1.0 - t) + b * t,
            _ => 0.0,
        }
    }
}

/// Most `S(cos)` tables kept by [`rough_albedo_table`] (34 numbers each).
const ALBEDO_CACHE_MAX: usize = 1 << 16;

/// `S` at `cos = k / COS_STEPS` for the rough coating `ggx` of index `eta`, computed once per
/// `(alpha, eta)` in a process: a scene whose objects share a plastic (each object has its own
/// material in a scene file) builds its table once, not once per object. The cache stops
/// growing at [`ALBEDO_CACHE_MAX`] entries (tables are then computed each time).
fn rough_albedo_table(ggx: &Facets, eta: f64) -> Vec<f64> {
    type Key = (Distribution, u64, u64, u64);
    static CACHE: LazyLock<Mutex<HashMap<Key, Vec<f64>>>> = LazyLock::new(Default::default);
    let (ax, ay) = ggx.alphas();
    let key = (ggx.kind(), ax.to_bits(), ay.to_bits(), eta.to_bits());
    if let Some(table) = CACHE.lock().ok().and_then(|c| c.get(&key).cloned()) {
        return table;
    }
    let table: Vec<f64> = (0..=COS_STEPS)
        .map(|k| rough_albedo(ggx, eta, (k as f64 / COS_STEPS as f64).max(1e-3)))
        .collect();
    if let Ok(mut cache) = CACHE.lock()
        && cache.len() < ALBEDO_CACHE_MAX
    {
        cache.insert(key, table.clone());
    }
    table
}

/// The directional albedo of a rough dielectric's reflection lobe, `integral F D G / (4 cos_i)
/// dwo` over the upper hemisphere, for a beam at `cos_i`: the mean of `F(wi.m) G / G1(wi)` over
/// the visible normals (a midpoint grid of the sampler's uniforms).
fn rough_albedo(ggx: &Facets, eta: f64, cos_i: f64) -> f64 {
    let sin_i = (1.0 - cos_i * cos_i).max(0.0).sqrt();
    let wi = DVec3::new(sin_i, 0.0, cos_i);
    let g1 = ggx.g1(wi);
    if !(g1 > 0.0) {
        return 0.0;
    }
    let mut sum = 0.0;
    for a in 0..QUAD {
        for b in 0..QUAD {
            let u = [(a as f64 + 0.5) / QUAD as f64, (b as f64 + 0.5) / QUAD as f64];
            let m = ggx.sample_visible(wi, u);
            let cos = wi.dot(m);
            let wo = 2.0 * cos * m - wi;
            if wo.z > 0.0 && cos > 0.0 {
                sum += fresnel_dielectric(cos, eta) * ggx.g(wo, wi) / g1;
            }
        }
    }
    let s = sum / (QUAD * QUAD) as f64;
    if s.is_finite() { s.clamp(0.0, 1.0) } else { 0.0 }
}

/// The values of a reflectance spectrum, sampled every 10 nm over 360-830 nm (its mean is the
/// lobe-choice estimate).
fn reflectance_values(r: &Reflectance) -> Vec<f64> {
    let steps = ((VALID_MAX_NM - VALID_MIN_NM) / 10.0) as usize;
    (0..=steps).map(|k| r.value(VALID_MIN_NM + 10.0 * k as f64)).collect()
}

#[typetag::serde]
impl Material for Plastic {
    /// The coating's reflection (probability `p_s`, from `u[0]`) or the diffuse base
    /// (cosine-distributed from `u[1]`, `u[2]`); two-sided.
    fn scatter(&self, incoming: &Incoming, u: [f64; 3]) -> Option<Scattered> {
        let (frame, flip, wi) = Self::local_incoming(incoming.direction, incoming.normal)?;
        let s = self.sample_local(wi, incoming.lambda, u)?;
        let weight = self.weight(wi, &s, incoming.lambda);
        if !(weight > 0.0) {
            return None;
        }
        Some(Scattered {
            direction: Self::to_world(&frame, flip, s.wo),
            weight,
            kind: if s.specular_delta { ScatterKind::Specular } else { ScatterKind::Diffuse },
            pdf: s.pdf,
            eta: 1.0,
            transmission: false,
        })
    }

    /// One lobe choice and direction for the bundle (made at the first live wavelength); each
    /// live wavelength's weight is its own `f |cos| / pdf` (or `F / p_s` for the delta lobe).
    fn scatter_bundle(
        &self,
        direction: DVec3,
        normal: DVec3,
        lambdas: &[f64],
        weights: &mut [f64],
        u: [f64; 3],
        _transport: Transport,
    ) -> Option<BundleScattered> {
        let first = weights.iter().zip(lambdas).find(|(w, _)| **w > 0.0).map(|(_, &l)| l)?;
        let sampled = Self::local_incoming(direction, normal).and_then(|(frame, flip, wi)| {
            Some((frame, flip, wi, self.sample_local(wi, first, u)?))
        });
        let Some((frame, flip, wi, s)) = sampled else {
            crate::scale_bundle(lambdas, weights, |_| 0.0);
            return None;
        };
        let any = crate::scale_bundle(lambdas, weights, |lambda| self.weight(wi, &s, lambda));
        any.then_some(BundleScattered {
            direction: Self::to_world(&frame, flip, s.wo),
            kind: if s.specular_delta { ScatterKind::Specular } else { ScatterKind::Diffuse },
            pdf: s.pdf,
            eta: 1.0,
            transmission: false,
        })
    }

    /// The non-delta part: the diffuse term, plus the microfacet lobe when rough.
    fn eval(&self, wi: DVec3, wo: DVec3, normal: DVec3, lambda: f64) -> f64 {
        Self::local_pair(wi, wo, normal).map_or(0.0, |(a, b)| self.f_local(a, b, lambda))
    }

    fn pdf(&self, wi: DVec3, wo: DVec3, normal: DVec3, lambda: f64) -> f64 {
        Self::local_pair(wi, wo, normal)
            .map_or(0.0, |(a, b)| self.pdf_local(a, b, self.specular_probability(a.z, lambda)))
    }

    fn is_specular(&self) -> bool {
        false
    }

    fn is_dispersive(&self) -> bool {
        false
    }
}
