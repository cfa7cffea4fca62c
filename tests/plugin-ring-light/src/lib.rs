//! An example third-party light for Spectrace: a thin ring (a circular tube lamp) that emits
//! isotropically from every point of a circle. It depends on `spectrace-lights` alone (plus
//! `serde`, `typetag` and `rand`, which the `#[typetag::serde]` attribute and the trait need),
//! and once linked into a binary the renderer accepts it from scene files:
//!
//! ```json
//! {"type": "RingLight", "center": [0, 2, 0], "axis": [0, 1, 0], "radius": 0.3, "power": 40,
//!  "spd": {"type": "CieIlluminant", "name": "F2"}}
//! ```
//!
//! A binary that wants the plugin must link it: depend on the crate and name it somewhere, e.g.
//! `use spectrace_plugin_ring_light as _;`. typetag registers implementations at link time; a
//! crate that nothing references may be left out by the linker, and its type name is then unknown.

use std::f64::consts::TAU;
use std::sync::Arc;

use rand::Rng;
use serde::{Deserialize, Serialize};
use spectrace_lights::glam::DVec3;
use spectrace_lights::spectrum::SpectralPowerDistribution;
use spectrace_lights::{Beam, LightError, LightSource, SpdLight, WavelengthSampling, uniform};

/// A ring of `radius` around `center`, in the plane perpendicular to `axis`, emitting uniformly in
/// all directions from every point of the circle.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(try_from = "RingRepr", into = "RingRepr")]
pub struct RingLight {
    emission: SpdLight,
    center: DVec3,
    axis: DVec3,
    radius: f64,
    /// Two unit vectors spanning the ring's plane.
    plane: (DVec3, DVec3),
}

/// Scene-file form of [`RingLight`].
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct RingRepr {
    center: DVec3,
    axis: DVec3,
    radius: f64,
    power: f64,
    spd: Arc<dyn SpectralPowerDistribution>,
}

impl TryFrom<RingRepr> for RingLight {
    type Error = LightError;
    fn try_from(r: RingRepr) -> Result<Self, LightError> {
        Self::new(r.center, r.axis, r.radius, r.power, r.spd)
    }
}

impl From<RingLight> for RingRepr {
    fn from(l: RingLight) -> Self {
        Self {
            center: l.center,
            axis: l.axis,
            radius: l.radius,
            power: l.emission.power(),
            spd: l.emission.spd().clone(),
        }
    }
}

impl RingLight {
    /// A ring light.
    ///
    /// # Errors
    /// [`LightError::Parameter`] naming `center`, `axis`, `radius` or `power`.
    pub fn new(
        center: DVec3,
        axis: DVec3,
        radius: f64,
        power: f64,
        spd: Arc<dyn SpectralPowerDistribution>,
    ) -> Result<Self, LightError> {
        if !center.is_finite() {
            return Err(LightError::parameter(
                "RingLight",
                "center",
                center.to_array(),
                "must be finite",
            ));
        }
        let len = axis.length();
        if !(len > 0.0 && len.is_finite()) {
            return Err(LightError::parameter(
                "RingLight",
                "axis",
                axis.to_array(),
                "must be a non-zero, finite vector",
            ));
        }
        if !(radius > 0.0 && radius.is_finite()) {
            return Err(LightError::parameter(
                "RingLight",
                "radius",
                radius,
                "must be finite and > 0",
            ));
        }
        let emission = SpdLight::new("RingLight", spd, power, WavelengthSampling::Importance)?;
        let a = axis / len;
        let u = a.any_orthonormal_vector();
        Ok(Self { emission, center, axis, radius, plane: (u, a.cross(u)) })
    }
}

#[typetag::serde]
impl LightSource for RingLight {
    fn next_beam(&self, rng: &mut dyn Rng) -> Beam {
        let (lambda, scale) = self.emission.wavelength(uniform(rng));
        let phi = TAU * uniform(rng);
        let origin =
            self.center + (self.plane.0 * phi.cos() + self.plane.1 * phi.sin()) * self.radius;
        let z = 1.0 - 2.0 * uniform(rng);
        let r = ((1.0 - z) * (1.0 + z)).max(0.0).sqrt();
        let psi = TAU * uniform(rng);
        let direction = DVec3::new(r * psi.cos(), r * psi.sin(), z).normalize();
        self.emission.count();
        Beam::new(origin, direction, lambda, scale)
    }
    spectrace_lights::delegate_to_spd_light!(emission);
}
