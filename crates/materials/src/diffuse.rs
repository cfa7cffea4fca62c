//! [`Diffuse`]: a Lambertian surface with a spectral reflectance.
//!
//! | field | unit | default | meaning |
//! |---|---|---|---|
//! | `reflectance` | fraction in `[0, 1]`, a number or `{"nm": [...], "values": [...]}` | required | the albedo `R(lambda)`: the fraction of a beam's power scattered |
//!
//! ```json
//! {"type": "Diffuse", "reflectance": {"nm": [400, 500, 600, 700], "values": [0.05, 0.1, 0.6, 0.8]}}
//! ```
//!
//! `f = R(lambda) / pi` for directions on the same side; the outgoing direction is
//! cosine-distributed, so the weight is exactly `R(lambda)`. The surface is **two-sided**: a beam
//! arriving from behind the normal is scattered back to its own side as if the normal were
//! flipped to face it; light never passes through.

use std::f64::consts::FRAC_1_PI;

use glam::DVec3;
use serde::{Deserialize, Serialize};
use spectrace_spectrum::Reflectance;

use spectrace_sampling::{Frame, clamp_uniform, pdf_cosine_hemisphere, sample_cosine_hemisphere};

use crate::vectors::{facing, normalise};
use crate::{BundleScattered, Incoming, Material, ScatterKind, Scattered, Transport, scale_bundle};

/// A Lambertian (ideal diffuse) reflector, two-sided.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Diffuse {
    /// The spectral albedo `R(lambda)`.
    pub reflectance: Reflectance,
}

impl Diffuse {
    /// A Lambertian surface with albedo `reflectance`.
    pub fn new(reflectance: Reflectance) -> Self {
        Self { reflectance }
    }
}

/// `true` if `wi` and `wo` lie strictly on the same side of the surface.
#[inline]
fn same_side(wi: DVec3, wo: DVec3, normal: DVec3) -> bool {
    wi.dot(normal) * wo.dot(normal) > 0.0
}

#[typetag::serde]
impl Material for Diffuse {
    /// Cosine-distributed around the normal turned to face the beam, from `u[1]`, `u[2]`;
    /// weight `R(lambda)`; `None` where `R(lambda) = 0`.
    fn scatter(&self, incoming: &Incoming, u: [f64; 3]) -> Option<Scattered> {
        let albedo = self.reflectance.value(incoming.lambda);
        if !(albedo > 0.0) {
            return None;
        }
        let n = facing(incoming.direction, incoming.normal);
        // Malley's method with the polar map: cos theta = sqrt(1 - u[1]) > 0, never tangent.
        let local = sample_cosine_hemisphere([clamp_uniform(u[1]), clamp_uniform(u[2])]);
        Some(Scattered {
            direction: normalise(Frame::from_normal(n).to_world(local)),
            weight: albedo,
            kind: ScatterKind::Diffuse,
            pdf: pdf_cosine_hemisphere(local.z),
            eta: 1.0,
            transmission: false,
        })
    }

    /// One cosine-distributed direction for the whole bundle; each live wavelength's weight
    /// times its `R(lambda)`.
    fn scatter_bundle(
        &self,
        direction: DVec3,
        normal: DVec3,
        lambdas: &[f64],
        weights: &mut [f64],
        u: [f64; 3],
        _transport: Transport,
    ) -> Option<BundleScattered> {
        if !scale_bundle(lambdas, weights, |lambda| self.reflectance.value(lambda)) {
            return None;
        }
        let n = facing(direction, normal);
        let local = sample_cosine_hemisphere([clamp_uniform(u[1]), clamp_uniform(u[2])]);
        Some(BundleScattered {
            direction: normalise(Frame::from_normal(n).to_world(local)),
            kind: ScatterKind::Diffuse,
            pdf: pdf_cosine_hemisphere(local.z),
            eta: 1.0,
            transmission: false,
        })
    }

    /// The lobe's side test once; `R(lambda) / pi` per wavelength.
    fn eval_bundle(
        &self,
        wi: DVec3,
        wo: DVec3,
        normal: DVec3,
        lambdas: &[f64],
        _transport: Transport,
        out: &mut [f64],
    ) {
        let lit = same_side(wi, wo, normal);
        for (o, &lambda) in out.iter_mut().zip(lambdas) {
            *o = if lit { self.reflectance.value(lambda) * FRAC_1_PI } else { 0.0 };
        }
    }

    fn eval(&self, wi: DVec3, wo: DVec3, normal: DVec3, lambda: f64) -> f64 {
        if same_side(wi, wo, normal) { self.reflectance.value(lambda) * FRAC_1_PI } else { 0.0 }
    }

    fn pdf(&self, wi: DVec3, wo: DVec3, normal: DVec3, _lambda: f64) -> f64 {
        if same_side(wi, wo, normal) { wo.dot(normal).abs() * FRAC_1_PI } else { 0.0 }
    }

    fn is_specular(&self) -> bool {
        false
    }

    fn is_dispersive(&self) -> bool {
        false
    }
}
