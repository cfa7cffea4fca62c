//! [`ThinDielectric`]: a thin transparent sheet (a window pane, a soap film without
//! interference): Fresnel reflection at both of its faces with every internal bounce summed, and
//! transmission straight through (the two refractions cancel). Mitsuba's `thindielectric`.
//!
//! | field | unit | default | meaning |
//! |---|---|---|---|
//! | `ior` | number or law, see [`Ior`] | required | index of refraction of the sheet; outside it, vacuum (n = 1) on both sides |
//! | `transmittance` | fraction in `[0, 1]`, a number or table, or `null` | `null` (= 1) | multiplies the weight of every transmission (a tint) |
//!
//! ```json
//! {"type": "ThinDielectric", "ior": 1.5}
//! ```
//!
//! With `R = F(cos)` the reflectance of one face, the internal reflections form a geometric
//! series: the sheet reflects `R' = R + (1 - R)^2 R / (1 - R^2) = 2 R / (1 + R)` and transmits
//! `1 - R'`, both sides alike. Reflection (a mirror) is chosen with probability `R'` and weight
//! 1, transmission with `1 - R'` and weight `transmittance(lambda)`; the beam keeps its direction
//! and its medium (`eta = 1`), so radiance and flux pass alike. A non-dispersive sheet chooses
//! one lobe for a whole wavelength bundle.

use glam::DVec3;
use serde::{Deserialize, Serialize};
use spectrace_spectrum::Transmittance;

use spectrace_sampling::clamp_uniform;

use crate::fresnel::{fresnel_dielectric, reflect};
use crate::ior::IorRepr;
use crate::{
    BundleScattered, Incoming, Ior, Material, MaterialError, ScatterKind, Scattered, Transport,
    scale_bundle, scatter_each,
};

/// A thin dielectric sheet.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "ThinDielectricRepr", into = "ThinDielectricRepr")]
pub struct ThinDielectric {
    ior: Ior,
    transmittance: Option<Transmittance>,
}

/// Scene-file form of [`ThinDielectric`].
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct ThinDielectricRepr {
    ior: IorRepr,
    #[serde(default)]
    transmittance: Option<Transmittance>,
}

impl TryFrom<ThinDielectricRepr> for ThinDielectric {
    type Error = MaterialError;
    fn try_from(r: ThinDielectricRepr) -> Result<Self, MaterialError> {
        let ior = Ior::try_from(r.ior).map_err(|e| e.within("ThinDielectric", "ior"))?;
        Ok(Self::new(ior, r.transmittance))
    }
}

impl From<ThinDielectric> for ThinDielectricRepr {
    fn from(d: ThinDielectric) -> Self {
        Self { ior: d.ior.into(), transmittance: d.transmittance }
    }
}

impl ThinDielectric {
    /// A sheet of index `ior` with an optional transmittance.
    pub fn new(ior: Ior, transmittance: Option<Transmittance>) -> Self {
        Self { ior, transmittance }
    }

    /// The sheet's reflectance `R' = 2 R / (1 + R)` for a beam along `direction` at `lambda`
    /// (either side), `R` the Fresnel reflectance of one face.
    pub fn reflectance(&self, direction: DVec3, normal: DVec3, lambda: f64) -> f64 {
        let r = fresnel_dielectric(direction.dot(normal).abs(), self.ior.n(lambda));
        2.0 * r / (1.0 + r)
    }

    /// The direction and whether it passes through, chosen by `u0`.
    fn lobe(&self, d: DVec3, normal: DVec3, lambda: f64, u0: f64) -> (DVec3, bool) {
        if clamp_uniform(u0) < self.reflectance(d, normal, lambda) {
            (reflect(d, normal), false)
        } else {
            (d, true)
        }
    }

    fn transmission_weight(&self, lambda: f64) -> f64 {
        self.transmittance.as_ref().map_or(1.0, |t| t.value(lambda))
    }
}

#[typetag::serde]
impl Material for ThinDielectric {
    fn scatter(&self, incoming: &Incoming, u: [f64; 3]) -> Option<Scattered> {
        self.scatter_with(incoming, u, Transport::Importance)
    }

    /// The same for flux and radiance: the beam stays in its medium.
    fn scatter_with(&self, incoming: &Incoming, u: [f64; 3], _: Transport) -> Option<Scattered> {
        let (direction, through) =
            self.lobe(incoming.direction, incoming.normal, incoming.lambda, u[0]);
        let weight = if through { self.transmission_weight(incoming.lambda) } else { 1.0 };
        (weight > 0.0).then_some(Scattered {
            direction,
            weight,
            kind: ScatterKind::Specular,
            pdf: 0.0,
            eta: 1.0,
            transmission: through,
        })
    }

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
        let (out, through) = self.lobe(direction, normal, first, u[0]);
        let any = scale_bundle(lambdas, weights, |lambda| {
            if through { self.transmission_weight(lambda) } else { 1.0 }
        });
        any.then_some(BundleScattered {
            direction: out,
            kind: ScatterKind::Specular,
            pdf: 0.0,
            eta: 1.0,
            transmission: through,
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

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    fn sheet() -> ThinDielectric {
        ThinDielectric::new(Ior::constant(1.5).unwrap(), None)
    }

    /// `2R / (1 + R)` is the sum of the internal-reflection series, on both sides alike.
    #[test]
    fn the_reflectance_sums_every_internal_bounce() {
        let n = DVec3::Z;
        for degrees in [0.0f64, 30.0, 60.0, 85.0] {
            let t = degrees.to_radians();
            let d = DVec3::new(t.sin(), 0.0, -t.cos());
            let r = fresnel_dielectric(t.cos(), 1.5);
            let series: f64 =
                r + (1..200).map(|k| (1.0 - r).powi(2) * r.powi(2 * k - 1)).sum::<f64>();
            assert!((sheet().reflectance(d, n, 550.0) - series).abs() < 1e-12, "{degrees}");
            let up = DVec3::new(d.x, d.y, -d.z);
            assert_eq!(sheet().reflectance(up, n, 550.0), sheet().reflectance(d, n, 550.0));
        }
    }

    /// Sampled lobes: reflection is the mirror direction with weight 1, transmission keeps
    /// the direction, with the transmittance; the reflected fraction of many uniforms is `R'`.
    #[test]
    fn lobes_are_the_mirror_and_the_straight_path() {
        let tinted = ThinDielectric::new(
            Ior::constant(1.5).unwrap(),
            Some(Transmittance::constant(0.8).unwrap()),
        );
        let d = DVec3::new(0.6, 0.0, -0.8);
        let incoming = Incoming { direction: d, normal: DVec3::Z, lambda: 550.0 };
        let n = 100_000;
        let mut reflected = 0;
        for k in 0..n {
            let s = tinted.scatter(&incoming, [(k as f64 + 0.5) / n as f64, 0.5, 0.5]).unwrap();
            if s.transmission {
                assert_eq!((s.direction, s.weight, s.eta), (d, 0.8, 1.0));
            } else {
                reflected += 1;
                assert!((s.direction - DVec3::new(0.6, 0.0, 0.8)).length() < 1e-12);
                assert_eq!(s.weight, 1.0);
            }
        }
        let expected = tinted.reflectance(d, DVec3::Z, 550.0);
        assert!((reflected as f64 / n as f64 - expected).abs() < 2.0 / n as f64);
        let json = serde_json::to_string(&(Box::new(tinted) as Box<dyn Material>)).unwrap();
        let back: Box<dyn Material> = serde_json::from_str(&json).unwrap();
        assert!(json.contains("ThinDielectric") && back.is_specular(), "{json}");
    }
}
