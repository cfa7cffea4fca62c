//! [`Sky`]: parallel beams over a rectangle, the seed's "array of lasers" (seed 2.4.2).
//!
//! The rectangle is `corner + s * edge_u + t * edge_v` for `s, t` in `[0, 1]`: beams start
//! uniformly over it and all travel along `direction`. (The seed's corners A and B are
//! `corner` and `corner + edge_u + edge_v`; two edge vectors make the orientation explicit.)
//!
//! | field | unit | default | meaning |
//! |---|---|---|---|
//! | `corner` | m | required | one corner of the rectangle |
//! | `edge_u`, `edge_v` | m | required | the two edges from `corner`; must span a rectangle (not parallel, not zero) |
//! | `direction` | | required | direction of every beam; must not lie in the rectangle's plane |
//! | `power` | W | one of `power`, `lumens` | total power through the rectangle |
//! | `lumens` | lm | one of `power`, `lumens` | total luminous flux through it instead: `power = lumens / luminous_efficacy(spd)` (written back as `power`) |
//! | `spd` | SPD | required | spectrum, e.g. `{"type": "CieIlluminant", "name": "D65"}` |
//! | `wavelength_sampling` | | `"importance"` | `"importance"` or `"equal_wavelengths"` |
//!
//! ```json
//! {"type": "Sky", "corner": [-1, 2, -1], "edge_u": [2, 0, 0], "edge_v": [0, 0, 2],
//!  "direction": [0, -1, 0], "power": 10, "spd": {"type": "CieIlluminant", "name": "D65"}}
//! ```

use std::sync::Arc;

use glam::DVec3;
use rand::Rng;
use serde::{Deserialize, Serialize};
use spectrace_spectrum::SpectralPowerDistribution;

use crate::geometry::{finite_point, safe_length, unit_direction};
use crate::laser::beam_through;
use crate::source::{power_from_keys, uniform};
use crate::{
    Beam, EmissionSample, LightError, LightFlags, LightSample, LightSource, SpdLight,
    WavelengthSampling,
};
use spectrace_sampling::clamp_uniform;

/// Parallel beams starting uniformly over a rectangle.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(try_from = "SkyRepr", into = "SkyRepr")]
pub struct Sky {
    emission: SpdLight,
    corner: DVec3,
    edge_u: DVec3,
    edge_v: DVec3,
    direction: DVec3,
    /// The rectangle's unit normal on the side the beams leave (`normal . direction > 0`).
    normal: DVec3,
    /// The rectangle's area (m^2).
    area: f64,
    /// Dual vectors of the edges in the rectangle's plane: a point `p` of the plane is
    /// `corner + s edge_u + t edge_v` with `s = (p - corner) . dual_u`, `t = (p - corner) . dual_v`.
    dual_u: DVec3,
    /// See `dual_u`.
    dual_v: DVec3,
}

/// Scene-file form of [`Sky`].
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct SkyRepr {
    corner: DVec3,
    edge_u: DVec3,
    edge_v: DVec3,
    direction: DVec3,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    power: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    lumens: Option<f64>,
    spd: Arc<dyn SpectralPowerDistribution>,
    #[serde(default)]
    wavelength_sampling: WavelengthSampling,
}

impl TryFrom<SkyRepr> for Sky {
    type Error = LightError;
    fn try_from(r: SkyRepr) -> Result<Self, LightError> {
        let power = power_from_keys("Sky", r.power, r.lumens, None, false, r.spd.as_ref())?;
        Self::new(r.corner, r.edge_u, r.edge_v, r.direction, power, r.spd, r.wavelength_sampling)
    }
}

impl From<Sky> for SkyRepr {
    fn from(s: Sky) -> Self {
        Self {
            corner: s.corner,
            edge_u: s.edge_u,
            edge_v: s.edge_v,
            direction: s.direction,
            power: Some(s.emission.power()),
            lumens: None,
            spd: s.emission.spd().clone(),
            wavelength_sampling: s.emission.sampling(),
        }
    }
}

/// Checks that two edges span a parallelogram of non-zero, representable area; returns its unit
/// normal and its area. The edges are judged on their directions (normalised first), so huge or
/// tiny finite edges are not mistaken for parallel ones.
pub(crate) fn rectangle_normal(
    light: &'static str,
    edge_u: DVec3,
    edge_v: DVec3,
) -> Result<(DVec3, f64), LightError> {
    finite_point(light, "edge_u", edge_u)?;
    finite_point(light, "edge_v", edge_v)?;
    let unit_u = unit_direction(light, "edge_u", edge_u)?;
    let unit_v = unit_direction(light, "edge_v", edge_v)?;
    let cross = unit_u.cross(unit_v);
    let sin = cross.length();
    if !(sin > 1e-12) {
        return Err(LightError::parameter(
            light,
            "edge_v",
            edge_v.to_array(),
            "must not be parallel to edge_u (the rectangle is degenerate)",
        ));
    }
    let (len_u, len_v) = (safe_length(edge_u), safe_length(edge_v));
    let area = len_u * len_v * sin;
    if !area.is_finite() {
        let (field, value) = if len_u >= len_v { ("edge_u", edge_u) } else { ("edge_v", edge_v) };
        return Err(LightError::parameter(
            light,
            field,
            value.to_array(),
            "too large: the area |edge_u| |edge_v| sin(angle) overflows",
        ));
    }
    if !(area > 0.0) {
        return Err(LightError::parameter(
            light,
            "edge_v",
            edge_v.to_array(),
            "too small: the area |edge_u| |edge_v| sin(angle) underflows to 0",
        ));
    }
    Ok((cross / sin, area))
}

impl Sky {
    /// Parallel beams along `direction` from the rectangle `corner + s edge_u + t edge_v`.
    ///
    /// # Errors
    /// [`LightError::Parameter`] naming `corner`, `edge_u`/`edge_v` (degenerate rectangle),
    /// `direction` (zero, or lying in the rectangle's plane) or `power`.
    pub fn new(
        corner: DVec3,
        edge_u: DVec3,
        edge_v: DVec3,
        direction: DVec3,
        power: f64,
        spd: Arc<dyn SpectralPowerDistribution>,
        wavelength_sampling: WavelengthSampling,
    ) -> Result<Self, LightError> {
        const L: &str = "Sky";
        let corner = finite_point(L, "corner", corner)?;
        let (normal, area) = rectangle_normal(L, edge_u, edge_v)?;
        let direction = unit_direction(L, "direction", direction)?;
        if direction.dot(normal).abs() < 1e-9 {
            return Err(LightError::parameter(
                L,
                "direction",
                direction.to_array(),
                "lies in the rectangle's plane, so no beam would cross it",
            ));
        }
        let emission = SpdLight::new(L, spd, power, wavelength_sampling)?;
        let normal = if direction.dot(normal) > 0.0 { normal } else { -normal };
        // edge_u . (edge_v x normal) = normal . (edge_u x edge_v) = +-area, never 0 here.
        let dual_u = edge_v.cross(normal) / edge_u.dot(edge_v.cross(normal));
        let dual_v = normal.cross(edge_u) / edge_v.dot(normal.cross(edge_u));
        Ok(Self { emission, corner, edge_u, edge_v, direction, normal, area, dual_u, dual_v })
    }

    /// Where `(s, t)` in the unit square lands on the rectangle.
    pub fn point(&self, s: f64, t: f64) -> DVec3 {
        self.corner + self.edge_u * s + self.edge_v * t
    }

    /// The rectangle's area (m^2).
    pub fn area(&self) -> f64 {
        self.area
    }

    /// Irradiance on a surface facing the beams (W/m^2): the power spread over the rectangle's
    /// area projected across the direction, `power / (area cos)`.
    pub fn irradiance(&self) -> f64 {
        self.emission.power() / (self.area * self.direction.dot(self.normal))
    }
}

#[typetag::serde]
impl LightSource for Sky {
    fn next_beam(&self, rng: &mut dyn Rng) -> Beam {
        self.next_beam_at(uniform(rng), rng)
    }
    fn next_beam_at(&self, u_lambda: f64, rng: &mut dyn Rng) -> Beam {
        let (lambda, scale) = self.emission.wavelength(u_lambda);
        let origin = self.point(uniform(rng), uniform(rng));
        self.emission.count();
        Beam::new(origin, self.direction, lambda, scale)
    }
    crate::delegate_to_spd_light!(emission);
    fn flags(&self) -> Option<LightFlags> {
        Some(LightFlags { delta_position: false, delta_direction: true })
    }
    /// An origin uniform on the rectangle (from `u[0]`, `u[1]`, as
    /// [`next_beam`](LightSource::next_beam) draws them), the sky's direction with
    /// `pdf_direction` 1 standing for the delta, `pdf_position = 1 / area`. The normal is the
    /// rectangle's, on the side the beams leave.
    fn sample_emission(&self, u: [f64; 4]) -> Option<EmissionSample> {
        Some(EmissionSample {
            position: self.point(clamp_uniform(u[0]), clamp_uniform(u[1])),
            normal: self.normal,
            direction: self.direction,
            pdf_position: 1.0 / self.area,
            pdf_direction: 1.0,
        })
    }
    /// The one beam that passes through `receiver`: it starts where the line through the
    /// receiver against the sky's direction crosses the rectangle, and gives the receiver the
    /// sky's [`irradiance`](Sky::irradiance) times the cosine there, as the beams do on average.
    /// `intensity` is that irradiance times the squared distance (so that `intensity cos /
    /// distance^2` is the irradiance, as for every light), `pdf` 1 and `delta` true (no camera
    /// ray can hit a delta direction). `None` when no beam passes through the receiver: it is
    /// beside the rectangle's shadow, upstream of it, on it, or so far that the squared
    /// distance is not a finite positive number.
    fn sample_towards(&self, receiver: DVec3, _u: [f64; 2]) -> Option<LightSample> {
        let distance = (receiver - self.corner).dot(self.normal) / self.direction.dot(self.normal);
        let position = receiver - self.direction * distance;
        let offset = position - self.corner;
        let (s, t) = (offset.dot(self.dual_u), offset.dot(self.dual_v));
        let inside = (0.0..=1.0).contains(&s) && (0.0..=1.0).contains(&t);
        inside
            .then(|| beam_through(position, self.direction, distance, self.irradiance()))
            .flatten()
    }
    /// The rectangle's normal on the side the beams leave, at every point (BDPT turns the
    /// density of a beam's origin into the density of the point it lights with it).
    fn normal_at(&self, _position: DVec3) -> Option<DVec3> {
        Some(self.normal)
    }
    /// `(1 / area, 1)` along the sky's direction (1 standing for the delta: the caller learns
    /// that it is one from [`flags`](LightSource::flags)), `(1 / area, 0)` along any other.
    fn pdf_emission(&self, _position: DVec3, direction: DVec3) -> Option<(f64, f64)> {
        let along = direction.dot(self.direction) >= 1.0 - crate::laser::SAME_DIRECTION;
        Some((1.0 / self.area, if along { 1.0 } else { 0.0 }))
    }
}
