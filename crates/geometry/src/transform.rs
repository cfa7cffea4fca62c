//! [`Transform`]: affine 4x4 transforms with their inverses, written row-major in scene files.
//!
//! | form | field | unit | default | meaning |
//! |---|---|---|---|---|
//! | matrix | `matrix` | m (translation column) | required | four rows of four numbers, **row-major** as in the seed: `matrix[r][c]`; the last row must be `[0, 0, 0, 1]` |
//! | parts | `scale` | 1 | `1` | `[sx, sy, sz]` or one number; every factor non-zero |
//! | parts | `rotate` | | none | `{"axis": [x, y, z], "degrees": d}`, right-handed (counter-clockwise looking down the axis) |
//! | parts | `translate` | m | `[0, 0, 0]` | offset |
//!
//! The parts form applies **scale first, then rotate, then translate**: `M = T R S`, so a point
//! becomes `p' = T(R(S p))`. `matrix` cannot be combined with the parts.
//!
//! ```json
//! {"matrix": [[1, 0, 0, 2], [0, 1, 0, 0], [0, 0, 1, -1], [0, 0, 0, 1]]}
//! {"translate": [0, 1, 0], "rotate": {"axis": [0, 1, 0], "degrees": 90}, "scale": 2}
//! ```
//!
//! Inside, glam's `DMat4` is column-major: [`Transform::from_rows`] transposes.

use glam::{DMat3, DMat4, DVec3, DVec4};
use serde::{Deserialize, Serialize};

use crate::GeometryError;

/// An invertible affine transform with its inverse.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "TransformRepr", into = "TransformRepr")]
pub struct Transform {
    matrix: DMat4,
    inverse: DMat4,
}

impl Default for Transform {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Transform {
    /// The identity.
    pub const IDENTITY: Self = Self { matrix: DMat4::IDENTITY, inverse: DMat4::IDENTITY };

    /// From a glam matrix (column-major), validated: finite, affine, invertible.
    ///
    /// # Errors
    /// [`GeometryError::Parameter`] naming `Transform.matrix`.
    pub fn from_matrix(matrix: DMat4) -> Result<Self, GeometryError> {
        const F: &str = "matrix";
        if !matrix.is_finite() {
            return Err(GeometryError::parameter("Transform", F, matrix, "must be finite"));
        }
        if matrix.row(3) != DVec4::new(0.0, 0.0, 0.0, 1.0) {
            return Err(GeometryError::parameter(
                "Transform",
                F,
                matrix.row(3),
                "last row must be [0, 0, 0, 1] (affine)",
            ));
        }
        let linear = DMat3::from_mat4(matrix).transpose(); // columns are now the rows
        let rows = [linear.x_axis, linear.y_axis, linear.z_axis];
        // Row equilibration: dividing each row by its largest entry keeps every entry in
        // [-1, 1], so the determinant and the inverse of the scaled part cannot overflow, and
        // singularity is judged relative to the matrix's own scale.
        let mut row_scale = [0.0; 3];
        for (i, row) in rows.iter().enumerate() {
            row_scale[i] = row.abs().max_element();
            if row_scale[i] == 0.0 {
                return Err(GeometryError::parameter(
                    "Transform",
                    F,
                    matrix.row(i),
                    "singular: a row of the linear part is zero",
                ));
            }
        }
        let scaled = DMat3::from_cols(
            rows[0] / row_scale[0],
            rows[1] / row_scale[1],
            rows[2] / row_scale[2],
        )
        .transpose(); // back to glam's layout: scaled = D^-1 A
        let det = scaled.determinant();
        let norms = rows.iter().zip(row_scale).map(|(r, s)| (*r / s).length()).product::<f64>();
        if !(det.abs() > 1e-12 * norms) {
            return Err(GeometryError::parameter(
                "Transform",
                F,
                det / norms,
                "singular: the rows are (nearly) linearly dependent (|det| / product of row \
                 lengths ~ 0)",
            ));
        }
        // A^-1 = (D^-1 A)^-1 D^-1: column j of the scaled inverse divided by row_scale[j].
        let si = scaled.inverse();
        let inv_linear = DMat3::from_cols(
            si.x_axis / row_scale[0],
            si.y_axis / row_scale[1],
            si.z_axis / row_scale[2],
        );
        let translation = matrix.w_axis.truncate();
        let inv_translation = -(inv_linear * translation);
        let inverse = DMat4::from_cols(
            inv_linear.x_axis.extend(0.0),
            inv_linear.y_axis.extend(0.0),
            inv_linear.z_axis.extend(0.0),
            inv_translation.extend(1.0),
        );
        if !inverse.is_finite() {
            return Err(GeometryError::parameter(
                "Transform",
                F,
                matrix,
                "entries too large or too small: the inverse overflows f64",
            ));
        }
        Ok(Self { matrix, inverse })
    }

    /// From four rows of four numbers, row-major as scene files write them (`rows[r][c]`).
    ///
    /// # Errors
    /// [`GeometryError::Parameter`] naming `Transform.matrix` when not finite, not affine or
    /// singular.
    pub fn from_rows(rows: [[f64; 4]; 4]) -> Result<Self, GeometryError> {
        Self::from_matrix(DMat4::from_cols_array_2d(&rows).transpose())
    }

    /// A translation by `offset`.
    ///
    /// # Errors
    /// [`GeometryError::Parameter`] naming `translate` when not finite.
    pub fn translate(offset: DVec3) -> Result<Self, GeometryError> {
        if !offset.is_finite() {
            return Err(GeometryError::parameter(
                "Transform",
                "translate",
                offset,
                "must be finite",
            ));
        }
        Ok(Self {
            matrix: DMat4::from_translation(offset),
            inverse: DMat4::from_translation(-offset),
        })
    }

    /// A right-handed rotation by `degrees` about `axis` (normalised here).
    ///
    /// # Errors
    /// [`GeometryError::Parameter`] naming `rotate.axis` (zero or not finite) or `rotate.degrees`.
    pub fn rotate(axis: DVec3, degrees: f64) -> Result<Self, GeometryError> {
        let axis = crate::float::unit_direction("Transform", "rotate.axis", axis)?;
        if !degrees.is_finite() {
            return Err(GeometryError::parameter(
                "Transform",
                "rotate.degrees",
                degrees,
                "must be finite",
            ));
        }
        let m = DMat4::from_axis_angle(axis, degrees.to_radians());
        Ok(Self { matrix: m, inverse: m.transpose() })
    }

    /// A scale by `factors` along x, y, z.
    ///
    /// # Errors
    /// [`GeometryError::Parameter`] naming `scale` when a factor is zero or not finite.
    pub fn scale(factors: DVec3) -> Result<Self, GeometryError> {
        if !factors.is_finite() || factors.cmpeq(DVec3::ZERO).any() {
            return Err(GeometryError::parameter(
                "Transform",
                "scale",
                factors,
                "must be finite and non-zero",
            ));
        }
        let recip = factors.recip();
        if !recip.is_finite() {
            return Err(GeometryError::parameter(
                "Transform",
                "scale",
                factors,
                "too small: its reciprocal (the inverse scale) overflows",
            ));
        }
        Ok(Self { matrix: DMat4::from_scale(factors), inverse: DMat4::from_scale(recip) })
    }

    /// `self` applied after `first`: `self.after(first).point(p) == self.point(first.point(p))`.
    pub fn after(&self, first: &Transform) -> Self {
        Self { matrix: self.matrix * first.matrix, inverse: first.inverse * self.inverse }
    }

    /// `next` applied after `self`.
    pub fn then(&self, next: &Transform) -> Self {
        next.after(self)
    }

    /// The inverse transform.
    pub fn inverse(&self) -> Self {
        Self { matrix: self.inverse, inverse: self.matrix }
    }

    /// The matrix (glam, column-major).
    pub fn matrix(&self) -> DMat4 {
        self.matrix
    }

    /// The matrix as rows (row-major, as scene files write it).
    pub fn to_rows(&self) -> [[f64; 4]; 4] {
        self.matrix.transpose().to_cols_array_2d()
    }

    /// A point transformed (translation applies).
    pub fn point(&self, p: DVec3) -> DVec3 {
        self.matrix.transform_point3(p)
    }

    /// A vector transformed (no translation).
    pub fn vector(&self, v: DVec3) -> DVec3 {
        self.matrix.transform_vector3(v)
    }

    /// A normal transformed by the inverse transpose (not normalised), so it stays perpendicular to
    /// transformed tangents.
    pub fn normal(&self, n: DVec3) -> DVec3 {
        DMat3::from_mat4(self.inverse).transpose() * n
    }

    /// Whether the linear part is a rotation (or reflection) times a uniform scale, within a
    /// relative `1e-9`; returns that scale. Analytic curved shapes accept only these.
    pub fn similarity_scale(&self) -> Option<f64> {
        // Scaled by the largest entry first so huge or tiny (finite) scales do not overflow or
        // underflow in `l^T l`.
        let l = DMat3::from_mat4(self.matrix);
        let m = l.to_cols_array().iter().fold(0.0_f64, |a, x| a.max(x.abs()));
        if !(m > 0.0) {
            return None;
        }
        let l = l * (1.0 / m);
        let g = l.transpose() * l;
        let s2 = (g.x_axis.x + g.y_axis.y + g.z_axis.z) / 3.0;
        let tol = 1e-9 * s2;
        let off = (g - DMat3::from_diagonal(DVec3::splat(s2))).to_cols_array();
        let scale = s2.sqrt() * m;
        (off.iter().all(|x| x.abs() <= tol) && scale.is_finite() && scale > 0.0).then_some(scale)
    }

    /// Whether the transform flips orientation (negative determinant). Judged on the rows
    /// scaled by their largest entries, so the sign is right even when the determinant itself
    /// would overflow or underflow.
    pub fn flips_orientation(&self) -> bool {
        let rows = DMat3::from_mat4(self.matrix).transpose();
        let scale = |r: DVec3| {
            let m = r.abs().max_element();
            if m > 0.0 { r / m } else { r }
        };
        DMat3::from_cols(scale(rows.x_axis), scale(rows.y_axis), scale(rows.z_axis)).determinant()
            < 0.0
    }
}

/// `rotate` of the parts form.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct RotateRepr {
    axis: DVec3,
    degrees: f64,
}

/// `scale` of the parts form: one number or three.
#[derive(Serialize, Deserialize)]
#[serde(untagged)]
enum ScaleRepr {
    Uniform(f64),
    Axes(DVec3),
}

/// Scene-file form of [`Transform`].
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct TransformRepr {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    matrix: Option<[[f64; 4]; 4]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    translate: Option<DVec3>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    rotate: Option<RotateRepr>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    scale: Option<ScaleRepr>,
}

impl TryFrom<TransformRepr> for Transform {
    type Error = GeometryError;
    fn try_from(r: TransformRepr) -> Result<Self, GeometryError> {
        if let Some(rows) = r.matrix {
            if r.translate.is_some() || r.rotate.is_some() || r.scale.is_some() {
                return Err(GeometryError::parameter(
                    "Transform",
                    "matrix",
                    "with translate/rotate/scale",
                    "give either matrix or the parts, not both",
                ));
            }
            return Self::from_rows(rows);
        }
        let s = match r.scale {
            None => Self::IDENTITY,
            Some(ScaleRepr::Uniform(s)) => Self::scale(DVec3::splat(s))?,
            Some(ScaleRepr::Axes(v)) => Self::scale(v)?,
        };
        let rot = match r.rotate {
            None => Self::IDENTITY,
            Some(RotateRepr { axis, degrees }) => Self::rotate(axis, degrees)?,
        };
        let t = Self::translate(r.translate.unwrap_or(DVec3::ZERO))?;
        Ok(s.then(&rot).then(&t))
    }
}

impl From<Transform> for TransformRepr {
    fn from(t: Transform) -> Self {
        Self { matrix: Some(t.to_rows()), translate: None, rotate: None, scale: None }
    }
}
