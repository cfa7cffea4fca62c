//! Mitsuba shapes as Spectrace objects: meshes from files, and the analytic shapes placed by
//! their `to_world` (curved ones only under similarities, which keep them spheres, disks and
//! cylinders; a rectangle and a cube take any affine map).

use glam::{DMat4, DVec3};
use serde_json::{Value, json};

use super::Importer;
use super::params::Params;
use super::spectra::{Role, spectrum};
use super::values::{transform, vector};
use super::xml::{Element, ImportError, error_at};

impl Importer {
    /// Adds the objects of a `<shape>` placed by `outer` (an instance's transform).
    pub(super) fn shape(&mut self, el: &Element, outer: DMat4) -> Result<(), ImportError> {
        let p = Params::new(el);
        let m = outer * p.get("to_world").map_or(Ok(DMat4::IDENTITY), transform)?;
        if el.kind() == "shapegroup" {
            // Defined once, placed by instances.
            for _ in p.nested("shape") {}
            return p.finish();
        }
        if el.kind() == "instance" {
            let group = p.nested("ref");
            let [r] = group.as_slice() else {
                return Err(error_at(
                    &el.loc,
                    "an instance needs one <ref id=\"...\"/> to a shapegroup",
                ));
            };
            let ids = self.ids();
            let g = super::resolve(&ids, r, "shape")?;
            for s in g.children.iter().filter(|c| c.tag == "shape") {
                self.shape(s, m)?;
            }
            return p.finish();
        }
        let shape = self.geometry(el, &p, m)?;
        if p.boolean("flip_normals", false)? {
            return Err(error_at(
                &el.loc,
                "flip_normals=true is not supported: reverse the faces in the file",
            ));
        }
        let bsdfs: Vec<&Element> =
            p.nested("bsdf").into_iter().chain(self.refs(&p, "bsdf")).collect();
        let material = match bsdfs.as_slice() {
            [] => {
                self.note(el, "no BSDF: Mitsuba's default, a diffuse reflectance of 0.5");
                json!({"type": "Diffuse", "reflectance": 0.5})
            }
            [b] => self.bsdf(b, false)?,
            _ => return Err(error_at(&el.loc, "a shape with more than one BSDF")),
        };
        let emitters: Vec<&Element> =
            p.nested("emitter").into_iter().chain(self.refs(&p, "emitter")).collect();
        let mut object = json!({"shape": shape, "material": material});
        if let Some(id) = el.attr("id") {
            object["name"] = json!(id);
        }
        match emitters.as_slice() {
            [] => {}
            [e] => {
                if let Some(emission) = self.area_emission(e)? {
                    object["emission"] = emission;
                }
            }
            _ => return Err(error_at(&el.loc, "a shape with more than one emitter")),
        }
        for r in p.nested("ref") {
            if !self.is_ref_to(r, "bsdf") && !self.is_ref_to(r, "emitter") {
                return Err(error_at(&r.loc, "<ref> here must name a bsdf or an emitter"));
            }
        }
        if p.get("face_normals").is_some() {
            self.note(
                el,
                "face_normals: Spectrace shades with the file's vertex normals when present",
            );
        }
        p.finish()?;
        self.objects.push(object);
        Ok(())
    }

    /// The native shape of `el`, placed by `m`.
    fn geometry(&mut self, el: &Element, p: &Params<'_>, m: DMat4) -> Result<Value, ImportError> {
        let matrix = |m: DMat4| json!({"matrix": [m.row(0).to_array(), m.row(1).to_array(), m.row(2).to_array(), m.row(3).to_array()]});
        Ok(match el.kind() {
            "obj" | "ply" | "serialized" => {
                let name = p
                    .string("filename")?
                    .ok_or_else(|| error_at(&el.loc, "needs <string name=\"filename\">"))?;
                let path = self.file_path(el, name)?;
                let face_normals = p.boolean("face_normals", false)?;
                let normals = if face_normals { "none" } else { "computed" };
                let mut s =
                    json!({"type": "Mesh", "transform": matrix(m), "vertex_normals": normals});
                s[el.kind()] = json!(path);
                if el.kind() == "serialized" {
                    let index =
                        p.get("shape_index").map_or(Ok(0), |e| super::values::whole(e, 0))?;
                    s["shape_index"] = json!(index);
                }
                s
            }
            "rectangle" => {
                let corner = m.transform_point3(DVec3::new(-1.0, -1.0, 0.0));
                let u = m.transform_vector3(DVec3::new(2.0, 0.0, 0.0));
                let v = m.transform_vector3(DVec3::new(0.0, 2.0, 0.0));
                // Mitsuba's normal is the transformed +z (as a normal); u x v points the other
                // way under a mirroring map.
                let (u, v) = if m.determinant() < 0.0 { (v, u) } else { (u, v) };
                json!({"type": "Rectangle", "corner": corner.to_array(), "edge_u": u.to_array(), "edge_v": v.to_array()})
            }
            "cube" => {
                let corners: Vec<[f64; 3]> = (0..8)
                    .map(|i| {
                        let c = DVec3::new(
                            if i & 1 == 0 { -1.0 } else { 1.0 },
                            if i & 2 == 0 { -1.0 } else { 1.0 },
                            if i & 4 == 0 { -1.0 } else { 1.0 },
                        );
                        m.transform_point3(c).to_array()
                    })
                    .collect();
                // Counter-clockwise seen from outside (for a map keeping orientation).
                let mut faces = spectrace_geometry::CUBE_TRIANGLES;
                if m.determinant() < 0.0 {
                    for f in &mut faces {
                        f.swap(1, 2);
                    }
                }
                json!({"type": "Mesh", "positions": corners, "triangles": faces})
            }
            "sphere" => {
                let center = p.get("center").map_or(Ok(DVec3::ZERO), vector)?;
                let radius = p.float("radius", 1.0)?;
                similarity(el, m)?;
                // Mitsuba's sphere has its pole on local +z, Spectrace's on +y; a quarter turn
                // about x gives the same uv (azimuth from +x, polar angle from the pole).
                let placed = m
                    * DMat4::from_translation(center)
                    * DMat4::from_rotation_x(std::f64::consts::FRAC_PI_2);
                json!({"type": "Sphere", "center": [0.0, 0.0, 0.0], "radius": radius, "transform": matrix(placed)})
            }
            "disk" => {
                let s = similarity(el, m)?;
                let n = m.transform_vector3(DVec3::Z).normalize();
                json!({"type": "Disk", "center": m.transform_point3(DVec3::ZERO).to_array(), "normal": n.to_array(), "radius": s})
            }
            "cylinder" => {
                let p0 = p.get("p0").map_or(Ok(DVec3::ZERO), vector)?;
                let p1 = p.get("p1").map_or(Ok(DVec3::Z), vector)?;
                let radius = p.float("radius", 1.0)?;
                let s = similarity(el, m)?;
                let (a, b) = (m.transform_point3(p0), m.transform_point3(p1));
                json!({"type": "Cylinder", "center": a.to_array(), "axis": (b - a).normalize_or_zero().to_array(),
                       "height": (b - a).length(), "radius": radius * s})
            }
            other => {
                return Err(error_at(
                    &el.loc,
                    format!(
                        "shape type \"{other}\" is not supported (obj, ply, rectangle, cube, sphere, disk, cylinder, shapegroup, instance are)"
                    ),
                ));
            }
        })
    }

    /// The emission of an `area` emitter on a shape: its radiance, integrated, and its spectrum.
    fn area_emission(&mut self, e: &Element) -> Result<Option<Value>, ImportError> {
        let ids = self.ids();
        let e = super::resolve(&ids, e, "emitter")?;
        if e.kind() != "area" {
            return Err(error_at(
                &e.loc,
                format!("a shape's emitter must be \"area\", not \"{}\"", e.kind()),
            ));
        }
        let p = Params::new(e);
        let radiance = p
            .get("radiance")
            .ok_or_else(|| error_at(&e.loc, "an area emitter needs `radiance`"))?;
        let spec = spectrum(radiance, Role::Emission)?;
        p.finish()?;
        Ok(match spec.emission() {
            Some((integral, spd)) => {
                Some(json!({"radiance": integral, "spd": spd, "two_sided": false}))
            }
            None => {
                self.note(e, "emits nothing (zero radiance): left out");
                None
            }
        })
    }
}

/// The uniform scale of a similarity `m`; an error for any other map (a sphere would become an
/// ellipsoid).
fn similarity(el: &Element, m: DMat4) -> Result<f64, ImportError> {
    let cols = [m.x_axis.truncate(), m.y_axis.truncate(), m.z_axis.truncate()];
    let s = cols[0].length();
    let ok = cols.iter().all(|c| (c.length() - s).abs() <= 1e-6 * s)
        && cols[0].dot(cols[1]).abs() <= 1e-6 * s * s
        && cols[0].dot(cols[2]).abs() <= 1e-6 * s * s
        && cols[1].dot(cols[2]).abs() <= 1e-6 * s * s
        && s > 0.0;
    if ok {
        Ok(s)
    } else {
        Err(error_at(
            &el.loc,
            format!(
                "a {} under a non-uniform scale or shear is not supported (it would no longer be one)",
                el.kind()
            ),
        ))
    }
}
