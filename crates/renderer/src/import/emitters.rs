//! Mitsuba's free emitters (not on a shape) as Spectrace lights, in power: `point` emits
//! `P = 4 pi integral(I)`, `spot` (linear falloff from `beam_width` to `cutoff_angle`)
//! `P = 2 pi integral(I) (1 - (sin c - sin b) / (c - b))`, and `2 pi integral(I) (1 - cos c)`
//! when `beam_width >= cutoff_angle`; `directional` of irradiance `E` becomes a `Sky` whose
//! rectangle, perpendicular to the beams, covers the scene's bounding sphere from outside it
//! (side `2 R`, `R` 1% beyond the sphere's radius), with `P = integral(E) (2 R)^2`; `constant`
//! of radiance `L` becomes a black sphere around the objects and the camera (1.5 times their
//! bounding sphere) glowing on both sides with radiance `L`: every point inside receives `L` from
//! every direction, exactly a constant environment (the outward half of its power is wasted by
//! the light tracer). `envmap` becomes the scene's `environment` (the same texels, read as
//! Mitsuba 3's spectral variants read them; `scale` kept, `to_world`'s rotation as `rotation`).

use std::f64::consts::PI;

use glam::{DMat4, DVec3};
use serde_json::json;

use super::Importer;
use super::params::Params;
use super::spectra::{Role, spectrum};
use super::values::{transform, vector};
use super::xml::{Element, ImportError, error_at};
use serde_json::Value;

impl Importer {
    /// Adds a top-level `<emitter>` (an `area` one with an id is only a definition).
    pub(super) fn emitter(&mut self, el: &Element) -> Result<(), ImportError> {
        if el.kind() == "area" {
            if el.attr("id").is_none() {
                return Err(error_at(
                    &el.loc,
                    "an area emitter outside a shape must have an id for shapes to <ref>",
                ));
            }
            return Ok(());
        }
        let p = Params::new(el);
        let m = p.get("to_world").map_or(Ok(DMat4::IDENTITY), transform)?;
        let intensity = |p: &Params<'_>| -> Result<Option<(f64, serde_json::Value)>, ImportError> {
            let i = p.get("intensity").ok_or_else(|| error_at(&el.loc, "needs `intensity`"))?;
            Ok(spectrum(i, Role::Emission)?.emission())
        };
        let light = match el.kind() {
            "point" => {
                let position = match p.get("position") {
                    Some(v) => vector(v)?,
                    None => m.transform_point3(DVec3::ZERO),
                };
                intensity(&p)?.map(|(i, spd)| {
                    json!({"type": "PointLight", "position": position.to_array(), "power": 4.0 * PI * i, "spd": spd})
                })
            }
            "spot" => {
                let cutoff = p.float("cutoff_angle", 20.0)?;
                let beam = p.float("beam_width", cutoff * 0.75)?;
                if !(cutoff > 0.0 && cutoff < 180.0 && beam >= 0.0) {
                    return Err(error_at(
                        &el.loc,
                        format!(
                            "cutoff_angle {cutoff}, beam_width {beam}: need 0 < cutoff < 180 and beam_width >= 0"
                        ),
                    ));
                }
                if p.get("texture").is_some() {
                    return Err(error_at(&el.loc, "a spot light's texture is not supported"));
                }
                let position = m.transform_point3(DVec3::ZERO);
                let direction = m.transform_vector3(DVec3::Z).normalize_or_zero();
                intensity(&p)?.map(|(i, spd)| {
                    let (c, b) = (cutoff.to_radians(), beam.to_radians());
                    if beam >= cutoff {
                        json!({"type": "UniformSpotLight", "position": position.to_array(), "direction": direction.to_array(),
                               "cone_angle": cutoff, "power": 2.0 * PI * i * (1.0 - c.cos()), "spd": spd})
                    } else {
                        let fraction = 1.0 - (c.sin() - b.sin()) / (c - b);
                        json!({"type": "FadingSpotLight", "position": position.to_array(), "direction": direction.to_array(),
                               "cone_angle": cutoff, "fade_per_angle": 1.0 / (cutoff - beam), "power": 2.0 * PI * i * fraction, "spd": spd})
                    }
                })
            }
            "directional" => {
                let direction = match p.get("direction") {
                    Some(v) => vector(v)?,
                    None => m.transform_vector3(DVec3::Z),
                };
                let direction = direction.normalize_or_zero();
                if direction == DVec3::ZERO {
                    return Err(error_at(&el.loc, "the direction is zero"));
                }
                let e =
                    p.get("irradiance").ok_or_else(|| error_at(&el.loc, "needs `irradiance`"))?;
                let spec = spectrum(e, Role::Emission)?;
                p.finish()?;
                match spec.emission() {
                    Some((irradiance, spd)) => {
                        self.directional.push((el.loc.clone(), direction, irradiance, spd))
                    }
                    None => self.note(el, "emits nothing (zero irradiance): left out"),
                }
                return Ok(());
            }
            "constant" => {
                let r = p.get("radiance").ok_or_else(|| error_at(&el.loc, "needs `radiance`"))?;
                let spec = spectrum(r, Role::Emission)?;
                p.finish()?;
                match spec.emission() {
                    Some((radiance, spd)) => self.constant.push((el.loc.clone(), radiance, spd)),
                    None => self.note(el, "emits nothing (zero radiance): left out"),
                }
                return Ok(());
            }
            "envmap" => {
                let environment = self.envmap(el, &p, m)?;
                p.finish()?;
                if self.environment.is_some() {
                    return Err(error_at(&el.loc, "a scene may have one envmap emitter"));
                }
                self.environment = Some((el.loc.clone(), environment));
                return Ok(());
            }
            "sunsky" | "projector" => {
                return Err(error_at(
                    &el.loc,
                    format!(
                        "emitter type \"{}\" is not supported (area, point, spot, directional, constant and envmap are; docs/import.md)",
                        el.kind()
                    ),
                ));
            }
            other => {
                return Err(error_at(
                    &el.loc,
                    format!("emitter type \"{other}\" is not supported"),
                ));
            }
        };
        p.finish()?;
        match light {
            Some(l) => self.lights.push(l),
            None => self.note(el, "emits nothing (zero intensity): left out"),
        }
        Ok(())
    }
}

impl Importer {
    /// An `envmap`: its file (resolved like a mesh's), `scale`, and the rotation of `to_world`
    /// (a translation is irrelevant to directions; anything else is refused).
    fn envmap(&mut self, el: &Element, p: &Params<'_>, m: DMat4) -> Result<Value, ImportError> {
        let name = p
            .string("filename")?
            .ok_or_else(|| error_at(&el.loc, "needs <string name=\"filename\">"))?;
        let file = self.file_path(el, name)?;
        let scale = p.float("scale", 1.0)?;
        if !(scale > 0.0 && scale.is_finite()) {
            return Err(error_at(&el.loc, format!("scale {scale}: must be finite and > 0")));
        }
        if p.boolean("mis_compensation", false)? {
            self.note(el, "mis_compensation changes only Mitsuba's noise: not used");
        }
        let r = glam::DMat3::from_mat4(m);
        let rotation = (r.transpose() * r - glam::DMat3::IDENTITY)
            .to_cols_array()
            .iter()
            .all(|v| v.abs() <= 1e-6)
            && r.determinant() > 0.0;
        if !rotation {
            return Err(error_at(
                &el.loc,
                "an envmap's to_world must be a rotation (with any translation): no scale or mirror",
            ));
        }
        let rows = r.transpose().to_cols_array_2d();
        let mut env = json!({"file": file, "scale": scale});
        if r != glam::DMat3::IDENTITY {
            env["rotation"] = json!(rows);
        }
        Ok(env)
    }

    /// The lights placed around the scene once every object is known: the `Sky` of each
    /// directional emitter, and for a constant environment a glowing sphere around everything.
    pub(super) fn place_around(&mut self, camera: glam::DVec3) -> Result<(), ImportError> {
        if let (Some((loc, _)), Some(_)) = (&self.environment, self.constant.first()) {
            return Err(error_at(
                loc,
                "an envmap and a constant emitter in one scene are not supported (add the constant to the map)",
            ));
        }
        let Some(loc) = self
            .directional
            .first()
            .map(|d| d.0.clone())
            .or_else(|| self.constant.first().map(|c| c.0.clone()))
        else {
            return Ok(());
        };
        let mut bounds: Option<spectrace_geometry::Bounds> = None;
        for (i, object) in self.objects.iter().enumerate() {
            let loc = &loc;
            let mut shape: spectrace_geometry::Shape =
                serde_json::from_value(object["shape"].clone()).map_err(|e| {
                    error_at(loc, format!("placing the directional light: object {i}: {e}"))
                })?;
            shape.load(std::path::Path::new("/")).map_err(|e| {
                error_at(loc, format!("placing the directional light: object {i}: {e}"))
            })?;
            let b = shape.bounds();
            bounds = Some(bounds.map_or(b, |a| a.union(b)));
        }
        let Some(bounds) = bounds else {
            return Err(error_at(
                &self.directional[0].0,
                "a directional light needs objects to light",
            ));
        };
        let center = bounds.center();
        let radius = ((bounds.max - bounds.min).length() / 2.0).max(1e-6) * 1.01;
        for (_, d, irradiance, spd) in std::mem::take(&mut self.directional) {
            let (u, v) = d.any_orthonormal_pair();
            let corner = center - d * radius - u * radius - v * radius;
            self.lights.push(json!({
                "type": "Sky", "corner": corner.to_array(), "edge_u": (u * 2.0 * radius).to_array(),
                "edge_v": (v * 2.0 * radius).to_array(), "direction": d.to_array(),
                "power": irradiance * 4.0 * radius * radius, "spd": spd
            }));
        }
        // A constant environment: a sphere of uniform radiance around the objects and the camera
        // sends the same radiance from every direction to every point inside it, exactly.
        let around = bounds.with_point(camera);
        let (centre, sphere_radius) =
            (around.center(), ((around.max - around.min).length() / 2.0).max(1e-6) * 1.5);
        for (_, radiance, spd) in std::mem::take(&mut self.constant) {
            self.objects.push(json!({
                "name": "constant environment",
                "shape": {"type": "Sphere", "center": centre.to_array(), "radius": sphere_radius},
                "material": {"type": "Diffuse", "reflectance": 0.0},
                "emission": {"radiance": radiance, "spd": spd, "two_sided": true}
            }));
        }
        Ok(())
    }
}
