//! [`Prism`]: a triangular glass prism, built as an 8-triangle [`Mesh`].
//!
//! | field | unit | default | meaning |
//! |---|---|---|---|
//! | `center` | m, `[x, y, z]` | `[0, 0, 0]` | centre of the prism's bounding box (before `transform`) |
//! | `apex_angle_degrees` | degrees | `60` | angle between the two equal sides, in `(0, 180)` |
//! | `side` | m | required | length of the two equal sides that meet at the apex, > 0 |
//! | `length` | m | required | extrusion length along `z`, > 0 |
//! | `transform` | [`Transform`] | none | any affine transform, applied after placing at `center` |
//!
//! ```json
//! {"type": "Prism", "center": [0, 0.5, 0], "apex_angle_degrees": 60, "side": 0.3, "length": 0.5,
//!  "transform": {"rotate": {"axis": [0, 1, 0], "degrees": 30}}}
//! ```
//!
//! Untransformed, the cross-section is an isosceles triangle in the `xy` plane with its apex at the
//! top (`+y`) and its base (of width `2 side sin(apex / 2)`) at the bottom, parallel to `x`; the
//! prism runs from `z = -length/2` to `+length/2` around `center`. All faces wind outwards.

use glam::DVec3;
use serde::{Deserialize, Serialize};

use crate::float::{finite_point, positive};
use crate::{GeometryError, Mesh, Transform};

/// A triangular prism (a closed mesh).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "PrismRepr", into = "PrismRepr")]
pub struct Prism {
    mesh: Mesh,
    repr: Box<PrismRepr>,
}

/// The default apex angle (degrees).
fn sixty() -> f64 {
    60.0
}

/// Scene-file form of [`Prism`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct PrismRepr {
    #[serde(default)]
    center: DVec3,
    #[serde(default = "sixty")]
    apex_angle_degrees: f64,
    side: f64,
    length: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    transform: Option<Transform>,
}

impl TryFrom<PrismRepr> for Prism {
    type Error = GeometryError;
    fn try_from(r: PrismRepr) -> Result<Self, GeometryError> {
        const S: &str = "Prism";
        let c = finite_point(S, "center", r.center)?;
        let side = positive(S, "side", r.side)?;
        let length = positive(S, "length", r.length)?;
        let apex = r.apex_angle_degrees;
        if !(apex > 0.0 && apex < 180.0) {
            return Err(GeometryError::parameter(
                S,
                "apex_angle_degrees",
                apex,
                "must be in (0, 180)",
            ));
        }
        let half = (apex * 0.5).to_radians();
        let (hw, h, hz) = (side * half.sin(), side * half.cos(), length * 0.5);
        let section = [
            DVec3::new(-hw, -h * 0.5, 0.0),
            DVec3::new(hw, -h * 0.5, 0.0),
            DVec3::new(0.0, h * 0.5, 0.0),
        ];
        // 0..3 at z = -hz (back), 3..6 at z = +hz (front); section order B, C, A is counter-clockwise from +z.
        let positions: Vec<DVec3> = [-hz, hz]
            .iter()
            .flat_map(|&z| section.map(|p| c + p + DVec3::new(0.0, 0.0, z)))
            .collect();
        let mut triangles = vec![[3, 4, 5], [0, 2, 1]];
        for (p, q) in [(0u32, 1u32), (1, 2), (2, 0)] {
            triangles.push([p, q, q + 3]);
            triangles.push([p, q + 3, p + 3]);
        }
        if positions.iter().any(|p| !p.is_finite()) {
            let (field, value) = if c.abs().max_element() >= side.max(length) {
                ("center", format!("{c:?}"))
            } else if side >= length {
                ("side", format!("{side:?}"))
            } else {
                ("length", format!("{length:?}"))
            };
            return Err(GeometryError::Parameter {
                shape: S,
                field,
                value,
                reason: "too large: the prism's vertices overflow f64",
            });
        }
        // Errors of the inner mesh are about the prism's own fields.
        let as_prism = |e: GeometryError| match e {
            GeometryError::Parameter { field, value, reason, .. } => {
                let field = if field == "transform" { field } else { "center" };
                GeometryError::Parameter { shape: S, field, value, reason }
            }
            other => other,
        };
        let mesh = Mesh::from_triangles(positions, triangles).map_err(as_prism)?;
        let mesh = match &r.transform {
            Some(t) => mesh.transformed(t).map_err(as_prism)?,
            None => mesh,
        };
        Ok(Self { mesh, repr: Box::new(r) })
    }
}

impl From<Prism> for PrismRepr {
    fn from(p: Prism) -> Self {
        *p.repr
    }
}

impl Prism {
    /// A prism around `center` with the given apex angle (degrees), equal sides and length.
    ///
    /// # Errors
    /// [`GeometryError::Parameter`] naming `center`, `apex_angle_degrees`, `side` or `length`.
    pub fn new(
        center: DVec3,
        apex_angle_degrees: f64,
        side: f64,
        length: f64,
    ) -> Result<Self, GeometryError> {
        PrismRepr { center, apex_angle_degrees, side, length, transform: None }.try_into()
    }

    /// The prism as a mesh (8 triangles).
    pub fn mesh(&self) -> &Mesh {
        &self.mesh
    }
}
