//! [`Laser`]: a beam from one point in one direction (seed 2.4.1), optionally of finite width.
//!
//! | field | unit | default | meaning |
//! |---|---|---|---|
//! | `position` | m, `[x, y, z]` | required | where the beams start (the beam's centre) |
//! | `direction` | `[x, y, z]` | required | direction of the beams (normalised; must be non-zero) |
//! | `power` | W | one of `power`, `lumens` | total emitted power |
//! | `lumens` | lm | one of `power`, `lumens` | total luminous flux instead: `power = lumens / luminous_efficacy(spd)` (written back as `power`) |
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

/// The next-event sample of a parallel beam that starts at `position` on the light and reaches
/// the receiver `distance` along `direction`, carrying `irradiance` (W/m^2 across the beam):
/// `intensity = irradiance distance^2`, so that `intensity cos / distance^2` is the irradiance;
/// `pdf` 1, a delta. `None` upstream (`distance <= 0`) or when the squared distance or the
/// intensity is not a finite positive number.
pub(crate) fn beam_through(
    position: DVec3,
    direction: DVec3,
    distance: f64,
    irradiance: f64,
) -> Option<LightSample> {
    let squared = distance * distance;
    let intensity = irradiance * squared;
    (distance > 0.0 && squared.is_normal() && intensity.is_finite()).then_some(LightSample {
        position,
        direction,
        distance,
        intensity,
        pdf: 1.0,
        delta: true,
    })
}

/// How far (in `1 - cos` of the angle between them) a direction may be from a laser's or a sky's
/// and still count as its direction in `pdf_emission`: about 4.5e-5 rad.
pub(crate) const SAME_DIRECTION: f64 = 1e-9;

use crate::geometry::{finite_point, non_negative, unit_direction};
use crate::source::{power_from_keys, uniform};
use crate::{
    Beam, EmissionSample, LightError, LightFlags, LightSample, LightSource, SpdLight,
    WavelengthSampling,
};

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
    #[serde(default, skip_serializing_if = "Option::is_none")]
    power: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    lumens: Option<f64>,
    spd: Arc<dyn SpectralPowerDistribution>,
    #[serde(default)]
    beam_radius: f64,
    #[serde(default)]
    wavelength_sampling: WavelengthSampling,
}

impl TryFrom<LaserRepr> for Laser {
    type Error = LightError;
    fn try_from(r: LaserRepr) -> Result<Self, LightError> {
        let power = power_from_keys("Laser", r.power, r.lumens, None, false, r.spd.as_ref())?;
        Self::new(r.position, r.direction, power, r.spd, r.beam_radius, r.wavelength_sampling)
    }
}

impl From<Laser> for LaserRepr {
    fn from(l: Laser) -> Self {
        Self {
            position: l.position,
            direction: l.direction,
            power: Some(l.emission.power()),
            lumens: None,
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

    /// A beam origin from two uniforms: the position, or a point uniform on the disk of
    /// `beam_radius` around it, perpendicular to the direction.
    fn origin_from(&self, u: [f64; 2]) -> DVec3 {
        if self.beam_radius > 0.0 {
            let [x, y] = sample_uniform_disk_concentric(u);
            self.position + self.frame.to_world(DVec3::new(x, y, 0.0)) * self.beam_radius
        } else {
            self.position
        }
    }

    /// Irradiance inside a beam of finite radius on a surface facing it (W/m^2), `power / (pi
    /// beam_radius^2)`; 0 for a beam of radius 0 (a delta) or one whose area is not a positive
    /// finite number.
    pub fn irradiance(&self) -> f64 {
        if self.beam_radius > 0.0 { self.emission.power() * self.pdf_position() } else { 0.0 }
    }

    /// Area density of the beam origins (m^-2): 1 (a delta) for a beam of radius 0, else
    /// `1 / (pi beam_radius^2)`, or 0 when that area is not a positive finite number (a radius
    /// so small that it underflows, or so large that it overflows).
    fn pdf_position(&self) -> f64 {
        if self.beam_radius > 0.0 {
            let area = std::f64::consts::PI * self.beam_radius * self.beam_radius;
            if area > 0.0 && area.is_finite() { 1.0 / area } else { 0.0 }
        } else {
            1.0
        }
    }
}

#[typetag::serde]
impl LightSource for Laser {
    fn next_beam(&self, rng: &mut dyn Rng) -> Beam {
        self.next_beam_at(uniform(rng), rng)
    }
    fn next_beam_at(&self, u_lambda: f64, rng: &mut dyn Rng) -> Beam {
        let (lambda, scale) = self.emission.wavelength(u_lambda);
        let origin = if self.beam_radius > 0.0 {
            self.origin_from([uniform(rng), uniform(rng)])
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
    /// For a beam of finite radius, the one beam through `receiver`: it starts on the beam's
    /// disk, on the line through the receiver against the direction, and gives the receiver the
    /// beam's [`irradiance`](Laser::irradiance) times the cosine there. `intensity` is that
    /// irradiance times the squared distance, `pdf` 1, `delta` true. `None` outside the beam,
    /// upstream of the laser, for a beam of radius 0 (a line no point can sample: only light
    /// paths find it), or when the squared distance is not a finite positive number.
    fn sample_towards(&self, receiver: DVec3, _u: [f64; 2]) -> Option<LightSample> {
        let irradiance = self.irradiance();
        let distance = (receiver - self.position).dot(self.direction);
        let position = receiver - self.direction * distance;
        let inside = (position - self.position).length() <= self.beam_radius;
        (irradiance > 0.0 && inside)
            .then(|| beam_through(position, self.direction, distance, irradiance))
            .flatten()
    }
    /// The direction for a beam of finite radius (the disk its beams start from faces it),
    /// `None` for a beam of radius 0 (a point).
    fn normal_at(&self, _position: DVec3) -> Option<DVec3> {
        (self.beam_radius > 0.0).then_some(self.direction)
    }
    /// The direction is always the laser's, with `pdf_direction` 1 standing for the delta; the
    /// origin as [`next_beam`](LightSource::next_beam) draws it (from `u[0]`, `u[1]`). The normal
    /// is the direction for a beam of finite radius (the disk the beams start from faces it), zero
    /// for a point. `None` when the beam is so wide or narrow that its area is not representable.
    fn sample_emission(&self, u: [f64; 4]) -> Option<EmissionSample> {
        let pdf_position = self.pdf_position();
        (pdf_position > 0.0).then(|| EmissionSample {
            position: self.origin_from([u[0], u[1]]),
            normal: if self.beam_radius > 0.0 { self.direction } else { DVec3::ZERO },
            direction: self.direction,
            pdf_position,
            pdf_direction: 1.0,
        })
    }
    /// `(pdf_position, 1)` along the laser's direction (1 standing for the delta: the caller
    /// learns that it is one from [`flags`](LightSource::flags)), `(pdf_position, 0)` along any
    /// other. `pdf_position` is 1 (a delta) for a beam of radius 0, else `1 / (pi beam_radius^2)`.
    fn pdf_emission(&self, _position: DVec3, direction: DVec3) -> Option<(f64, f64)> {
        let along = direction.dot(self.direction) >= 1.0 - SAME_DIRECTION;
        Some((self.pdf_position(), if along { 1.0 } else { 0.0 }))
    }
}
