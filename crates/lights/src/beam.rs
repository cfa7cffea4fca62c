//! [`Beam`]: what a light source emits (seed section 2.4), and [`LightId`].

use glam::DVec3;
use serde::{Deserialize, Serialize};

/// Which light a beam came from: the light's index in its [`crate::LightSet`] (0 for a light used
/// on its own).
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Default, Serialize, Deserialize,
)]
pub struct LightId(pub u32);

/// One beam: spatial data (origin, unit direction), colour data (one wavelength and a weight),
/// the bounce count and the light it came from.
///
/// The beam's power is `parent.power() / parent.number_of_beams() * scale` watts: every beam of a
/// light carries an equal share of its power, reweighted by `scale` (1 when the wavelength was
/// importance-sampled from the light's SPD).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Beam {
    /// Where the beam starts (m).
    pub origin: DVec3,
    /// Unit direction of travel.
    pub direction: DVec3,
    /// Wavelength (nm).
    pub lambda: f64,
    /// Weight relative to an equal share of the light's power (1 by default).
    pub scale: f64,
    /// Number of bounces so far; 0 at emission.
    pub level: u32,
    /// The light the beam came from.
    pub parent: LightId,
}

impl Beam {
    /// A freshly emitted beam (`level` 0, `parent` 0: a [`crate::LightSet`] sets its own index).
    pub fn new(origin: DVec3, direction: DVec3, lambda: f64, scale: f64) -> Self {
        Self { origin, direction, lambda, scale, level: 0, parent: LightId(0) }
    }

    /// The beam's power (W) given its light's power and beam count:
    /// `power / number_of_beams * scale`.
    pub fn power(&self, light_power: f64, number_of_beams: u64) -> f64 {
        if number_of_beams == 0 { 0.0 } else { light_power / number_of_beams as f64 * self.scale }
    }
}
