//! Lambertian area lights: [`RectangleLight`] and [`DiskLight`], one-sided by default.
//!
//! Every point of the surface emits the same radiance `L = power / (pi * area)` (halved when
//! two-sided) into the hemisphere around the normal, so beams start uniformly over the surface
//! and leave with a cosine-weighted direction. The normal of a rectangle is
//! `normalize(edge_u x edge_v)` (right-handed); a disk gives it explicitly.
//!
//! | light | field | unit | default | meaning |
//! |---|---|---|---|---|
//! | both | `power` | W | one of `power`, `lumens` | total emitted power (both sides together when two-sided) |
//! | both | `lumens` | lm | one of `power`, `lumens` | total luminous flux instead: `power = lumens / luminous_efficacy(spd)` (written back as `power`) |
//! | both | `spd` | SPD | required | spectrum |
//! | both | `two_sided` | | `false` | emit from both faces |
//! | both | `wavelength_sampling` | | `"importance"` | `"importance"` or `"equal_wavelengths"` |
//! | rectangle | `corner`, `edge_u`, `edge_v` | m | required | the rectangle `corner + s edge_u + t edge_v` |
//! | disk | `center` | m | required | centre |
//! | disk | `normal` | | required | emitting side |
//! | disk | `radius` | m | required | > 0 |
//!
//! ```json
//! {"type": "RectangleLight", "corner": [-0.25, 1.99, -0.25], "edge_u": [0.5, 0, 0],
//!  "edge_v": [0, 0, 0.5], "power": 50, "spd": {"type": "Blackbody", "kelvin": 4000}}
//! {"type": "DiskLight", "center": [0, 2, 0], "normal": [0, -1, 0], "radius": 0.2, "power": 20,
//!  "spd": {"type": "CieIlluminant", "name": "F11"}, "two_sided": true}
//! ```

use std::f64::consts::PI;
use std::sync::Arc;

use glam::DVec3;
use rand::Rng;
use serde::{Deserialize, Serialize};
use spectrace_spectrum::SpectralPowerDistribution;

use spectrace_sampling::{
    Frame, clamp_uniform, sample_cosine_hemisphere_concentric, sample_uniform_disk_concentric,
};

use crate::geometry::{finite_point, positive, unit_direction};
use crate::sky::rectangle_normal;
use crate::source::{power_from_keys, uniform};
use crate::{
    Beam, EmissionSample, LightBounds, LightError, LightFlags, LightSample, LightSource,
    LightSurface, SpdLight, WavelengthSampling,
};

/// A cosine-weighted direction around `frame.n()`, flipped to the back face with probability 1/2
/// when two-sided (the choice uses the top half of `u_side`).
fn lambertian_direction(frame: &Frame, two_sided: bool, u1: f64, u2: f64, u_side: f64) -> DVec3 {
    // Malley's method: a uniform point on the disk lifted to the hemisphere.
    let mut local = sample_cosine_hemisphere_concentric([u1, u2]);
    if two_sided && u_side >= 0.5 {
        local.z = -local.z;
    }
    frame.to_world(local).normalize()
}

/// Solid-angle density of a Lambertian emitter's directions: `cos / pi` on the emitting side,
/// `|cos| / (2 pi)` when two-sided.
fn lambertian_density(normal: DVec3, two_sided: bool, direction: DVec3) -> f64 {
    let c = direction.dot(normal);
    if two_sided { c.abs() / (2.0 * PI) } else { c.max(0.0) / PI }
}

/// Radiance `radiance` of a Lambertian face with front `normal` seen from the unit `direction`
/// leaving it: the front, and the back too when two-sided; 0 edge-on.
fn lambertian_radiance(normal: DVec3, two_sided: bool, radiance: f64, direction: DVec3) -> f64 {
    let c = direction.dot(normal);
    if c > 0.0 || (two_sided && c < 0.0) { radiance } else { 0.0 }
}

/// Solid-angle density (at `receiver`) with which an area light of front `normal` and area
/// `area`, sampled uniformly over its surface, gives the point `position`: `d^2 / (area |cos|)`,
/// 0 where [`area_sample`] gives pdf 0 (the back of a one-sided light, edge-on, or `receiver` on
/// the light).
fn area_pdf_towards(
    position: DVec3,
    normal: DVec3,
    area: f64,
    two_sided: bool,
    receiver: DVec3,
) -> f64 {
    let to = receiver - position;
    let distance = to.length();
    if !(distance > 0.0 && distance.is_finite()) {
        return 0.0;
    }
    let cos = (to / distance).dot(normal);
    let cos = if two_sided { cos.abs() } else { cos.max(0.0) };
    if cos > 0.0 { distance * distance / (area * cos) } else { 0.0 }
}

/// An emission ray of a Lambertian area light from `position` (drawn with area density
/// `1 / area`), its direction from `u_dir` as [`lambertian_direction`] distributes them; when
/// two-sided, the side is the top half of `u_dir[1]`, which is then stretched back to `[0, 1)`.
/// `None` for a grazing direction of density 0 (only at the rim of the uniforms' range).
fn area_emission(
    frame: &Frame,
    two_sided: bool,
    area: f64,
    position: DVec3,
    u_dir: [f64; 2],
) -> Option<EmissionSample> {
    let (u1, mut u2) = (u_dir[0], u_dir[1]);
    let back = two_sided && u2 >= 0.5;
    if two_sided {
        // Exact in binary floating point: 2 u is a doubling, 2 u - 1 an exact subtraction.
        u2 = if back { 2.0 * u2 - 1.0 } else { 2.0 * u2 };
    }
    let direction = lambertian_direction(frame, two_sided, u1, u2, if back { 1.0 } else { 0.0 });
    let pdf_direction = lambertian_density(frame.n(), two_sided, direction);
    if !(pdf_direction > 0.0) {
        return None;
    }
    Some(EmissionSample {
        position,
        normal: if back { -frame.n() } else { frame.n() },
        direction,
        pdf_position: 1.0 / area,
        pdf_direction,
    })
}

/// The sample of an area light at `position` (normal `normal`, area `area`, radiance `radiance`)
/// as seen from `receiver`.
fn area_sample(
    position: DVec3,
    normal: DVec3,
    area: f64,
    radiance: f64,
    two_sided: bool,
    receiver: DVec3,
) -> Option<LightSample> {
    let to = receiver - position;
    let distance = to.length();
    if !(distance > 0.0 && distance.is_finite()) {
        return None;
    }
    let direction = to / distance;
    let cos = direction.dot(normal);
    let cos = if two_sided { cos.abs() } else { cos.max(0.0) };
    let pdf = if cos > 0.0 { distance * distance / (area * cos) } else { 0.0 };
    Some(LightSample {
        position,
        direction,
        distance,
        intensity: radiance * cos * area,
        pdf,
        delta: false,
    })
}

/// A Lambertian emitter on the rectangle `corner + s edge_u + t edge_v`.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(try_from = "RectangleRepr", into = "RectangleRepr")]
pub struct RectangleLight {
    emission: SpdLight,
    corner: DVec3,
    edge_u: DVec3,
    edge_v: DVec3,
    two_sided: bool,
    frame: Frame,
    area: f64,
}

/// Scene-file form of [`RectangleLight`].
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct RectangleRepr {
    corner: DVec3,
    edge_u: DVec3,
    edge_v: DVec3,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    power: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    lumens: Option<f64>,
    spd: Arc<dyn SpectralPowerDistribution>,
    #[serde(default)]
    two_sided: bool,
    #[serde(default)]
    wavelength_sampling: WavelengthSampling,
}

impl TryFrom<RectangleRepr> for RectangleLight {
    type Error = LightError;
    fn try_from(r: RectangleRepr) -> Result<Self, LightError> {
        let power =
            power_from_keys("RectangleLight", r.power, r.lumens, None, false, r.spd.as_ref())?;
        Self::new(r.corner, r.edge_u, r.edge_v, power, r.spd, r.two_sided, r.wavelength_sampling)
    }
}

impl From<RectangleLight> for RectangleRepr {
    fn from(l: RectangleLight) -> Self {
        Self {
            corner: l.corner,
            edge_u: l.edge_u,
            edge_v: l.edge_v,
            power: Some(l.emission.power()),
            lumens: None,
            spd: l.emission.spd().clone(),
            two_sided: l.two_sided,
            wavelength_sampling: l.emission.sampling(),
        }
    }
}

impl RectangleLight {
    /// A Lambertian rectangle emitting towards `edge_u x edge_v` (both ways if `two_sided`).
    ///
    /// # Errors
    /// [`LightError::Parameter`] naming `corner`, `edge_u`/`edge_v` (degenerate rectangle) or
    /// `power`.
    pub fn new(
        corner: DVec3,
        edge_u: DVec3,
        edge_v: DVec3,
        power: f64,
        spd: Arc<dyn SpectralPowerDistribution>,
        two_sided: bool,
        wavelength_sampling: WavelengthSampling,
    ) -> Result<Self, LightError> {
        const L: &str = "RectangleLight";
        let corner = finite_point(L, "corner", corner)?;
        let (normal, area) = rectangle_normal(L, edge_u, edge_v)?;
        if !(corner + edge_u + edge_v).is_finite() {
            return Err(LightError::parameter(
                L,
                "corner",
                corner.to_array(),
                "too large: corner + edge_u + edge_v overflows",
            ));
        }
        let emission = SpdLight::new(L, spd, power, wavelength_sampling)?;
        Ok(Self {
            emission,
            corner,
            edge_u,
            edge_v,
            two_sided,
            frame: Frame::from_normal(normal),
            area,
        })
    }

    /// Emitted radiance (W m^-2 sr^-1, whole spectrum): `power / (pi * area)`, halved if two-sided.
    pub fn radiance(&self) -> f64 {
        self.emission.power() / (PI * self.area * if self.two_sided { 2.0 } else { 1.0 })
    }

    /// The unit normal of the emitting side.
    pub fn normal(&self) -> DVec3 {
        self.frame.n()
    }

    /// The rectangle's area (m^2).
    pub fn area(&self) -> f64 {
        self.area
    }

    /// The point `corner + s edge_u + t edge_v`, `s` and `t` clamped into `[0, 1)` (NaN to 0).
    fn point(&self, s: f64, t: f64) -> DVec3 {
        self.corner + self.edge_u * clamp_uniform(s) + self.edge_v * clamp_uniform(t)
    }
}

#[typetag::serde]
impl LightSource for RectangleLight {
    fn next_beam(&self, rng: &mut dyn Rng) -> Beam {
        self.next_beam_at(uniform(rng), rng)
    }
    fn next_beam_at(&self, u_lambda: f64, rng: &mut dyn Rng) -> Beam {
        let (lambda, scale) = self.emission.wavelength(u_lambda);
        let origin = self.corner + self.edge_u * uniform(rng) + self.edge_v * uniform(rng);
        let (u1, u2, u3) = (uniform(rng), uniform(rng), uniform(rng));
        let direction = lambertian_direction(&self.frame, self.two_sided, u1, u2, u3);
        self.emission.count();
        Beam::new(origin, direction, lambda, scale)
    }
    crate::delegate_to_spd_light!(emission);
    fn flags(&self) -> Option<LightFlags> {
        Some(LightFlags::default())
    }
    fn light_bounds(&self) -> Option<LightBounds> {
        let (c, u, v) = (self.corner, self.edge_u, self.edge_v);
        let points = [c, c + u, c + v, c + u + v];
        Some(LightBounds::surface(&points, self.frame.n(), self.power(), self.two_sided))
    }
    fn emission_density(&self, _origin: DVec3, direction: DVec3) -> f64 {
        lambertian_density(self.frame.n(), self.two_sided, direction)
    }
    fn sample_towards(&self, receiver: DVec3, u: [f64; 2]) -> Option<LightSample> {
        let position = self.point(u[0], u[1]);
        area_sample(position, self.frame.n(), self.area, self.radiance(), self.two_sided, receiver)
    }
    fn pdf_towards(&self, receiver: DVec3, position: DVec3) -> f64 {
        area_pdf_towards(position, self.frame.n(), self.area, self.two_sided, receiver)
    }
    fn emitted_radiance(&self, _position: DVec3, direction: DVec3) -> f64 {
        lambertian_radiance(self.frame.n(), self.two_sided, self.radiance(), direction)
    }
    fn sample_emission(&self, u: [f64; 4]) -> Option<EmissionSample> {
        let position = self.point(u[0], u[1]);
        area_emission(&self.frame, self.two_sided, self.area, position, [u[2], u[3]])
    }
    fn pdf_emission(&self, _position: DVec3, direction: DVec3) -> Option<(f64, f64)> {
        Some((1.0 / self.area, lambertian_density(self.frame.n(), self.two_sided, direction)))
    }
    fn normal_at(&self, _position: DVec3) -> Option<DVec3> {
        Some(self.frame.n())
    }
    fn surface(&self) -> Option<LightSurface> {
        Some(LightSurface::Rectangle {
            corner: self.corner,
            edge_u: self.edge_u,
            edge_v: self.edge_v,
        })
    }
}

/// A Lambertian emitter on a disk.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(try_from = "DiskRepr", into = "DiskRepr")]
pub struct DiskLight {
    emission: SpdLight,
    center: DVec3,
    normal: DVec3,
    radius: f64,
    two_sided: bool,
    frame: Frame,
}

/// Scene-file form of [`DiskLight`].
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct DiskRepr {
    center: DVec3,
    normal: DVec3,
    radius: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    power: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    lumens: Option<f64>,
    spd: Arc<dyn SpectralPowerDistribution>,
    #[serde(default)]
    two_sided: bool,
    #[serde(default)]
    wavelength_sampling: WavelengthSampling,
}

impl TryFrom<DiskRepr> for DiskLight {
    type Error = LightError;
    fn try_from(r: DiskRepr) -> Result<Self, LightError> {
        let power = power_from_keys("DiskLight", r.power, r.lumens, None, false, r.spd.as_ref())?;
        Self::new(r.center, r.normal, r.radius, power, r.spd, r.two_sided, r.wavelength_sampling)
    }
}

impl From<DiskLight> for DiskRepr {
    fn from(l: DiskLight) -> Self {
        Self {
            center: l.center,
            normal: l.normal,
            radius: l.radius,
            power: Some(l.emission.power()),
            lumens: None,
            spd: l.emission.spd().clone(),
            two_sided: l.two_sided,
            wavelength_sampling: l.emission.sampling(),
        }
    }
}

impl DiskLight {
    /// A Lambertian disk of `radius` at `center` emitting towards `normal`.
    ///
    /// # Errors
    /// [`LightError::Parameter`] naming `center`, `normal`, `radius` or `power`.
    pub fn new(
        center: DVec3,
        normal: DVec3,
        radius: f64,
        power: f64,
        spd: Arc<dyn SpectralPowerDistribution>,
        two_sided: bool,
        wavelength_sampling: WavelengthSampling,
    ) -> Result<Self, LightError> {
        const L: &str = "DiskLight";
        let center = finite_point(L, "center", center)?;
        let normal = unit_direction(L, "normal", normal)?;
        let radius = positive(L, "radius", radius)?;
        let area = PI * radius * radius;
        if !area.is_finite() {
            return Err(LightError::parameter(
                L,
                "radius",
                radius,
                "too large: the area overflows",
            ));
        }
        if !(area > 0.0) {
            return Err(LightError::parameter(
                L,
                "radius",
                radius,
                "too small: the area underflows to 0",
            ));
        }
        let emission = SpdLight::new(L, spd, power, wavelength_sampling)?;
        Ok(Self { emission, center, normal, radius, two_sided, frame: Frame::from_normal(normal) })
    }

    /// The disk's area (m^2).
    pub fn area(&self) -> f64 {
        PI * self.radius * self.radius
    }

    /// Emitted radiance (W m^-2 sr^-1, whole spectrum).
    pub fn radiance(&self) -> f64 {
        self.emission.power() / (PI * self.area() * if self.two_sided { 2.0 } else { 1.0 })
    }

    fn point(&self, u1: f64, u2: f64) -> DVec3 {
        let [x, y] = sample_uniform_disk_concentric([u1, u2]);
        self.center + self.frame.to_world(DVec3::new(x, y, 0.0)) * self.radius
    }
}

#[typetag::serde]
impl LightSource for DiskLight {
    fn next_beam(&self, rng: &mut dyn Rng) -> Beam {
        self.next_beam_at(uniform(rng), rng)
    }
    fn next_beam_at(&self, u_lambda: f64, rng: &mut dyn Rng) -> Beam {
        let (lambda, scale) = self.emission.wavelength(u_lambda);
        let origin = self.point(uniform(rng), uniform(rng));
        let (u1, u2, u3) = (uniform(rng), uniform(rng), uniform(rng));
        let direction = lambertian_direction(&self.frame, self.two_sided, u1, u2, u3);
        self.emission.count();
        Beam::new(origin, direction, lambda, scale)
    }
    crate::delegate_to_spd_light!(emission);
    fn flags(&self) -> Option<LightFlags> {
        Some(LightFlags::default())
    }
    fn light_bounds(&self) -> Option<LightBounds> {
        // The disk's box: along each axis, radius times the sine of its angle to the normal.
        let n = self.frame.n();
        let extent = (DVec3::ONE - n * n).max(DVec3::ZERO).powf(0.5) * self.radius;
        let points = [self.center - extent, self.center + extent];
        Some(LightBounds::surface(&points, n, self.power(), self.two_sided))
    }
    fn emission_density(&self, _origin: DVec3, direction: DVec3) -> f64 {
        lambertian_density(self.normal, self.two_sided, direction)
    }
    fn sample_towards(&self, receiver: DVec3, u: [f64; 2]) -> Option<LightSample> {
        area_sample(
            self.point(u[0], u[1]),
            self.normal,
            self.area(),
            self.radiance(),
            self.two_sided,
            receiver,
        )
    }
    fn pdf_towards(&self, receiver: DVec3, position: DVec3) -> f64 {
        area_pdf_towards(position, self.normal, self.area(), self.two_sided, receiver)
    }
    fn emitted_radiance(&self, _position: DVec3, direction: DVec3) -> f64 {
        lambertian_radiance(self.normal, self.two_sided, self.radiance(), direction)
    }
    fn sample_emission(&self, u: [f64; 4]) -> Option<EmissionSample> {
        let position = self.point(u[0], u[1]);
        area_emission(&self.frame, self.two_sided, self.area(), position, [u[2], u[3]])
    }
    fn pdf_emission(&self, _position: DVec3, direction: DVec3) -> Option<(f64, f64)> {
        Some((1.0 / self.area(), lambertian_density(self.normal, self.two_sided, direction)))
    }
    fn normal_at(&self, _position: DVec3) -> Option<DVec3> {
        Some(self.normal)
    }
    fn surface(&self) -> Option<LightSurface> {
        Some(LightSurface::Disk { center: self.center, normal: self.normal, radius: self.radius })
    }
}
