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
use crate::{Incoming, Ior, Material, MaterialError, ScatterKind, Scattered, Transport};

/// A smooth dielectric boundary (glass) with a possibly dispersive index of refraction.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "DielectricRepr", into = "DielectricRepr")]
pub struct Dielectric {
    ior: Ior,
    transmittance: Option<Transmittance>,
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
        let d = incoming.direction;
        let n_inside = self.ior.n(incoming.lambda);
        let entering = d.dot(incoming.normal) < 0.0;
        // Normal on the beam's side, and the indices before (i) and after (t) the boundary.
        let (n, eta_i, eta_t) = if entering {
            (incoming.normal, 1.0, n_inside)
        } else {
            (-incoming.normal, n_inside, 1.0)
        };
        let cos_i = (-d.dot(n)).clamp(0.0, 1.0);
        let f = fresnel_dielectric(cos_i, eta_t / eta_i);
        let reflection = Scattered {
            direction: normalise(d + 2.0 * cos_i * n),
            weight: 1.0,
            kind: ScatterKind::Specular,
            pdf: 0.0,
            eta: 1.0,
            transmission: false,
        };
        if clamp_uniform(u[0]) < f {
            return Some(reflection);
        }
        let Some(direction) = refract(d, n, eta_t / eta_i) else {
            return Some(reflection); // total internal reflection (F = 1 already chose it)
        };
        let mut weight = self.transmittance.as_ref().map_or(1.0, |t| t.value(incoming.lambda));
        if transport == Transport::Radiance {
            let ratio = eta_i / eta_t;
            weight *= ratio * ratio;
        }
        if !(weight > 0.0) {
            return None;
        }
        Some(Scattered {
            direction,
            weight,
            kind: ScatterKind::Specular,
            pdf: 0.0,
            eta: eta_t / eta_i,
            transmission: true,
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
