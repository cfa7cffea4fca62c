//! [`RoughDielectric`]: a rough boundary of a transparent medium (frosted glass): GGX microfacet
//! reflection and transmission (Walter et al., "Microfacet models for refraction through rough
//! surfaces", EGSR 2007), with the same, possibly dispersive, index of refraction as
//! [`Dielectric`].
//!
//! | field | unit | default | meaning |
//! |---|---|---|---|
//! | `ior` | number or law, see [`Ior`] | required | index of refraction of the inside, `n(lambda)`; the outside is vacuum (n = 1) |
//! | `roughness` | GGX alpha, finite, `>= 0` | required (or the pair below) | isotropic roughness; below [`SMOOTH_ALPHA`] (e.g. 0) the boundary is exactly the smooth [`Dielectric`] |
//! | `roughness_u`, `roughness_v` | GGX alphas, finite, `>= 0` | — | anisotropic roughness along the first / second tangent (instead of `roughness`; both required) |
//! | `distribution` | `"ggx"` or `"beckmann"` | `"ggx"` | the microfacet distribution ([`Distribution`]), with the roughness as its `alpha` |
//! | `transmittance` | fraction in `[0, 1]`, a number or `{"nm": [...], "values": [...]}`, or `null` | `null` (= 1) | multiplies every refraction (a surface tint), as for [`Dielectric`] |
//!
//! ```json
//! {"type": "RoughDielectric", "ior": {"glass": "SF11"}, "roughness": 0.1}
//! {"type": "RoughDielectric", "ior": 1.5, "roughness_u": 0.05, "roughness_v": 0.3, "transmittance": 0.95}
//! ```
//!
//! **Geometry.** The outside is the side [`Incoming::normal`] points to, as for [`Dielectric`].
//! The shading frame is built from that outward normal, `Frame::from_normal(normal)`; its first
//! tangent `Frame::t()` is the direction `roughness_u` acts along (the Material API carries no
//! surface tangent, so on a flat shape it is a fixed direction; geometry tangents are not used).
//! A beam from inside is handled in the same frame with the local `z` of both directions flipped.
//!
//! **Sampling.** A microfacet normal `m` is drawn from the GGX distribution of normals visible
//! from the incoming side (Heitz 2018, [`Ggx::sample_visible`]); the beam is reflected about `m`
//! with probability `F(wi . m)` (exact unpolarised Fresnel) and refracted through `m` otherwise
//! (total internal reflection on `m` has `F = 1`). A direction that ends on the wrong side of the
//! macro-surface is absorbed (`None`): that, with Smith's single-scattering `G`, is the known
//! energy loss of microfacet models at high roughness (no multiple scattering between
//! microfacets). The weight of every sample is `G(wi, wo) / G1(wi)` (times the transmittance on
//! refraction, and `(n_i / n_t)^2` for [`Transport::Radiance`]).
//!
//! **The BSDF and its transports.** `eval(wi, wo)` follows the trait's convention: light arrives
//! from `wi` and leaves towards `wo`. With `n_i`, `n_o` the indices on the sides of `wi` and `wo`,
//! `m` the (generalised) half vector `n_i wi + n_o wo` (or `wi + wo` for reflection) turned to the
//! outside, and `F = F(wi . m)`:
//!
//! * reflection: `f = F D(m) G / (4 |wi.n| |wo.n|)`;
//! * transmission: `f = T(lambda) (1 - F) D(m) G |wi.m| |wo.m| n_o^2 / (|wi.n| |wo.n| (n_i wi.m + n_o wo.m)^2)`.
//!
//! This is the physical (radiance) BSDF: `integral f |wo.n| dwo <= 1` (a beam's power is not
//! created) and it obeys the generalised reciprocity `f(wi -> wo) / n_o^2 = f(wo -> wi) / n_i^2`.
//! Because both [`Transport`]s give `eval_with` its arguments in this same light order (`wi` the
//! side the light comes from; the path tracer and BDPT pass the light-sample side as `wi`, the
//! light tracer the beam's), **`eval_with` returns the same value for both transports**: the
//! adjoint `f*(a, b) = f(b, a)` is what a caller passing the *path* order (first the side the path
//! arrived from, as [`Material::pdf`] takes it) would need. Accordingly [`Material::scatter_with`]
//! satisfies, for a beam arriving from `wi` (direction `-wi`) and leaving along `wo` with density
//! `pdf(wi, wo)`:
//!
//! * [`Transport::Importance`] (the beam carries flux from a light): `weight = eval(wi, wo) |wo.n| / pdf(wi, wo)`;
//! * [`Transport::Radiance`] (the path comes from the camera, light flows back along it):
//!   `weight = eval(wo, wi) |wo.n| / pdf(wi, wo)`, which is the Importance weight times
//!   `(n_i / n_t)^2` on refraction (path from `n_i` into `n_t`), exactly as [`Dielectric`] does.
//!
//! An index of exactly 1 makes the boundary invisible: the beam passes straight through (a delta
//! lobe, [`ScatterKind::Specular`]) and there is no reflection.

use std::sync::Arc;

use glam::DVec3;
use serde::{Deserialize, Serialize};
use spectrace_spectrum::Transmittance;

use spectrace_sampling::{Frame, clamp_uniform};

use crate::fresnel::{fresnel_dielectric, refract};
use crate::ior::IorRepr;
use crate::microfacet::{Facets, Microfacet, alphas_from_keys, alphas_to_keys, check_alpha};
use crate::vectors::normalise;
use crate::{
    BundleScattered, Dielectric, Distribution, Ggx, Incoming, Ior, Material, MaterialError,
    ScatterKind, Scattered, Transport, scale_bundle, scatter_each,
};

const NAME: &str = "RoughDielectric";

/// A rough dielectric boundary (frosted glass): GGX microfacet reflection and refraction with a
/// possibly dispersive index of refraction.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "RoughDielectricRepr", into = "RoughDielectricRepr")]
pub struct RoughDielectric {
    /// The index and transmittance, and the smooth limit used below [`SMOOTH_ALPHA`].
    smooth: Arc<Dielectric>,
    alpha_u: f64,
    alpha_v: f64,
    distribution: Distribution,
}

/// Scene-file form of [`RoughDielectric`].
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct RoughDielectricRepr {
    ior: IorRepr,
    #[serde(default)]
    roughness: Option<f64>,
    #[serde(default)]
    roughness_u: Option<f64>,
    #[serde(default)]
    roughness_v: Option<f64>,
    #[serde(default)]
    transmittance: Option<Transmittance>,
    #[serde(default)]
    distribution: Distribution,
}

impl TryFrom<RoughDielectricRepr> for RoughDielectric {
    type Error = MaterialError;
    fn try_from(r: RoughDielectricRepr) -> Result<Self, MaterialError> {
        let ior = Ior::try_from(r.ior).map_err(|e| e.within(NAME, "ior"))?;
        let (u, v) = alphas_from_keys(
            NAME,
            r.roughness,
            r.roughness_u,
            r.roughness_v,
            "0 for smooth glass",
        )?;
        Ok(Self::new(ior, u, v, r.transmittance)?.with_distribution(r.distribution))
    }
}

impl From<RoughDielectric> for RoughDielectricRepr {
    fn from(d: RoughDielectric) -> Self {
        let (roughness, roughness_u, roughness_v) = alphas_to_keys(d.alpha_u, d.alpha_v);
        Self {
            ior: d.smooth.ior().clone().into(),
            roughness,
            roughness_u,
            roughness_v,
            transmittance: d.smooth.transmittance().cloned(),
            distribution: d.distribution,
        }
    }
}

/// A sampled direction in the beam-side local frame (`wi.z > 0`).
struct Sample {
    wo: DVec3,
    transmission: bool,
    /// `n_far / n_near` from the beam's side.
    eta: f64,
    pdf: f64,
    /// `G(wi, wo) / G1(wi)`: the weight before the transmittance and radiance factors.
    ratio: f64,
    /// A delta lobe (index 1: straight through).
    delta: bool,
}

impl RoughDielectric {
    /// A rough dielectric with index `ior`, GGX roughness `alpha_u` along the first tangent and
    /// `alpha_v` along the second, and an optional transmittance applied on refraction.
    ///
    /// # Errors
    /// [`MaterialError::Parameter`] naming `roughness_u` or `roughness_v` unless finite and
    /// `>= 0`.
    pub fn new(
        ior: Ior,
        alpha_u: f64,
        alpha_v: f64,
        transmittance: Option<Transmittance>,
    ) -> Result<Self, MaterialError> {
        check_alpha(NAME, "roughness_u", alpha_u)?;
        check_alpha(NAME, "roughness_v", alpha_v)?;
        Ok(Self {
            smooth: Arc::new(Dielectric::new(ior, transmittance)),
            alpha_u,
            alpha_v,
            distribution: Distribution::Ggx,
        })
    }

    /// An isotropic rough dielectric (`roughness` = `alpha`).
    ///
    /// # Errors
    /// [`MaterialError::Parameter`] naming `roughness` unless `alpha` is finite and `>= 0`.
    pub fn isotropic(
        ior: Ior,
        alpha: f64,
        transmittance: Option<Transmittance>,
    ) -> Result<Self, MaterialError> {
        check_alpha(NAME, "roughness", alpha)?;
        Self::new(ior, alpha, alpha, transmittance)
    }

    /// The same glass with the isotropic roughness `alpha` (a texel's; finite, `>= 0`). Shares
    /// the index, so it allocates nothing.
    pub(crate) fn with_alpha(&self, alpha: f64) -> Self {
        Self {
            smooth: Arc::clone(&self.smooth),
            alpha_u: alpha,
            alpha_v: alpha,
            distribution: self.distribution,
        }
    }

    /// The same glass with the microfacet distribution `kind` (GGX unless asked).
    pub fn with_distribution(mut self, kind: Distribution) -> Self {
        self.distribution = kind;
        self
    }

    /// The microfacet distribution.
    pub fn distribution(&self) -> Distribution {
        self.distribution
    }

    /// The index of refraction of the inside.
    pub fn ior(&self) -> &Ior {
        self.smooth.ior()
    }

    /// The transmittance applied on refraction (`None`: 1).
    pub fn transmittance(&self) -> Option<&Transmittance> {
        self.smooth.transmittance()
    }

    /// The GGX roughness `(alpha_u, alpha_v)` along the first and second tangent, as given.
    pub fn roughness(&self) -> (f64, f64) {
        (self.alpha_u, self.alpha_v)
    }

    /// `true` when both alphas are below [`SMOOTH_ALPHA`](crate::SMOOTH_ALPHA): the material is then exactly the
    /// smooth [`Dielectric`] with the same index and transmittance.
    pub fn is_smooth(&self) -> bool {
        Ggx::is_smooth_alphas(self.alpha_u, self.alpha_v)
    }

    fn facets(&self) -> Facets {
        Facets::new(self.distribution, self.alpha_u, self.alpha_v)
    }

    /// `n_far / n_near` seen from the side of a local direction with `z = side_z`.
    fn eta_from(&self, side_z: f64, lambda: f64) -> f64 {
        let n = self.smooth.ior().n(lambda);
        if side_z > 0.0 { n } else { 1.0 / n }
    }

    /// The transmittance at `lambda` (1 without one).
    fn tint(&self, lambda: f64) -> f64 {
        self.smooth.transmittance().map_or(1.0, |t| t.value(lambda))
    }

    /// The microfacet normal joining `wi` (local, `wi.z > 0`) and `wo` (local, `wo.z != 0`) for
    /// relative index `eta`, on the outside (`m.z > 0`), or `None` for a pair no microfacet
    /// connects (back-facing, or a straight pass through an index of 1).
    fn half_vector(wi: DVec3, wo: DVec3, eta: f64) -> Option<DVec3> {
        let raw = if wo.z > 0.0 { wi + wo } else { wi + eta * wo };
        let len2 = raw.length_squared();
        if !(len2 > 0.0 && len2.is_finite()) {
            return None;
        }
        let mut m = raw / len2.sqrt();
        if m.z < 0.0 {
            m = -m;
        }
        // Both directions must see the microfacet from their own side.
        (m.z > 0.0 && wi.dot(m) > 0.0 && wo.dot(m) * wo.z > 0.0).then_some(m)
    }

    /// The BSDF for light from `wi` to `wo`, local, `wi.z > 0` (the side flip done), `eta` the
    /// index on `wo`'s side over `wi`'s when `wo` is across; without the transmittance.
    fn f_local(&self, wi: DVec3, wo: DVec3, eta: f64) -> f64 {
        if !(wi.z > 0.0) || wo.z == 0.0 || (wo.z < 0.0 && eta == 1.0) {
            return 0.0;
        }
        let Some(m) = Self::half_vector(wi, wo, eta) else { return 0.0 };
        let facets = self.facets();
        let (cos_im, cos_om) = (wi.dot(m), wo.dot(m));
        let f = fresnel_dielectric(cos_im, eta);
        let d = facets.d(m);
        let g = facets.g(wo, wi);
        let value = if wo.z > 0.0 {
            f * d * g / (4.0 * wi.z * wo.z)
        } else {
            let den = cos_im + eta * cos_om;
            (1.0 - f) * d * g * (cos_im * cos_om).abs() * eta * eta
                / (wi.z * wo.z.abs() * den * den)
        };
        if value.is_finite() { value.max(0.0) } else { 0.0 }
    }

    /// The density of sampling `wo` for a beam arriving from `wi` (local, `wi.z > 0`), `eta`
    /// the index across over the index on `wi`'s side.
    fn pdf_local(&self, wi: DVec3, wo: DVec3, eta: f64) -> f64 {
        if !(wi.z > 0.0) || wo.z == 0.0 || (wo.z < 0.0 && eta == 1.0) {
            return 0.0;
        }
        let Some(m) = Self::half_vector(wi, wo, eta) else { return 0.0 };
        let (cos_im, cos_om) = (wi.dot(m), wo.dot(m));
        let f = fresnel_dielectric(cos_im, eta);
        let visible = self.facets().pdf_visible(wi, m);
        let p = if wo.z > 0.0 {
            f * visible / (4.0 * cos_im)
        } else {
            let den = cos_im + eta * cos_om;
            (1.0 - f) * visible * eta * eta * cos_om.abs() / (den * den)
        };
        if p.is_finite() { p.max(0.0) } else { 0.0 }
    }

    /// Samples the rough lobes for a beam arriving from local `wi` (`wi.z > 0`), `eta` across
    /// over near.
    fn sample_local(&self, wi: DVec3, eta: f64, u: [f64; 3]) -> Option<Sample> {
        if eta == 1.0 {
            return Some(Sample {
                wo: -wi,
                transmission: true,
                eta,
                pdf: 0.0,
                ratio: 1.0,
                delta: true,
            });
        }
        let facets = self.facets();
        let m = facets.sample_visible(wi, [clamp_uniform(u[1]), clamp_uniform(u[2])]);
        let cos_im = wi.dot(m);
        if !(cos_im > 0.0) {
            return None;
        }
        let f = fresnel_dielectric(cos_im, eta);
        let reflected = normalise(2.0 * cos_im * m - wi);
        let (wo, transmission) = if clamp_uniform(u[0]) < f {
            (reflected, false)
        } else {
            match refract(-wi, m, eta) {
                Some(t) => (t, true),
                None => (reflected, false), // total internal reflection (F = 1 to rounding)
            }
        };
        if transmission == (wo.z > 0.0) || wo.z == 0.0 {
            return None; // left through the wrong side of the macro-surface: absorbed
        }
        let pdf = self.pdf_local(wi, wo, eta);
        let ratio = facets.g(wo, wi) / facets.g1(wi);
        (pdf > 0.0 && pdf.is_finite() && ratio > 0.0 && ratio.is_finite()).then_some(Sample {
            wo,
            transmission,
            eta,
            pdf,
            ratio,
            delta: false,
        })
    }

    /// The weight of `sample` at `lambda` for `transport`.
    fn weight(&self, sample: &Sample, lambda: f64, transport: Transport) -> f64 {
        if !sample.transmission {
            return sample.ratio;
        }
        let mut w = sample.ratio * self.tint(lambda);
        if transport == Transport::Radiance {
            let r = 1.0 / sample.eta;
            w *= r * r;
        }
        w
    }

    /// Samples for a beam along world `direction`: the frame, whether the side was flipped, and
    /// the sample (local, beam side up).
    fn sample_world(
        &self,
        direction: DVec3,
        normal: DVec3,
        lambda: f64,
        u: [f64; 3],
    ) -> Option<(Frame, bool, Sample)> {
        let frame = Frame::from_normal(normal);
        let mut wi = frame.to_local(-direction);
        if wi.z == 0.0 || !wi.is_finite() {
            return None;
        }
        let flip = wi.z < 0.0;
        let eta = self.eta_from(wi.z, lambda);
        if flip {
            wi.z = -wi.z;
        }
        let s = self.sample_local(normalise(wi), eta, u)?;
        Some((frame, flip, s))
    }

    /// The world direction of a local sample.
    fn to_world(frame: &Frame, flip: bool, mut wo: DVec3) -> DVec3 {
        if flip {
            wo.z = -wo.z;
        }
        normalise(frame.to_world(wo))
    }

    /// Local `wi`, `wo` with `wi` turned up and the index ratio from `wi`'s side; `None` when
    /// `wi` is tangent.
    fn local_pair(
        &self,
        wi: DVec3,
        wo: DVec3,
        normal: DVec3,
        lambda: f64,
    ) -> Option<(DVec3, DVec3, f64)> {
        let frame = Frame::from_normal(normal);
        let (mut a, mut b) = (frame.to_local(wi), frame.to_local(wo));
        if a.z == 0.0 {
            return None;
        }
        let eta = self.eta_from(a.z, lambda);
        if a.z < 0.0 {
            a.z = -a.z;
            b.z = -b.z;
        }
        Some((a, b, eta))
    }
}

#[typetag::serde]
impl Material for RoughDielectric {
    /// GGX reflection or refraction for flux ([`Transport::Importance`]); `u[0]` chooses the
    /// lobe, `u[1]`, `u[2]` the visible microfacet normal.
    fn scatter(&self, incoming: &Incoming, u: [f64; 3]) -> Option<Scattered> {
        self.scatter_with(incoming, u, Transport::Importance)
    }

    fn scatter_with(
        &self,
        incoming: &Incoming,
        u: [f64; 3],
        transport: Transport,
    ) -> Option<Scattered> {
        if self.is_smooth() {
            return self.smooth.scatter_with(incoming, u, transport);
        }
        let (frame, flip, s) =
            self.sample_world(incoming.direction, incoming.normal, incoming.lambda, u)?;
        let weight = self.weight(&s, incoming.lambda, transport);
        if !(weight > 0.0 && weight.is_finite()) {
            return None;
        }
        Some(Scattered {
            direction: Self::to_world(&frame, flip, s.wo),
            weight,
            kind: if s.delta { ScatterKind::Specular } else { ScatterKind::Diffuse },
            pdf: s.pdf,
            eta: if s.transmission { s.eta } else { 1.0 },
            transmission: s.transmission,
        })
    }

    /// Without dispersion the lobe choice and the direction are the same for every wavelength:
    /// sampled once, each wavelength's weight then differs only by its transmittance. A
    /// dispersive index scatters each wavelength ([`scatter_each`]); the smooth limit is
    /// [`Dielectric`]'s.
    fn scatter_bundle(
        &self,
        direction: DVec3,
        normal: DVec3,
        lambdas: &[f64],
        weights: &mut [f64],
        u: [f64; 3],
        transport: Transport,
    ) -> Option<BundleScattered> {
        if self.is_smooth() {
            return self.smooth.scatter_bundle(direction, normal, lambdas, weights, u, transport);
        }
        if self.is_dispersive() {
            return scatter_each(self, direction, normal, lambdas, weights, u, transport);
        }
        let first = weights.iter().zip(lambdas).find(|(w, _)| **w > 0.0).map(|(_, &l)| l)?;
        let Some((frame, flip, s)) = self.sample_world(direction, normal, first, u) else {
            scale_bundle(lambdas, weights, |_| 0.0);
            return None;
        };
        let any = scale_bundle(lambdas, weights, |lambda| {
            let w = self.weight(&s, lambda, transport);
            if w.is_finite() { w } else { 0.0 }
        });
        any.then_some(BundleScattered {
            direction: Self::to_world(&frame, flip, s.wo),
            kind: if s.delta { ScatterKind::Specular } else { ScatterKind::Diffuse },
            pdf: s.pdf,
            eta: if s.transmission { s.eta } else { 1.0 },
            transmission: s.transmission,
        })
    }

    /// The radiance BSDF `f(wi -> wo)` (see the module documentation: light from `wi`).
    fn eval(&self, wi: DVec3, wo: DVec3, normal: DVec3, lambda: f64) -> f64 {
        if self.is_smooth() {
            return 0.0;
        }
        let Some((a, b, eta)) = self.local_pair(wi, wo, normal, lambda) else { return 0.0 };
        let f = self.f_local(a, b, eta);
        if b.z < 0.0 { f * self.tint(lambda) } else { f }
    }

    /// The same as [`eval`](Material::eval) for both transports: the arguments are in light
    /// order for both (see the module documentation).
    fn eval_with(
        &self,
        wi: DVec3,
        wo: DVec3,
        normal: DVec3,
        lambda: f64,
        _transport: Transport,
    ) -> f64 {
        self.eval(wi, wo, normal, lambda)
    }

    fn pdf(&self, wi: DVec3, wo: DVec3, normal: DVec3, lambda: f64) -> f64 {
        if self.is_smooth() {
            return 0.0;
        }
        let Some((a, b, eta)) = self.local_pair(wi, wo, normal, lambda) else { return 0.0 };
        self.pdf_local(a, b, eta)
    }

    fn is_specular(&self) -> bool {
        self.is_smooth()
    }

    fn is_dispersive(&self) -> bool {
        self.smooth.ior().is_dispersive()
    }
}
