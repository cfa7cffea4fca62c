//! What an observer's eye sees of a luminaire, for the Unified Glare Rating of CIE 117-1995
//! (*Discomfort glare in interior lighting*): [`GlareView`], the luminance and the solid angle of
//! a light's luminous parts seen from the eye, and [`LuminousOpening`], the shape the
//! photometric files give those parts.
//!
//! # CIE 117's quantities
//! The rating is `UGR = 8 log10(0.25 / L_b * sum L^2 omega / p^2)`, summed over the luminaires,
//! where `L` is "the luminance of the luminous parts of each luminaire in the direction of the
//! observer's eye" (cd/m^2), `omega` "the solid angle of the luminous parts of each luminaire at
//! the observer's eye" (sr), `p` the Guth position index and `L_b` the background luminance. A
//! photometric file gives a luminaire's luminous intensity `I` (cd) and the size of its
//! luminous opening, from which, as CIE 117 (and CIE 190 for tabulated ratings) does:
//!
//! ```text
//! A_p   = projected area of the luminous opening seen from the eye (m^2)
//! L     = I / A_p                 (the mean luminance of the opening towards the eye)
//! omega = A_p / r^2               (r: distance from the eye to the luminaire's centre)
//! ```
//!
//! `omega = A_p / r^2` is the small-source form of the solid angle; CIE 117 states its formula
//! for sources subtending between 0.0003 and 0.1 sr and leaves smaller and larger ones to other
//! rules, which are the caller's to apply. A point source (an opening of no size) has no
//! luminance: the light gives no [`GlareView`].
//!
//! # The opening's frame
//! Shapes are given in the luminaire's own frame, in metres: `x` along the C0 direction (LM-63's
//! *photometric horizontal*, "horizontal angle 0 and vertical angle 90"), `y` along C90 and `z`
//! along the nadir (downwards, the direction of vertical angle 0). A luminaire's *length* lies
//! along C0-C180 and its *width* along C90-C270 in both formats (see
//! [`crate::photometry::IesFile::luminous_opening`] and
//! [`crate::photometry::LdtFile::luminous_opening`]); its *height* is vertical.

use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI, TAU};

use glam::DVec3;

/// What an eye sees of a light: its centre, and the luminance, solid angle and projected area
/// of its luminous parts (see the module documentation for the definitions of CIE 117-1995).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GlareView {
    /// The light's centre (for a measured luminaire its photometric centre, `position`).
    pub centre: DVec3,
    /// Mean luminance of the luminous parts towards the eye (cd/m^2): `intensity /
    /// projected_area`.
    pub luminance: f64,
    /// Solid angle the luminous parts subtend at the eye (sr): `projected_area / r^2`, `r` the
    /// distance from the eye to `centre`.
    pub solid_angle: f64,
    /// Area of the luminous parts projected on a plane perpendicular to the line of sight
    /// (m^2).
    pub projected_area: f64,
    /// Luminous intensity towards the eye (cd), every multiplier of the light applied.
    pub intensity: f64,
}

/// The luminous opening of a measured luminaire, in metres, in the luminaire's frame: `length`
/// along C0-C180, `width` along C90-C270, heights vertical (see the module documentation).
/// [`projected_area`](Self::projected_area) gives the area an eye sees.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LuminousOpening {
    /// A rectangle (`heights` 0) or a box: a horizontal `length` x `width` face, and vertical
    /// sides of the heights `heights` facing C0, C90, C180 and C270 (the C0 side spans the width,
    /// the C90 side the length). A zero `length` or `width` with heights is a vertical
    /// rectangle.
    Box {
        /// Extent along C0-C180 (m).
        length: f64,
        /// Extent along C90-C270 (m).
        width: f64,
        /// Heights of the sides facing C0, C90, C180, C270 (m).
        heights: [f64; 4],
    },
    /// A disk or ellipse (`heights` 0) or a vertical cylinder: a horizontal elliptic face of
    /// diameters `length` (along C0-C180) and `width` (along C90-C270), and a vertical side
    /// whose height is `heights[q]` on the quarter of the rim centred on plane C(90 q).
    Cylinder {
        /// Diameter along C0-C180 (m).
        length: f64,
        /// Diameter along C90-C270 (m).
        width: f64,
        /// Heights of the side on the quarters of the rim about C0, C90, C180, C270 (m).
        heights: [f64; 4],
    },
    /// A sphere or ellipsoid of diameters `length`, `width` and `height`, luminous all over.
    Ellipsoid {
        /// Diameter along C0-C180 (m).
        length: f64,
        /// Diameter along C90-C270 (m).
        width: f64,
        /// Vertical diameter (m).
        height: f64,
    },
    /// A horizontal cylinder along the photometric horizontal (LM-63-2002's "horizontal
    /// cylinder along photometric horizontal"): axis along C0-C180 of length `length`, an
    /// elliptic cross-section of diameters `width` (horizontal) and `height` (vertical),
    /// luminous all over.
    CylinderAlongC0 {
        /// Length of the axis, along C0-C180 (m).
        length: f64,
        /// Horizontal diameter of the cross-section, along C90-C270 (m).
        width: f64,
        /// Vertical diameter of the cross-section (m).
        height: f64,
    },
    /// A horizontal cylinder perpendicular to the photometric horizontal: axis along C90-C270 of
    /// length `width`, a cross-section of diameters `length` (along C0-C180) and `height`,
    /// luminous all over.
    CylinderAlongC90 {
        /// Horizontal diameter of the cross-section, along C0-C180 (m).
        length: f64,
        /// Length of the axis, along C90-C270 (m).
        width: f64,
        /// Vertical diameter of the cross-section (m).
        height: f64,
    },
    /// A vertical disk or ellipse facing the photometric horizontal (C0): diameters `width`
    /// (along C90-C270) and `height`, luminous on both faces.
    VerticalEllipse {
        /// Horizontal diameter, along C90-C270 (m).
        width: f64,
        /// Vertical diameter (m).
        height: f64,
    },
}

impl LuminousOpening {
    /// The area (m^2) of the opening projected along the direction `local` (towards the eye,
    /// in the luminaire's frame: `x` along C0, `y` along C90, `z` along the nadir; normalised
    /// here, components under 1e-12 taken as 0; 0 for a zero or non-finite direction). `lower` says whether the horizontal face of a
    /// [`Box`](Self::Box) or [`Cylinder`](Self::Cylinder) gives light downwards (seen from
    /// below the opening's plane, `z > 0`), `upper` whether it gives light upwards; vertical
    /// sides and the other shapes are luminous all round. With `(x, y, z)` the unit direction,
    /// `a, b, c` the semi-diameters along `x, y, z`:
    ///
    /// ```text
    /// Box               L W (lower: max(z, 0) + upper: max(-z, 0))
    ///                     + W (h_C0 max(x, 0) + h_C180 max(-x, 0)) + L (h_C90 max(y, 0) + h_C270 max(-y, 0))
    /// Cylinder          pi a b (lower: max(z, 0) + upper: max(-z, 0))
    ///                     + R sum_q h_q (sin hi_q - sin lo_q)      (= 2 h R for equal heights)
    /// Ellipsoid         pi sqrt((b c x)^2 + (a c y)^2 + (a b z)^2)
    /// CylinderAlongC0   pi b c |x| + 2 length sqrt(b^2 z^2 + c^2 y^2)
    /// CylinderAlongC90  pi a c |y| + 2 width sqrt(a^2 z^2 + c^2 x^2)
    /// VerticalEllipse   pi b c |x|
    /// ```
    ///
    /// Each face of a box counts its area times the cosine between its normal and the line of
    /// sight, where that is positive (the faces of a convex body hide none of each other). A
    /// cylinder's side projects as `R = sqrt((b x)^2 + (a y)^2)` times the integral of the
    /// height around the lit half of the rim, `cos(phi - psi)` over `phi` in `psi +- 90`
    /// degrees (`phi` the rim's parametric angle, `psi = atan2(a y, b x)`), each quarter
    /// `[90 q - 45, 90 q + 45]` degrees at its own height; for a circular cylinder of equal
    /// heights that is `d h sin(gamma)`. The ellipsoid is the exact projection of an ellipsoid;
    /// a horizontal cylinder adds its two end caps (one seen at a time) to its side.
    pub fn projected_area(&self, local: DVec3, lower: bool, upper: bool) -> f64 {
        let length = local.length();
        if !(length > 0.0 && length.is_finite()) {
            return 0.0;
        }
        // Components within rounding of 0 (a direction along an axis, computed) are 0: an eye
        // straight above a box sees no side.
        let snap = |c: f64| if c.abs() < 1e-12 { 0.0 } else { c };
        let DVec3 { x, y, z } = (local / length).map(snap);
        let horizontal = |area: f64| {
            area * (if lower { z.max(0.0) } else { 0.0 } + if upper { (-z).max(0.0) } else { 0.0 })
        };
        let area = match *self {
            Self::Box { length, width, heights: [h0, h90, h180, h270] } => {
                horizontal(length * width)
                    + width * (h0 * x.max(0.0) + h180 * (-x).max(0.0))
                    + length * (h90 * y.max(0.0) + h270 * (-y).max(0.0))
            }
            Self::Cylinder { length, width, heights } => {
                let (a, b) = (length / 2.0, width / 2.0);
                horizontal(PI * a * b) + cylinder_side(a, b, heights, x, y)
            }
            Self::Ellipsoid { length, width, height } => {
                let (a, b, c) = (length / 2.0, width / 2.0, height / 2.0);
                PI * ((b * c * x).powi(2) + (a * c * y).powi(2) + (a * b * z).powi(2)).sqrt()
            }
            Self::CylinderAlongC0 { length, width, height } => {
                let (b, c) = (width / 2.0, height / 2.0);
                PI * b * c * x.abs() + 2.0 * length * ((b * z).powi(2) + (c * y).powi(2)).sqrt()
            }
            Self::CylinderAlongC90 { length, width, height } => {
                let (a, c) = (length / 2.0, height / 2.0);
                PI * a * c * y.abs() + 2.0 * width * ((a * z).powi(2) + (c * x).powi(2)).sqrt()
            }
            Self::VerticalEllipse { width, height } => PI * width * height / 4.0 * x.abs(),
        };
        if area.is_finite() { area.max(0.0) } else { 0.0 }
    }

    /// Whether every dimension is finite and `>= 0` and some is `> 0` (an opening that can be
    /// seen); the readers give no other.
    pub fn is_valid(&self) -> bool {
        let dims: Vec<f64> = match *self {
            Self::Box { length, width, heights } | Self::Cylinder { length, width, heights } => {
                [length, width].into_iter().chain(heights).collect()
            }
            Self::Ellipsoid { length, width, height }
            | Self::CylinderAlongC0 { length, width, height }
            | Self::CylinderAlongC90 { length, width, height } => vec![length, width, height],
            Self::VerticalEllipse { width, height } => vec![width, height],
        };
        dims.iter().all(|d| d.is_finite() && *d >= 0.0) && dims.iter().any(|d| *d > 0.0)
    }
}

/// The projected area of the side of a vertical elliptic cylinder of semi-diameters `a` (along
/// `x`) and `b` (along `y`) and heights `heights` on the quarters of its rim, seen along the unit
/// direction with horizontal components `x, y` (see [`LuminousOpening::projected_area`]).
fn cylinder_side(a: f64, b: f64, heights: [f64; 4], x: f64, y: f64) -> f64 {
    // The rim (a cos phi, b sin phi) has outward normal times arc length (b cos phi, a sin phi)
    // dphi, so the lit part of the side projects as the integral of
    // h(phi) max(0, b x cos phi + a y sin phi) = h(phi) R max(0, cos(phi - psi)).
    let (u, v) = (b * x, a * y);
    let r = u.hypot(v);
    if !(r > 0.0) {
        return 0.0;
    }
    let psi = v.atan2(u);
    let lit: f64 = heights
        .iter()
        .enumerate()
        .map(|(q, &h)| {
            // The quarter's centre relative to psi, in [-pi, pi): its wrapped-around part lies
            // beyond 3 pi / 4 and so outside the lit half.
            let centre = (q as f64 * FRAC_PI_2 - psi + PI).rem_euclid(TAU) - PI;
            let lo = (centre - FRAC_PI_4).max(-FRAC_PI_2);
            let hi = (centre + FRAC_PI_4).min(FRAC_PI_2);
            if hi > lo { h * (hi.sin() - lo.sin()) } else { 0.0 }
        })
        .sum();
    r * lit
}

/// A luminaire's opening placed in the world: its shape, the world directions of its frame's
/// axes, and which horizontal faces give light.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct PlacedOpening {
    opening: Option<LuminousOpening>,
    /// World directions of the frame's `x` (C0), `y` (C90) and `z` (nadir) axes.
    axes: [DVec3; 3],
    lower: bool,
    upper: bool,
}

impl PlacedOpening {
    /// `opening` (`None`: a point, or a shape the file does not define) with its frame's axes
    /// `[x, y, z]` in world directions; `lower` and `upper` as in
    /// [`LuminousOpening::projected_area`].
    pub(crate) fn new(
        opening: Option<LuminousOpening>,
        axes: [DVec3; 3],
        lower: bool,
        upper: bool,
    ) -> Self {
        Self { opening: opening.filter(LuminousOpening::is_valid), axes, lower, upper }
    }

    /// The opening's shape.
    pub(crate) fn opening(&self) -> Option<LuminousOpening> {
        self.opening
    }

    /// What an eye at `eye` sees of the opening centred at `position`, whose intensity (cd)
    /// along a unit world direction is `candela`; `None` for the eye at the centre, an opening
    /// of no projected area that way (a point source, a flat opening seen edge-on or from its
    /// dark side) or anything not finite.
    pub(crate) fn view(
        &self,
        position: DVec3,
        eye: DVec3,
        candela: impl Fn(DVec3) -> f64,
    ) -> Option<GlareView> {
        let opening = self.opening?;
        let to_eye = eye - position;
        let distance = to_eye.length();
        if !(distance > 0.0 && distance.is_finite()) {
            return None;
        }
        let d = to_eye / distance;
        let local = DVec3::new(d.dot(self.axes[0]), d.dot(self.axes[1]), d.dot(self.axes[2]));
        let projected_area = opening.projected_area(local, self.lower, self.upper);
        if !(projected_area > 0.0 && projected_area.is_finite()) {
            return None;
        }
        let intensity = candela(d);
        let view = GlareView {
            centre: position,
            luminance: intensity / projected_area,
            solid_angle: projected_area / (distance * distance),
            projected_area,
            intensity,
        };
        let finite =
            [view.luminance, view.solid_angle, view.intensity].iter().all(|v| v.is_finite());
        (finite && intensity >= 0.0).then_some(view)
    }
}

/// Which horizontal faces of a type C table's opening give light: `(lower, upper)`, whether
/// some measured value below the horizontal (vertical angle `< 90`) and some above (`> 90`) is
/// positive. Values at 90 degrees exactly (grazing the opening's plane) count for neither.
pub(crate) fn lit_faces(vertical: &[f64], candela: &[Vec<f64>]) -> (bool, bool) {
    let lit = |side: fn(f64) -> bool| {
        candela.iter().any(|row| row.iter().zip(vertical).any(|(&c, &g)| c > 0.0 && side(g)))
    };
    (lit(|g| g < 90.0), lit(|g| g > 90.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-12 * (1.0 + b.abs())
    }

    #[test]
    fn a_cylinder_of_equal_heights_projects_its_side_as_the_elliptic_formula() {
        for (a, b) in [(0.3, 0.3), (0.5, 0.2), (0.1, 0.7)] {
            for k in 0..24 {
                let t = f64::from(k) * TAU / 24.0 + 0.1;
                let (x, y) = (0.8 * t.cos(), 0.8 * t.sin());
                let side = cylinder_side(a, b, [0.2; 4], x, y);
                let want = 2.0 * 0.2 * ((a * y).powi(2) + (b * x).powi(2)).sqrt();
                assert!(close(side, want), "{a} {b} {t}: {side} vs {want}");
            }
        }
    }

    #[test]
    fn each_quarter_of_the_rim_has_its_own_height() {
        // Seen straight from C0, only the C0 quarter shows fully (r sin 45 on each side of the
        // axis) and the C90 and C270 quarters show their remaining parts.
        let (r, h) = (0.5, [1.0, 2.0, 4.0, 8.0]);
        let side = cylinder_side(r, r, h, 1.0, 0.0);
        let s = FRAC_PI_4.sin();
        let want = r * (1.0 * 2.0 * s + 2.0 * (1.0 - s) + 8.0 * (1.0 - s));
        assert!(close(side, want), "{side} vs {want}");
    }

    /// Cauchy: a convex body's projected area, averaged over all directions, is a quarter of
    /// its surface area (every face luminous). Averaged over a Fibonacci sphere.
    #[test]
    fn mean_projected_areas_are_a_quarter_of_the_surface() {
        let n = 200_000;
        let golden = PI * (3.0 - 5f64.sqrt());
        let mean = |o: LuminousOpening| {
            let sum: f64 = (0..n)
                .map(|i| {
                    let z = 1.0 - (2.0 * f64::from(i) + 1.0) / f64::from(n);
                    let r = (1.0 - z * z).sqrt();
                    let phi = golden * f64::from(i);
                    o.projected_area(DVec3::new(r * phi.cos(), r * phi.sin(), z), true, true)
                })
                .sum();
            sum / f64::from(n)
        };
        let (l, w, h) = (0.6, 0.3, [0.05, 0.1, 0.15, 0.2]);
        let r = 0.2;
        let quarter_arc = r * FRAC_PI_2;
        let cases = [
            (
                LuminousOpening::Box { length: l, width: w, heights: h },
                2.0 * l * w + w * (h[0] + h[2]) + l * (h[1] + h[3]),
            ),
            (
                LuminousOpening::Cylinder { length: 2.0 * r, width: 2.0 * r, heights: h },
                2.0 * PI * r * r + quarter_arc * h.iter().sum::<f64>(),
            ),
            (
                LuminousOpening::Ellipsoid { length: 2.0 * r, width: 2.0 * r, height: 2.0 * r },
                4.0 * PI * r * r,
            ),
            (
                LuminousOpening::CylinderAlongC0 { length: l, width: 2.0 * r, height: 2.0 * r },
                2.0 * PI * r * r + 2.0 * PI * r * l,
            ),
            (
                LuminousOpening::CylinderAlongC90 { length: 2.0 * r, width: l, height: 2.0 * r },
                2.0 * PI * r * r + 2.0 * PI * r * l,
            ),
            (LuminousOpening::VerticalEllipse { width: 0.3, height: 0.5 }, 2.0 * PI * 0.15 * 0.25),
        ];
        for (o, surface) in cases {
            let m = mean(o);
            assert!((m - surface / 4.0).abs() < 1e-4 * surface, "{o:?}: {m} vs {}", surface / 4.0);
        }
    }

    #[test]
    fn lit_faces_follow_the_measured_values() {
        let v = [0.0, 45.0, 90.0, 135.0, 180.0];
        assert_eq!(lit_faces(&v, &[vec![1.0, 1.0, 1.0, 0.0, 0.0]]), (true, false));
        assert_eq!(lit_faces(&v, &[vec![0.0, 0.0, 0.0, 3.0, 0.0]]), (false, true));
        assert_eq!(lit_faces(&v, &[vec![0.0, 0.0, 5.0, 0.0, 0.0]]), (false, false));
    }
}
