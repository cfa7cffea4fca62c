//! [`ObjectLight`]: any object of a scene made to glow (`objects[i].emission`), a Lambertian
//! emitter over its shape's whole surface, sampled uniformly by area.
//!
//! | field | unit | default | meaning |
//! |---|---|---|---|
//! | `power` | W | one of `power`, `lumens`, `radiance` | total emitted power (both sides together when two-sided) |
//! | `lumens` | lm | one of `power`, `lumens`, `radiance` | total luminous flux instead: `power = lumens / luminous_efficacy(spd)` |
//! | `radiance` | W m^-2 sr^-1 | one of `power`, `lumens`, `radiance` | the radiance of every point instead (the spectral radiance integrated over wavelength; `spd` gives its shape): `power = radiance * pi * area`, twice that when two-sided, found when the shape is known. Renderers that give emitters a radiance (Mitsuba's `area`) translate to this |
//! | `spd` | SPD | required | spectrum |
//! | `two_sided` | | `false` | emit from both sides of the surface (else only outwards: along the geometric normal) |
//!
//! ```json
//! {"shape": {"type": "Sphere", "center": [0, 1, 0], "radius": 0.1},
//!  "material": {"type": "Diffuse", "reflectance": 0.8},
//!  "emission": {"power": 20, "spd": {"type": "Blackbody", "kelvin": 2700}}}
//! {"shape": {"type": "Sphere", "center": [0, 1, 0], "radius": 0.1},
//!  "material": {"type": "Diffuse", "reflectance": 0.8},
//!  "emission": {"lumens": 800, "spd": {"type": "CieIlluminant", "name": "A"}}}
//! ```
//!
//! `lumens` is converted to watts when the scene is read (`spectrace_lights::power_from_keys`);
//! serialising an emission writes `power`, or `radiance` when it was given so.
//!
//! Every point of the surface emits the radiance `L = power / (pi * area)` (halved when
//! two-sided) into the hemisphere around its outward normal; the object's material still
//! reflects light that falls on it. The light is built by the renderer from the object, so it is
//! not a light type of scene files' `lights` list.

use std::f64::consts::PI;
use std::sync::Arc;

use glam::DVec3;
use rand::Rng;
use serde::{Deserialize, Serialize};
use spectrace_geometry::{Ray, Shape};
use spectrace_lights::{
    Beam, EmissionSample, LightBounds, LightError, LightFlags, LightSample, LightSource, SpdLight,
    WavelengthSampling, power_from_keys, uniform,
};
use spectrace_sampling::{Frame, sample_cosine_hemisphere_concentric};
use spectrace_spectrum::SpectralPowerDistribution;

/// The scene-file form of an object's emission. A scene file gives its output as `power` (W),
/// `lumens` (lm, converted to watts when read: `W = lm / luminous_efficacy(spd)`) or `radiance`
/// (W m^-2 sr^-1, converted when the light is built, since it needs the shape's area); it is
/// written back as `power`, or as `radiance` when given so.
#[derive(Debug, Clone, Deserialize)]
#[serde(try_from = "EmissionRepr")]
pub struct ObjectEmission {
    /// Total emitted power (W); ignored when `radiance` is given.
    pub power: f64,
    /// The radiance of every point (W m^-2 sr^-1, whole spectrum) instead of `power`: the
    /// light's power is then `radiance * pi * area` (twice when two-sided).
    pub radiance: Option<f64>,
    /// The spectrum.
    pub spd: Arc<dyn SpectralPowerDistribution>,
    /// Whether both sides emit.
    pub two_sided: bool,
}

/// What a scene file may write for [`ObjectEmission`]: exactly one of `power` and `lumens`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct EmissionRepr {
    #[serde(default)]
    power: Option<f64>,
    #[serde(default)]
    lumens: Option<f64>,
    #[serde(default)]
    radiance: Option<f64>,
    spd: Arc<dyn SpectralPowerDistribution>,
    #[serde(default)]
    two_sided: bool,
}

impl TryFrom<EmissionRepr> for ObjectEmission {
    type Error = LightError;
    fn try_from(r: EmissionRepr) -> Result<Self, LightError> {
        if let Some(radiance) = r.radiance {
            if r.power.is_some() || r.lumens.is_some() {
                return Err(LightError::parameter(
                    "emission",
                    "radiance",
                    radiance,
                    "`power` or `lumens` is given too: give exactly one of `power` (W), `lumens` \
                     (lm) or `radiance` (W m^-2 sr^-1)",
                ));
            }
            if !(radiance >= 0.0 && radiance.is_finite()) {
                return Err(LightError::parameter(
                    "emission",
                    "radiance",
                    radiance,
                    "must be a finite radiance of at least 0 W m^-2 sr^-1",
                ));
            }
            return Ok(Self {
                power: 0.0,
                radiance: Some(radiance),
                spd: r.spd,
                two_sided: r.two_sided,
            });
        }
        let power = power_from_keys("emission", r.power, r.lumens, None, false, r.spd.as_ref())?;
        Ok(Self { power, radiance: None, spd: r.spd, two_sided: r.two_sided })
    }
}

impl Serialize for ObjectEmission {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        let mut s = serializer.serialize_struct("ObjectEmission", 3)?;
        match self.radiance {
            Some(r) => s.serialize_field("radiance", &r)?,
            None => s.serialize_field("power", &self.power)?,
        }
        s.serialize_field("spd", &self.spd)?;
        s.serialize_field("two_sided", &self.two_sided)?;
        s.end()
    }
}

/// A glowing object: a Lambertian emitter over a shape's surface.
#[derive(Debug, Clone)]
pub struct ObjectLight {
    emission: SpdLight,
    shape: Shape,
    area: f64,
    two_sided: bool,
}

impl ObjectLight {
    /// The light of `shape` emitting `emission`.
    ///
    /// # Errors
    /// [`LightError`] naming `power` (negative or not finite) or `area` (a shape without area).
    pub fn new(shape: Shape, emission: &ObjectEmission) -> Result<Self, LightError> {
        let area = shape.area();
        let sides = if emission.two_sided { 2.0 } else { 1.0 };
        let power = emission.radiance.map_or(emission.power, |r| r * PI * area * sides);
        let spd_light =
            SpdLight::new("emission", emission.spd.clone(), power, WavelengthSampling::Importance)?;
        if !(area > 0.0 && area.is_finite()) {
            return Err(LightError::parameter(
                "emission",
                "area",
                area,
                "the shape must have a positive, finite area to emit",
            ));
        }
        Ok(Self { emission: spd_light, shape, area, two_sided: emission.two_sided })
    }

    /// Radiance of every point (W m^-2 sr^-1, whole spectrum): `power / (pi area)`, halved when
    /// two-sided.
    pub fn radiance(&self) -> f64 {
        let sides = if self.two_sided { 2.0 } else { 1.0 };
        self.emission.power() / (PI * self.area * sides)
    }

    /// Surface area (m^2).
    pub fn area(&self) -> f64 {
        self.area
    }

    /// Whether both sides emit.
    pub fn two_sided(&self) -> bool {
        self.two_sided
    }

    /// The outward normal at `position` (a point of the surface), found by crossing the surface
    /// there along `direction` (a ray from just before the point); `None` for a direction
    /// tangent to the surface or a point not on it.
    fn normal_crossing(&self, position: DVec3, direction: DVec3) -> Option<DVec3> {
        let eps = 1e-7 * (1.0 + position.abs().max_element());
        for d in [direction, -direction] {
            let ray = Ray { origin: position - d * eps, direction: d };
            if let Some(hit) = self.shape.intersect(&ray, 2.0 * eps)
                && (hit.point - position).length() <= 4.0 * eps
            {
                return Some(hit.geometric_normal);
            }
        }
        None
    }

    /// Directional density (sr^-1) of emission along `direction` from a point with `normal`.
    fn density(&self, normal: DVec3, direction: DVec3) -> f64 {
        let c = direction.dot(normal);
        if self.two_sided { c.abs() / (2.0 * PI) } else { c.max(0.0) / PI }
    }

    /// Samples an emission ray from four uniforms and the area sample's third one.
    fn sample(&self, u: [f64; 5]) -> EmissionSample {
        let p = self.shape.sample_area([u[0], u[1], u[4]]);
        let mut normal = p.normal;
        let mut local = sample_cosine_hemisphere_concentric([u[2], u[3]]);
        if self.two_sided {
            // The side from the low bit of the area sample's spare uniform: fold it.
            let side = (u[4] * 2.0).fract() >= 0.5;
            if side {
                local.z = -local.z;
                normal = -normal;
            }
        }
        let direction = Frame::from_normal(p.normal).to_world(local).normalize();
        EmissionSample {
            position: p.point,
            normal,
            direction,
            pdf_position: 1.0 / self.area,
            pdf_direction: self.density(p.normal, direction),
        }
    }
}

/// A third uniform for the area sample when the caller gives two (`sample_towards`,
/// `sample_emission`): the SplitMix64 hash of both uniforms' bits, as independent of them as a
/// fresh draw for the purpose (its 53 bits depend on all of theirs).
fn third_uniform(a: f64, b: f64) -> f64 {
    let z = spectrace_sampling::mix64(
        a.to_bits() ^ b.to_bits().rotate_left(29) ^ spectrace_sampling::GOLDEN_GAMMA,
    );
    (z >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

impl Serialize for ObjectLight {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        let mut s = serializer.serialize_struct("ObjectLight", 3)?;
        s.serialize_field("power", &self.emission.power())?;
        s.serialize_field("area", &self.area)?;
        s.serialize_field("two_sided", &self.two_sided)?;
        s.end()
    }
}

impl<'de> Deserialize<'de> for ObjectLight {
    fn deserialize<D: serde::Deserializer<'de>>(_deserializer: D) -> Result<Self, D::Error> {
        Err(serde::de::Error::custom(
            "ObjectLight is not a light type of the `lights` list: give an object an `emission` \
             ({\"power\": W, \"spd\": {...}}) to make it glow",
        ))
    }
}

impl ObjectLight {
    /// The beam of the five uniforms `u` (its origin and direction) and the wavelength drawn
    /// from `u_lambda`.
    fn beam(&self, u: [f64; 5], u_lambda: f64) -> Beam {
        let s = self.sample(u);
        let (lambda, scale) = self.emission.wavelength(u_lambda);
        self.emission.count();
        Beam::new(s.position, s.direction, lambda, scale)
    }
}

#[typetag::serde]
impl LightSource for ObjectLight {
    fn next_beam(&self, rng: &mut dyn Rng) -> Beam {
        let u = [uniform(rng), uniform(rng), uniform(rng), uniform(rng), uniform(rng)];
        self.beam(u, uniform(rng))
    }

    fn next_beam_at(&self, u_lambda: f64, rng: &mut dyn Rng) -> Beam {
        let u = [uniform(rng), uniform(rng), uniform(rng), uniform(rng), uniform(rng)];
        self.beam(u, u_lambda)
    }

    spectrace_lights::delegate_to_spd_light!(emission);

    fn flags(&self) -> Option<LightFlags> {
        Some(LightFlags::default())
    }
    fn light_bounds(&self) -> Option<LightBounds> {
        // Any shape: its box, shining every way (its normals are not known to lie in a cone).
        let b = self.shape.bounds();
        Some(LightBounds::anywhere(b.min, b.max, self.power()))
    }

    fn emission_density(&self, origin: DVec3, direction: DVec3) -> f64 {
        self.normal_crossing(origin, direction).map_or(0.0, |n| self.density(n, direction))
    }

    fn sample_towards(&self, receiver: DVec3, u: [f64; 2]) -> Option<LightSample> {
        let p = self.shape.sample_area([u[0], u[1], third_uniform(u[0], u[1])]);
        let to = receiver - p.point;
        let distance = to.length();
        if !(distance > 0.0 && distance.is_finite()) {
            return None;
        }
        let direction = to / distance;
        let c = direction.dot(p.normal);
        let cos = if self.two_sided { c.abs() } else { c.max(0.0) };
        let pdf = if c != 0.0 { distance * distance / (self.area * c.abs()) } else { 0.0 };
        Some(LightSample {
            position: p.point,
            direction,
            distance,
            intensity: self.radiance() * cos * self.area,
            pdf,
            delta: false,
        })
    }

    fn pdf_towards(&self, receiver: DVec3, position: DVec3) -> f64 {
        let to = receiver - position;
        let d2 = to.length_squared();
        let Some(n) = self.normal_crossing(position, -to) else { return 0.0 };
        let c = (to.dot(n) / d2.sqrt()).abs();
        if c > 0.0 { d2 / (self.area * c) } else { 0.0 }
    }

    fn emitted_radiance(&self, position: DVec3, direction: DVec3) -> f64 {
        let Some(n) = self.normal_crossing(position, direction) else { return 0.0 };
        let c = direction.dot(n);
        if c > 0.0 || (self.two_sided && c < 0.0) { self.radiance() } else { 0.0 }
    }

    fn sample_emission(&self, u: [f64; 4]) -> Option<EmissionSample> {
        Some(self.sample([u[0], u[1], u[2], u[3], third_uniform(u[0], u[1])]))
    }

    fn normal_at(&self, position: DVec3) -> Option<DVec3> {
        // Cross the surface at the point along a direction that is not tangent to it.
        [DVec3::X, DVec3::Y, DVec3::Z, DVec3::new(0.6, 0.48, 0.64)]
            .into_iter()
            .find_map(|d| self.normal_crossing(position, d))
    }

    fn pdf_emission(&self, position: DVec3, direction: DVec3) -> Option<(f64, f64)> {
        let n = self.normal_crossing(position, direction)?;
        Some((1.0 / self.area, self.density(n, direction)))
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use spectrace_spectrum::luminous_efficacy;

    fn emission(json: &str) -> Result<ObjectEmission, String> {
        serde_json::from_str(json).map_err(|e| e.to_string())
    }

    /// `radiance` becomes power once the shape is known: a unit square at radiance 2 emits
    /// `2 pi` W one-sided and `4 pi` W two-sided; it is written back as `radiance`, and given
    /// with `power` it is refused naming both.
    #[test]
    fn an_emission_given_as_radiance_takes_its_power_from_the_area() {
        let shape: Shape = serde_json::from_str(
            r#"{"type": "Rectangle", "corner": [0, 0, 0], "edge_u": [1, 0, 0], "edge_v": [0, 1, 0]}"#,
        )
        .unwrap();
        for (two_sided, power) in [(false, 2.0 * PI), (true, 4.0 * PI)] {
            let e = emission(&format!(
                r#"{{"radiance": 2, "spd": {{"type": "CieIlluminant", "name": "D65"}}, "two_sided": {two_sided}}}"#
            ))
            .unwrap();
            let light = ObjectLight::new(shape.clone(), &e).unwrap();
            assert!((light.power() - power).abs() < 1e-12, "{}", light.power());
            assert!((light.radiance() - 2.0).abs() < 1e-12);
            let json = serde_json::to_string(&e).unwrap();
            assert!(json.contains("\"radiance\":2.0") && !json.contains("power"), "{json}");
            assert_eq!(emission(&json).unwrap().radiance, Some(2.0));
        }
        let both = emission(
            r#"{"radiance": 2, "power": 1, "spd": {"type": "CieIlluminant", "name": "D65"}}"#,
        )
        .unwrap_err();
        assert!(both.contains("radiance") && both.contains("power"), "{both}");
        let negative =
            emission(r#"{"radiance": -1, "spd": {"type": "CieIlluminant", "name": "D65"}}"#)
                .unwrap_err();
        assert!(negative.contains("radiance"), "{negative}");
    }

    #[test]
    fn an_emission_in_lumens_is_read_as_watts_and_written_as_watts() {
        let e = emission(
            r#"{"lumens": 800, "spd": {"type": "CieIlluminant", "name": "A"}, "two_sided": true}"#,
        )
        .unwrap();
        assert_eq!(e.power, 800.0 / luminous_efficacy(e.spd.as_ref()));
        assert!(e.two_sided);
        let line =
            emission(r#"{"lumens": 683, "spd": {"type": "Monochromatic", "lambda_nm": 555}}"#)
                .unwrap();
        assert!((line.power - 1.0).abs() < 1e-12, "{}", line.power);
        assert!(!line.two_sided);
        // Written back in watts, and read again to the same power.
        let json = serde_json::to_string(&e).unwrap();
        assert!(json.contains(r#""power":"#) && !json.contains("lumens"), "{json}");
        assert_eq!(emission(&json).unwrap().power, e.power);
    }

    #[test]
    fn an_emission_needs_exactly_one_visible_output() {
        let spd = r#""spd": {"type": "Blackbody", "kelvin": 2700}"#;
        let cases = [
            (
                format!(r#"{{"power": 1, "lumens": 5, {spd}}}"#),
                "emission.lumens = 5.0: `power` is given too",
            ),
            (
                format!(r#"{{{spd}}}"#),
                "emission.power = missing: the light's output is missing: give exactly one of `power` (W) or `lumens` (lm)",
            ),
            (
                format!(r#"{{"lumens": -5, {spd}}}"#),
                "emission.lumens = -5.0: must be finite and >= 0",
            ),
            (
                format!(r#"{{"power": -1, {spd}}}"#),
                "emission.power = -1.0: must be finite and >= 0",
            ),
            (format!(r#"{{"candela": 5, {spd}}}"#), "unknown field `candela`"),
            (
                r#"{"lumens": 5, "spd": {"type": "Monochromatic", "lambda_nm": 1000}}"#.to_owned(),
                "emission.lumens = 5.0: the spectrum has no visible light",
            ),
        ];
        for (json, needle) in cases {
            let e = emission(&json).unwrap_err();
            assert!(e.contains(needle), "error for {json}\n  was: {e}\n  expected: {needle}");
        }
    }
}
