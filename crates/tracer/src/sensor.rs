//! Illuminance sensors: rectangles divided into cells that record the light arriving on their
//! front side, what lighting designers measure on a work plane.
//!
//! | field | unit | default | meaning |
//! |---|---|---|---|
//! | `type` | | required | `"IrradianceSensor"` |
//! | `name` | | required | names the output files (`NAME.csv`, `NAME.exr`, `NAME.png`): a plain file name |
//! | `corner` | m | required | a corner of the rectangle |
//! | `edge_u`, `edge_v` | m | required | its edges from `corner`; the front side is the side `edge_u x edge_v` points to |
//! | `cells` | | required | `[nu, nv]`: cells along `edge_u` and `edge_v`, each 1 to 4096, at most 2^20 in all |
//!
//! ```json
//! "sensors": [{"type": "IrradianceSensor", "name": "workplane", "corner": [-2, 0.75, -3],
//!              "edge_u": [0, 0, 6], "edge_v": [4, 0, 0], "cells": [30, 20]}]
//! ```
//! Here `edge_u x edge_v` = +z x +x = +y: the front faces up, as a work plane lit from above
//! needs (listing the edges the other way round would make it face down and record nothing).
//!
//! # Estimator
//! A sensor blocks nothing. Every segment of a light path (from the light, or from a bounce, to
//! the next surface or to infinity) that crosses the sensor's rectangle travelling against its
//! front normal adds the path's power to the cell it crosses: radiant power for irradiance, and
//! power times `683 ybar(lambda)` for illuminance. A cell's irradiance is the power that crossed
//! it over its area; its expectation is exactly the irradiance averaged over the cell (the flux
//! through a surface is what irradiance integrates to). Light arriving from behind is not
//! counted, as a cosine-corrected meter lying on the plane would not.

use glam::DVec3;
use serde::{Deserialize, Serialize};

/// Most cells along one edge of a sensor.
pub const MAX_SENSOR_CELLS_PER_EDGE: u32 = 4096;
/// Most cells of one sensor.
pub const MAX_SENSOR_CELLS: u64 = 1 << 20;

/// An illuminance sensor: a rectangle of `nu x nv` cells recording light arriving on its front.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "SensorRepr", into = "SensorRepr")]
pub struct IrradianceSensor {
    name: String,
    corner: DVec3,
    edge_u: DVec3,
    edge_v: DVec3,
    cells: [u32; 2],
    /// `edge_u x edge_v` (not normalised): the front normal times the area.
    normal: DVec3,
    /// Dual vectors: `(p - corner) . du` and `. dv` are `p`'s coordinates along the edges.
    du: DVec3,
    dv: DVec3,
}

/// Scene-file form of a sensor (tagged by `type`).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(tag = "type", deny_unknown_fields)]
enum SensorRepr {
    /// The only sensor type so far.
    IrradianceSensor { name: String, corner: DVec3, edge_u: DVec3, edge_v: DVec3, cells: [u32; 2] },
}

impl TryFrom<SensorRepr> for IrradianceSensor {
    type Error = String;
    fn try_from(r: SensorRepr) -> Result<Self, String> {
        let SensorRepr::IrradianceSensor { name, corner, edge_u, edge_v, cells } = r;
        Self::new(name, corner, edge_u, edge_v, cells)
    }
}

impl From<IrradianceSensor> for SensorRepr {
    fn from(s: IrradianceSensor) -> Self {
        SensorRepr::IrradianceSensor {
            name: s.name,
            corner: s.corner,
            edge_u: s.edge_u,
            edge_v: s.edge_v,
            cells: s.cells,
        }
    }
}

impl IrradianceSensor {
    /// A sensor on the parallelogram `corner + s edge_u + t edge_v` with `cells = [nu, nv]`.
    ///
    /// # Errors
    /// Why, naming the field: a point or edge not finite, an edge of length 0, parallel edges,
    /// a cell count of 0 or above the limits, an empty name.
    pub fn new(
        name: String,
        corner: DVec3,
        edge_u: DVec3,
        edge_v: DVec3,
        cells: [u32; 2],
    ) -> Result<Self, String> {
        if name.is_empty() {
            return Err("name: must not be empty (it names the sensor's output files)".into());
        }
        for (field, v) in [("corner", corner), ("edge_u", edge_u), ("edge_v", edge_v)] {
            if !v.is_finite() {
                return Err(format!("{field}: {:?} must be finite", v.to_array()));
            }
        }
        let normal = edge_u.cross(edge_v);
        let area = normal.length();
        let spanned = area > 1e-12 * edge_u.length() * edge_v.length();
        if !(area > 0.0 && area.is_finite() && spanned) {
            return Err(format!(
                "edge_u {:?} and edge_v {:?}: must be non-zero and not parallel (they span the \
                 sensor's rectangle)",
                edge_u.to_array(),
                edge_v.to_array()
            ));
        }
        for (axis, &n) in ["nu", "nv"].iter().zip(&cells) {
            if n == 0 || n > MAX_SENSOR_CELLS_PER_EDGE {
                return Err(format!(
                    "cells: {axis} = {n} must be from 1 to {MAX_SENSOR_CELLS_PER_EDGE}"
                ));
            }
        }
        if u64::from(cells[0]) * u64::from(cells[1]) > MAX_SENSOR_CELLS {
            return Err(format!(
                "cells: {} x {} cells, more than the {MAX_SENSOR_CELLS} a sensor may have",
                cells[0], cells[1]
            ));
        }
        let vn = edge_v.cross(normal);
        let nu = normal.cross(edge_u);
        let du = vn / edge_u.dot(vn);
        let dv = nu / edge_v.dot(nu);
        Ok(Self { name, corner, edge_u, edge_v, cells, normal, du, dv })
    }

    /// The sensor's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The corner the cells count from.
    pub fn corner(&self) -> DVec3 {
        self.corner
    }

    /// The edge along which `iu` counts.
    pub fn edge_u(&self) -> DVec3 {
        self.edge_u
    }

    /// The edge along which `iv` counts.
    pub fn edge_v(&self) -> DVec3 {
        self.edge_v
    }

    /// `[nu, nv]`.
    pub fn cells(&self) -> [u32; 2] {
        self.cells
    }

    /// How many cells: `nu * nv`.
    pub fn cell_count(&self) -> u32 {
        self.cells[0] * self.cells[1]
    }

    /// The area of one cell (m^2).
    pub fn cell_area(&self) -> f64 {
        self.normal.length() / f64::from(self.cell_count())
    }

    /// The unit normal of the front side.
    pub fn front(&self) -> DVec3 {
        self.normal.normalize()
    }

    /// The cell (`iv * nu + iu`) that a segment from `origin` along the unit `direction`, of
    /// length `t_max` (infinite for a ray that escapes), crosses while arriving on the front
    /// side; `None` if it does not.
    #[inline]
    pub fn crossing(&self, origin: DVec3, direction: DVec3, t_max: f64) -> Option<u32> {
        let denominator = direction.dot(self.normal);
        if !(denominator < 0.0) {
            return None;
        }
        let t = (self.corner - origin).dot(self.normal) / denominator;
        if !(t > 0.0 && t < t_max) {
            return None;
        }
        let d = origin + direction * t - self.corner;
        let (s, r) = (d.dot(self.du), d.dot(self.dv));
        if !((0.0..1.0).contains(&s) && (0.0..1.0).contains(&r)) {
            return None;
        }
        let iu = ((s * f64::from(self.cells[0])) as u32).min(self.cells[0] - 1);
        let iv = ((r * f64::from(self.cells[1])) as u32).min(self.cells[1] - 1);
        Some(iv * self.cells[0] + iu)
    }

    /// The centre of cell `(iu, iv)`.
    pub fn cell_centre(&self, iu: u32, iv: u32) -> DVec3 {
        self.corner
            + self.edge_u * ((f64::from(iu) + 0.5) / f64::from(self.cells[0]))
            + self.edge_v * ((f64::from(iv) + 0.5) / f64::from(self.cells[1]))
    }
}

/// What the film keeps per sensor cell, summed over the crossings (relative beam weights, before
/// the lights' power over the beam count): `[radiant, luminous, luminous^2, melanopic]`, where
/// `luminous` is the weight times `683 ybar(lambda)` (lm/W), its square serves the error
/// estimate, and `melanopic` is the weight times the melanopic EDI per watt
/// ([`spectrace_spectrum::melanopic_edi_per_watt`], CIE S 026), so that it becomes melanopic
/// equivalent daylight illuminance (lux) as `luminous` becomes illuminance.
pub type SensorSums = [f64; 4];

/// The sensors of a scene, their cells numbered consecutively (sensor 0's cells first).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SensorSet {
    sensors: Vec<IrradianceSensor>,
    offsets: Vec<u32>,
    total: u32,
}

impl SensorSet {
    /// The set of `sensors`.
    ///
    /// # Errors
    /// When their cells together exceed [`MAX_SENSOR_CELLS`] x 4, or two share a name.
    pub fn new(sensors: Vec<IrradianceSensor>) -> Result<Self, String> {
        let mut offsets = Vec::with_capacity(sensors.len());
        let mut total = 0u64;
        for (i, s) in sensors.iter().enumerate() {
            if sensors[..i].iter().any(|o| o.name == s.name) {
                return Err(format!("sensors[{i}].name: \"{}\" is used twice", s.name));
            }
            offsets.push(total as u32);
            total += u64::from(s.cell_count());
        }
        if total > 4 * MAX_SENSOR_CELLS {
            return Err(format!(
                "sensors: {total} cells in all, more than {}",
                4 * MAX_SENSOR_CELLS
            ));
        }
        Ok(Self { sensors, offsets, total: total as u32 })
    }

    /// The sensors.
    pub fn sensors(&self) -> &[IrradianceSensor] {
        &self.sensors
    }

    /// Cells of all sensors.
    pub fn total_cells(&self) -> u32 {
        self.total
    }

    /// Where sensor `i`'s cells start in the numbering of all cells.
    pub fn offset(&self, i: usize) -> u32 {
        self.offsets.get(i).copied().unwrap_or(self.total)
    }

    /// Whether there are no sensors.
    pub fn is_empty(&self) -> bool {
        self.sensors.is_empty()
    }

    /// Calls `f(cell)` for every sensor cell (numbered over all sensors) that the segment
    /// crosses on its front side.
    #[inline]
    pub fn crossings(&self, origin: DVec3, direction: DVec3, t_max: f64, mut f: impl FnMut(u32)) {
        for (s, &offset) in self.sensors.iter().zip(&self.offsets) {
            if let Some(cell) = s.crossing(origin, direction, t_max) {
                f(offset + cell);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    fn floor() -> IrradianceSensor {
        // Front faces +y: edge_u +z, edge_v +x.
        IrradianceSensor::new(
            "floor".into(),
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(0.0, 0.0, 2.0),
            DVec3::new(4.0, 0.0, 0.0),
            [2, 4],
        )
        .unwrap()
    }

    #[test]
    fn segments_arriving_on_the_front_find_their_cell() {
        let s = floor();
        assert_eq!(s.front(), DVec3::Y);
        assert!((s.cell_area() - 1.0).abs() < 1e-15);
        // From above, down onto (x 2.5, z 1.5): iu = 1 (z), iv = 2 (x).
        let o = DVec3::new(2.5, 3.0, 1.5);
        assert_eq!(s.crossing(o, DVec3::NEG_Y, f64::INFINITY), Some(2 * 2 + 1));
        // Stopped by a surface before the plane, from behind, or beside the rectangle: none.
        assert_eq!(s.crossing(o, DVec3::NEG_Y, 2.9), None);
        assert_eq!(s.crossing(DVec3::new(2.5, -1.0, 1.5), DVec3::Y, f64::INFINITY), None);
        assert_eq!(s.crossing(DVec3::new(4.5, 3.0, 1.5), DVec3::NEG_Y, f64::INFINITY), None);
        assert_eq!(s.cell_centre(1, 2), DVec3::new(2.5, 0.0, 1.5));
    }

    #[test]
    fn bad_sensors_are_refused_naming_the_field() {
        let make = |u: DVec3, v: DVec3, cells: [u32; 2]| {
            IrradianceSensor::new("s".into(), DVec3::ZERO, u, v, cells).unwrap_err()
        };
        assert!(make(DVec3::X, DVec3::X * 2.0, [1, 1]).contains("not parallel"));
        assert!(make(DVec3::ZERO, DVec3::Y, [1, 1]).contains("non-zero"));
        assert!(make(DVec3::X, DVec3::Z, [0, 1]).contains("cells: nu = 0"));
        assert!(make(DVec3::X, DVec3::Z, [4096, 4096]).contains("more than"));
        assert!(make(DVec3::new(f64::NAN, 0.0, 0.0), DVec3::Z, [1, 1]).contains("edge_u"));
        let json = r#"{"type": "IrradianceSensor", "name": "a", "corner": [0, 0, 0],
                      "edge_u": [1, 0, 0], "edge_v": [0, 0, 1], "cells": [2, 2], "size": 3}"#;
        let e = serde_json::from_str::<IrradianceSensor>(json).unwrap_err().to_string();
        assert!(e.contains("size"), "{e}");
        let e = SensorSet::new(vec![floor(), floor()]).unwrap_err();
        assert!(e.contains("used twice"), "{e}");
    }
}
