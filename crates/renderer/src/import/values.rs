//! Mitsuba property values: numbers, points and vectors, and `<transform>`s as 4x4 matrices.

use glam::{DMat4, DVec3};

use super::xml::{Element, ImportError, error_at};

/// The numbers of a comma- or space-separated list.
pub(crate) fn numbers(el: &Element, text: &str) -> Result<Vec<f64>, ImportError> {
    text.split(|c: char| c == ',' || c.is_whitespace())
        .filter(|s| !s.is_empty())
        .map(|s| {
            s.parse::<f64>().ok().filter(|v| v.is_finite()).ok_or_else(|| {
                error_at(&el.loc, format!("{}: `{s}` is not a finite number", el.describe()))
            })
        })
        .collect()
}

/// The single number of a `<float>` or `<integer>` (`value`).
pub(crate) fn number(el: &Element) -> Result<f64, ImportError> {
    match numbers(el, el.required("value")?)?.as_slice() {
        [v] => Ok(*v),
        _ => Err(error_at(&el.loc, format!("{}: one number expected", el.describe()))),
    }
}

/// The whole number of a `<float>` or `<integer>`, at least `min`: an error naming the
/// parameter for a fraction or a smaller value (never rounded or clamped).
pub(crate) fn whole(el: &Element, min: i64) -> Result<i64, ImportError> {
    let v = number(el)?;
    if v.fract() != 0.0 || v < min as f64 || v > 2f64.powi(53) {
        return Err(error_at(
            &el.loc,
            format!("{}: {v} must be a whole number of at least {min}", el.describe()),
        ));
    }
    Ok(v as i64)
}

/// A `<point>` or `<vector>`: `value="x, y, z"` or attributes `x`, `y`, `z` (missing ones 0).
pub(crate) fn vector(el: &Element) -> Result<DVec3, ImportError> {
    if let Some(v) = el.attr("value") {
        return match numbers(el, v)?.as_slice() {
            [x, y, z] => Ok(DVec3::new(*x, *y, *z)),
            [s] => Ok(DVec3::splat(*s)),
            _ => Err(error_at(&el.loc, format!("{}: three numbers expected", el.describe()))),
        };
    }
    let c = |k: &str| {
        el.attr(k).map_or(Ok(0.0), |v| match numbers(el, v)?.as_slice() {
            [x] => Ok(*x),
            _ => Err(error_at(&el.loc, format!("{}: `{k}` must be one number", el.describe()))),
        })
    };
    Ok(DVec3::new(c("x")?, c("y")?, c("z")?))
}

/// A `<transform>`: its operations composed in order (each later one applied after the
/// earlier ones, as Mitsuba does).
pub(crate) fn transform(el: &Element) -> Result<DMat4, ImportError> {
    let mut m = DMat4::IDENTITY;
    for op in &el.children {
        let step = match op.tag.as_str() {
            "translate" => DMat4::from_translation(vector(op)?),
            "scale" => {
                let s = match op.attr("value") {
                    Some(v) => match numbers(op, v)?.as_slice() {
                        [s] => DVec3::splat(*s),
                        [x, y, z] => DVec3::new(*x, *y, *z),
                        _ => {
                            return Err(error_at(
                                &op.loc,
                                "<scale>: one or three numbers expected",
                            ));
                        }
                    },
                    None => {
                        let c = |k: &str| {
                            op.attr(k).map_or(Ok(1.0), |v| {
                                numbers(op, v).and_then(|n| {
                                    n.first()
                                        .copied()
                                        .ok_or_else(|| error_at(&op.loc, "<scale>: empty value"))
                                })
                            })
                        };
                        DVec3::new(c("x")?, c("y")?, c("z")?)
                    }
                };
                DMat4::from_scale(s)
            }
            "rotate" => {
                let axis = vector(op)?;
                let angle = numbers(op, op.required("angle")?)?;
                let [angle] = angle.as_slice() else {
                    return Err(error_at(
                        &op.loc,
                        "<rotate>: `angle` must be one number (degrees)",
                    ));
                };
                if !(axis.length() > 0.0) {
                    return Err(error_at(&op.loc, "<rotate>: the axis is zero"));
                }
                DMat4::from_axis_angle(axis.normalize(), angle.to_radians())
            }
            "matrix" => {
                let v = numbers(op, op.required("value")?)?;
                match v.len() {
                    16 => DMat4::from_cols_array(&[
                        v[0], v[4], v[8], v[12], v[1], v[5], v[9], v[13], v[2], v[6], v[10], v[14],
                        v[3], v[7], v[11], v[15],
                    ]),
                    9 => DMat4::from_cols_array(&[
                        v[0], v[3], v[6], 0.0, v[1], v[4], v[7], 0.0, v[2], v[5], v[8], 0.0, 0.0,
                        0.0, 0.0, 1.0,
                    ]),
                    n => {
                        return Err(error_at(
                            &op.loc,
                            format!("<matrix>: 16 (or 9) numbers expected, found {n}"),
                        ));
                    }
                }
            }
            "lookat" => look_at(op)?,
            other => {
                return Err(error_at(
                    &op.loc,
                    format!(
                        "<{other}> inside <transform>: translate, rotate, scale, matrix and lookat are read"
                    ),
                ));
            }
        };
        m = step * m;
    }
    if !m.is_finite() || m.row(3) != glam::DVec4::new(0.0, 0.0, 0.0, 1.0) {
        return Err(error_at(
            &el.loc,
            "<transform>: not an affine transform (projective or not finite)",
        ));
    }
    Ok(m)
}

/// `<lookat origin target up>`: the camera frame Mitsuba builds, columns (left, up, forward,
/// origin).
fn look_at(op: &Element) -> Result<DMat4, ImportError> {
    let get = |k: &str| -> Result<DVec3, ImportError> {
        let v = numbers(op, op.required(k)?)?;
        match v.as_slice() {
            [x, y, z] => Ok(DVec3::new(*x, *y, *z)),
            _ => Err(error_at(&op.loc, format!("<lookat>: `{k}` must be three numbers"))),
        }
    };
    let origin = get("origin")?;
    let target = get("target")?;
    let up = op.attr("up").map_or(Ok(DVec3::Y), |_| get("up"))?;
    let dir = (target - origin).normalize_or_zero();
    let left = up.cross(dir).normalize_or_zero();
    if dir == DVec3::ZERO || left == DVec3::ZERO {
        return Err(error_at(
            &op.loc,
            "<lookat>: target equals origin, or up is parallel to the view",
        ));
    }
    let new_up = dir.cross(left);
    Ok(DMat4::from_cols(left.extend(0.0), new_up.extend(0.0), dir.extend(0.0), origin.extend(1.0)))
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::import::xml::Loc;
    use std::sync::Arc;

    fn el(tag: &str, attrs: &[(&str, &str)], children: Vec<Element>) -> Element {
        Element {
            tag: tag.to_owned(),
            attrs: attrs.iter().map(|(k, v)| ((*k).to_owned(), (*v).to_owned())).collect(),
            children,
            loc: Loc { file: Arc::new("t.xml".into()), line: 1 },
        }
    }

    /// Operations compose in order: scale 2, then translate by (1, 0, 0), then rotate 90 degrees
    /// about z takes (1, 0, 0) to (2, 0, 0), (3, 0, 0), then (0, 3, 0).
    #[test]
    fn operations_compose_in_order() {
        let t = el(
            "transform",
            &[("name", "to_world")],
            vec![
                el("scale", &[("value", "2")], vec![]),
                el("translate", &[("x", "1")], vec![]),
                el("rotate", &[("z", "1"), ("angle", "90")], vec![]),
            ],
        );
        let m = transform(&t).unwrap();
        let p = m.transform_point3(DVec3::X);
        assert!((p - DVec3::new(0.0, 3.0, 0.0)).length() < 1e-12, "{p}");
        let r = el(
            "transform",
            &[],
            vec![el("matrix", &[("value", "1 0 0 5 0 1 0 6 0 0 1 7 0 0 0 1")], vec![])],
        );
        assert_eq!(transform(&r).unwrap().transform_point3(DVec3::ZERO), DVec3::new(5.0, 6.0, 7.0));
    }

    #[test]
    fn bad_transforms_are_refused_with_the_cause() {
        let cases = [
            (el("matrix", &[("value", "1 2 3")], vec![]), "16"),
            (el("matrix", &[("value", "1 0 0 0 0 1 0 0 0 0 1 0 1 0 0 1")], vec![]), "affine"),
            (el("rotate", &[("x", "1")], vec![]), "angle"),
            (el("translate", &[("x", "nan")], vec![]), "finite"),
            (el("lookat", &[("origin", "0,0,0"), ("target", "0,0,0")], vec![]), "origin"),
            (el("shear", &[], vec![]), "shear"),
        ];
        for (op, cause) in cases {
            let e = transform(&el("transform", &[], vec![op])).unwrap_err().to_string();
            assert!(e.contains(cause) && e.starts_with("t.xml:1"), "{e}");
        }
    }
}
