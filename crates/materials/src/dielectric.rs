//! [`Dielectric`]: a smooth boundary of a transparent medium (glass, water): Fresnel reflection
//! and Snell refraction, total internal reflection, and dispersion.
//!
//! | field | unit | default | meaning |
//! |---|---|---|---|
//! | `ior` | number or law, see [`Ior`] | required | index of refraction of the inside, `n(lambda)`; the outside is vacuum (n = 1) |
//! | `transmittance` | fraction in `[0, 1]`, a number or `{"nm": [...], "values": [...]}`, or `null` | `null` (= 1) | multiplies the weight on every refraction (a surface tint) |
//!
//! ```json
//! {"type": "Dielectric", "ior": {"glass": "BK7"}}
//! {"type": "Dielectric", "ior": 1.33, "transmittance": {"nm": [400, 700], "values": [0.9, 0.99]}}
//! ```
//!
//! The outside is the side [`Incoming::normal`] points to: a beam with `direction . normal < 0`
//! is entering (from index 1 into `n`), otherwise leaving (from `n` into 1). Reflection is chosen
//! with probability `F` (the exact unpolarised Fresnel reflectance) and refraction with `1 - F`,
//! so the weight is 1 for reflection and `transmittance(lambda)` for refraction; beyond the
//! critical angle the beam is totally reflected with weight 1.
//!
//! **Flux, not radiance.** A beam from a light carries power (or, from the camera in a light
//! tracer, importance), which passes a boundary with no `(n_t / n_i)^2` factor: that is what
//! [`Material::scatter`] does. A path tracer following *radiance* from the camera must call
//! [`Material::scatter_with`] with [`Transport::Radiance`], which multiplies refraction by
//! `(n_i / n_t)^2` (`n_i` the index the path leaves, `n_t` the one it enters).

use glam::DVec3;
use serde::{Deserialize, Serialize};
use spectrace_spectrum::Transmittance;

use spectrace_sampling::clamp_uniform;

use crate::fresnel::{fresnel_dielectric, refract};
use crate::ior::IorRepr;
use crate::vectors::normalise;
use crate::{
    BundleScattered, Incoming, Ior, Material, MaterialError, ScatterKind, Scattered, Transport,
    scale_bundle, scatter_each,
};

/// A smooth dielectric boundary (glass) with a possibly dispersive index of refraction.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "DielectricRepr", into = "DielectricRepr")]
pub struct Dielectric {
    ior: Ior,
    transmittance: Option<Transmittance>,
}

/// The lobe a uniform chose: its direction, whether it refracts, and the indices before and
/// after the boundary.
struct Lobe {
    direction: DVec3,
    transmission: bool,
    eta_i: f64,
    eta_t: f64,
}

/// Scene-file form of [`Dielectric`]: the index unvalidated, so its errors name the field.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct DielectricRepr {
    ior: IorRepr,
    #[serde(default)]
    transmittance: Option<Transmittance>,
}

impl TryFrom<DielectricRepr> for Dielectric {
    type Error = MaterialError;
    fn try_from(r: DielectricRepr) -> Result<Self, MaterialError> {
        let ior = Ior::try_from(r.ior).map_err(|e| e.within("Dielectric", "ior"))?;
        Ok(Self::new(ior, r.transmittance))
    }
}

impl From<Dielectric> for DielectricRepr {
    fn from(d: Dielectric) -> Self {
        Self { ior: d.ior.into(), transmittance: d.transmittance }
    }
}

impl Dielectric {
    /// A dielectric with index `ior` and an optional transmittance applied on refraction.
    pub fn new(ior: Ior, transmittance: Option<Transmittance>) -> Self {
        Self { ior, transmittance }
    }

    /// Clear glass from the catalog, e.g. `Dielectric::glass("BK7")`.
    ///
    /// # Errors
    /// [`MaterialError::UnknownGlass`] (field `Dielectric.ior.glass`) listing the known names.
    pub fn glass(name: &str) -> Result<Self, MaterialError> {
        let ior = Ior::glass(name).map_err(|e| e.within("Dielectric", "ior"))?;
        Ok(Self::new(ior, None))
    }

    /// The index of refraction of the inside.
    pub fn ior(&self) -> &Ior {
        &self.ior
    }

    /// The transmittance applied on refraction (`None`: 1).
    pub fn transmittance(&self) -> Option<&Transmittance> {
        self.transmittance.as_ref()
    }

    /// The lobe `u0` chooses for a beam along `d` at `lambda`: Fresnel reflection with
    /// probability `F`, else refraction (total internal reflection where there is none).
    fn lobe(&self, d: DVec3, normal: DVec3, lambda: f64, u0: f64) -> Lobe {
        let n_inside = self.ior.n(lambda);
        let entering = d.dot(normal) < 0.0;
        // Normal on the beam's side, and the indices before (i) and after (t) the boundary.
        let (n, eta_i, eta_t) =
            if entering { (normal, 1.0, n_inside) } else { (-normal, n_inside, 1.0) };
        let cos_i = (-d.dot(n)).clamp(0.0, 1.0);
        let f = fresnel_dielectric(cos_i, eta_t / eta_i);
        let reflection =
            Lobe { direction: normalise(d + 2.0 * cos_i * n), transmission: false, eta_i, eta_t };
        if clamp_uniform(u0) < f {
            return reflection;
        }
        match refract(d, n, eta_t / eta_i) {
            Some(direction) => Lobe { direction, transmission: true, eta_i, eta_t },
            None => reflection, // total internal reflection (F = 1 already chose it)
        }
    }

    /// The weight of a refraction at `lambda`: the transmittance, and for radiance the
    /// `(n_i / n_t)^2` change across the boundary.
    fn refraction_weight(&self, lobe: &Lobe, lambda: f64, transport: Transport) -> f64 {
        let mut weight = self.transmittance.as_ref().map_or(1.0, |t| t.value(lambda));
        if transport == Transport::Radiance {
            let ratio = lobe.eta_i / lobe.eta_t;
            weight *= ratio * ratio;
        }
        weight
    }

    /// The Fresnel reflectance for a beam travelling along `direction` onto a boundary with
    /// outward `normal` at `lambda` (nm): the probability that [`Material::scatter`] reflects.
    pub fn reflectance(&self, direction: DVec3, normal: DVec3, lambda: f64) -> f64 {
        // pbrt's convention: cos_theta_i > 0 on the outside, eta = n_inside / n_outside.
        fresnel_dielectric(-direction.dot(normal), self.ior.n(lambda))
    }
}

#[typetag::serde]
impl Material for Dielectric {
    /// Fresnel reflection (probability `F`, from `u[0]`) or refraction, for flux
    /// ([`Transport::Importance`]).
    fn scatter(&self, incoming: &Incoming, u: [f64; 3]) -> Option<Scattered> {
        self.scatter_with(incoming, u, Transport::Importance)
    }

    fn scatter_with(
        &self,
        incoming: &Incoming,
        u: [f64; 3],
        transport: Transport,
    ) -> Option<Scattered> {
        let lobe = self.lobe(incoming.direction, incoming.normal, incoming.lambda, u[0]);
        let weight = if lobe.transmission {
            self.refraction_weight(&lobe, incoming.lambda, transport)
        } else {
            1.0
        };
        if !(weight > 0.0) {
            return None;
        }
        Some(Scattered {
            direction: lobe.direction,
            weight,
            kind: ScatterKind::Specular,
            pdf: 0.0,
            eta: if lobe.transmission { lobe.eta_t / lobe.eta_i } else { 1.0 },
            transmission: lobe.transmission,
        })
    }

    /// Without dispersion the Fresnel choice and both directions are the same for every
    /// wavelength: the lobe is chosen once, and only the transmittance differs per wavelength.
    /// A dispersive index scatters each wavelength (the general way, [`scatter_each`]).
    fn scatter_bundle(
        &self,
        direction: DVec3,
        normal: DVec3,
        lambdas: &[f64],
        weights: &mut [f64],
        u: [f64; 3],
        transport: Transport,
    ) -> Option<BundleScattered> {
        if self.is_dispersive() {
            return scatter_each(self, direction, normal, lambdas, weights, u, transport);
        }
        let first = weights.iter().zip(lambdas).find(|(w, _)| **w > 0.0).map(|(_, &l)| l)?;
        let lobe = self.lobe(direction, normal, first, u[0]);
        let any = scale_bundle(lambdas, weights, |lambda| {
            if lobe.transmission { self.refraction_weight(&lobe, lambda, transport) } else { 1.0 }
        });
        any.then_some(BundleScattered {
            direction: lobe.direction,
            kind: ScatterKind::Specular,
            pdf: 0.0,
            eta: if lobe.transmission { lobe.eta_t / lobe.eta_i } else { 1.0 },
            transmission: lobe.transmission,
        })
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
        self.ior.is_dispersive()
    }
}
