//! [`Laser`]: a beam from one point in one direction (seed 2.4.1), optionally of finite width.
//!
//! | field | unit | default | meaning |
//! |---|---|---|---|
//! | `position` | m, `[x, y, z]` | required | where the beams start (the beam's centre) |
//! | `direction` | `[x, y, z]` | required | direction of the beams (normalised; must be non-zero) |
//! | `power` | W | required | total emitted power |
//! | `spd` | SPD | required | spectrum, e.g. a narrow `Gaussian` or `Monochromatic` line |
//! | `beam_radius` | m | `0` | radius of a finite beam: origins uniform over a disk perpendicular to `direction` |
//! | `wavelength_sampling` | | `"importance"` | `"importance"` or `"equal_wavelengths"` |
//!
//! ```json
//! {"type": "Laser", "position": [0, 1, 0], "direction": [1, 0, 0], "power": 0.005,
//!  "spd": {"type": "Gaussian", "center_nm": 632.8, "fwhm_nm": 0.002}, "beam_radius": 0.0005}
//! ```

use std::sync::Arc;

use glam::DVec3;
use rand::Rng;
use serde::{Deserialize, Serialize};
use spectrace_spectrum::SpectralPowerDistribution;

use spectrace_sampling::{Frame, sample_uniform_disk_concentric};

use crate::geometry::{finite_point, non_negative, unit_direction};
use crate::source::uniform;
use crate::{Beam, LightError, LightFlags, LightSource, SpdLight, WavelengthSampling};

/// A laser: parallel beams from a point (or a disk of `beam_radius`) along one direction.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(try_from = "LaserRepr", into = "LaserRepr")]
pub struct Laser {
    emission: SpdLight,
    position: DVec3,
    direction: DVec3,
    beam_radius: f64,
    frame: Frame,
}

/// Scene-file form of [`Laser`].
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct LaserRepr {
    position: DVec3,
    direction: DVec3,
    power: f64,
    spd: Arc<dyn SpectralPowerDistribution>,
    #[serde(default)]
    beam_radius: f64,
    #[serde(default)]
    wavelength_sampling: WavelengthSampling,
}

impl TryFrom<LaserRepr> for Laser {
    type Error = LightError;
    fn try_from(r: LaserRepr) -> Result<Self, LightError> {
        Self::new(r.position, r.direction, r.power, r.spd, r.beam_radius, r.wavelength_sampling)
    }
}

impl From<Laser> for LaserRepr {
    fn from(l: Laser) -> Self {
        Self {
            position: l.position,
            direction: l.direction,
            power: l.emission.power(),
            spd: l.emission.spd().clone(),
            beam_radius: l.beam_radius,
            wavelength_sampling: l.emission.sampling(),
        }
    }
}

impl Laser {
    /// A laser at `position` shining along `direction`.
    ///
    /// # Errors
    /// [`LightError::Parameter`] naming `position`, `direction`, `power` or `beam_radius`.
    pub fn new(
        position: DVec3,
        direction: DVec3,
        power: f64,
        spd: Arc<dyn SpectralPowerDistribution>,
        beam_radius: f64,
        wavelength_sampling: WavelengthSampling,
    ) -> Result<Self, LightError> {
        const L: &str = "Laser";
        let position = finite_point(L, "position", position)?;
        let direction = unit_direction(L, "direction", direction)?;
        let beam_radius = non_negative(L, "beam_radius", beam_radius)?;
        let emission = SpdLight::new(L, spd, power, wavelength_sampling)?;
        Ok(Self {
            emission,
            position,
            direction,
            beam_radius,
            frame: Frame::from_normal(direction),
        })
    }

    /// The beams' direction (unit).
    pub fn direction(&self) -> DVec3 {
        self.direction
    }
}

#[typetag::serde]
impl LightSource for Laser {
    fn next_beam(&self, rng: &mut dyn Rng) -> Beam {
        let (lambda, scale) = self.emission.wavelength(uniform(rng));
        let origin = if self.beam_radius > 0.0 {
            let [x, y] = sample_uniform_disk_concentric([uniform(rng), uniform(rng)]);
            self.position + self.frame.to_world(DVec3::new(x, y, 0.0)) * self.beam_radius
        } else {
            self.position
        };
        self.emission.count();
        Beam::new(origin, self.direction, lambda, scale)
    }
    crate::delegate_to_spd_light!(emission);
    fn flags(&self) -> Option<LightFlags> {
        Some(LightFlags { delta_position: self.beam_radius == 0.0, delta_direction: true })
    }
}
