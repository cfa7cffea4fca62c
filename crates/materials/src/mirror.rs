//! [`Mirror`]: a perfect specular reflector with a spectral reflectance.
//!
//! | field | unit | default | meaning |
//! |---|---|---|---|
//! | `reflectance` | fraction in `[0, 1]`, a number or `{"nm": [...], "values": [...]}` | required | `R(lambda)`, the fraction of a beam's power reflected (e.g. a gold-coloured mirror) |
//!
//! ```json
//! {"type": "Mirror", "reflectance": 0.95}
//! ```
//!
//! The law of reflection, `r = d - 2 (d . n) n`, weight `R(lambda)`, a delta lobe (`pdf` 0,
//! `eval` 0). **Two-sided**: a beam from behind the normal is reflected on its own side.

use glam::DVec3;
use serde::{Deserialize, Serialize};
use spectrace_spectrum::Reflectance;

use crate::fresnel::reflect;
use crate::vectors::facing;
use crate::{BundleScattered, Incoming, Material, ScatterKind, Scattered, Transport, scale_bundle};

/// A perfect mirror, two-sided, with a wavelength-dependent reflectance.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Mirror {
    /// The fraction reflected, `R(lambda)`.
    pub reflectance: Reflectance,
}

impl Mirror {
    /// A mirror reflecting the fraction `reflectance`.
    pub fn new(reflectance: Reflectance) -> Self {
        Self { reflectance }
    }
}

#[typetag::serde]
impl Material for Mirror {
    /// Reflects about the normal (either side); weight `R(lambda)`; `None` where it is 0. Uses no
    /// uniforms.
    fn scatter(&self, incoming: &Incoming, _u: [f64; 3]) -> Option<Scattered> {
        let r = self.reflectance.value(incoming.lambda);
        if !(r > 0.0) {
            return None;
        }
        let n = facing(incoming.direction, incoming.normal);
        Some(Scattered {
            direction: reflect(incoming.direction, n),
            weight: r,
            kind: ScatterKind::Specular,
            pdf: 0.0,
            eta: 1.0,
            transmission: false,
        })
    }

    /// One reflection for the whole bundle; each live wavelength's weight times its
    /// `R(lambda)`.
    fn scatter_bundle(
        &self,
        direction: DVec3,
        normal: DVec3,
        lambdas: &[f64],
        weights: &mut [f64],
        _u: [f64; 3],
        _transport: Transport,
    ) -> Option<BundleScattered> {
        if !scale_bundle(lambdas, weights, |lambda| self.reflectance.value(lambda)) {
            return None;
        }
        let n = facing(direction, normal);
        Some(BundleScattered {
            direction: reflect(direction, n),
            kind: ScatterKind::Specular,
            pdf: 0.0,
            eta: 1.0,
            transmission: false,
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
        false
    }
}
