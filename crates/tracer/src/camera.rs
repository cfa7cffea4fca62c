//! [`PinholeCamera`]: rays out of the camera ([`PinholeCamera::generate_ray`]), the camera seen
//! from a scene point for light-tracing and BDPT connections ([`PinholeCamera::sample_wi`],
//! [`PinholeCamera::project`]) and the densities of camera rays for MIS
//! ([`PinholeCamera::pdf_we`]). With an `aperture_radius` the same type is a thin-lens camera.
//!
//! | field | unit | default | meaning |
//! |---|---|---|---|
//! | `position` | m | required | the pinhole (the lens centre with an aperture) |
//! | `look_at` | m | required | a point the camera looks at (the image centre) |
//! | `up` | | `[0, 1, 0]` | a direction that appears upwards in the image (not parallel to the view) |
//! | `fov` | degrees | required | full field of view along `fov_axis`, in (0, 180) |
//! | `fov_axis` | | `"horizontal"` | `"horizontal"`, `"vertical"` or `"diagonal"` |
//! | `width`, `height` | pixels | required | resolution, each at least 1 |
//! | `aperture_radius` | m | `0` | radius of a thin lens centred on `position`, facing the view direction; finite, `>= 0`; 0 is a pinhole |
//! | `focus_distance` | m | none | distance along the view direction of the plane in focus; finite, `> 0`; required when `aperture_radius > 0` |
//!
//! ```json
//! {"position": [0, 1, 4], "look_at": [0, 1, 0], "fov": 40, "fov_axis": "vertical", "width": 640, "height": 480}
//! {"position": [0, 1, 4], "look_at": [0, 1, 0], "fov": 40, "width": 640, "height": 480, "aperture_radius": 0.02, "focus_distance": 4}
//! ```
//!
//! # Film units
//! A pixel holds the mean spectral radiance over its area on the image plane (at distance 1 from
//! the pinhole; a box filter one pixel wide), so a camera ray through a uniformly chosen point of
//! the pixel estimates it directly. Seen from a scene point `x`, the same measurement is
//! `L(x -> camera) * cos(theta_x) / (d^2 * cos^3(theta_camera) * pixel_area)`, which
//! [`PinholeCamera::project`] returns as `importance` (without `L`).
//!
//! # Thin lens
//! A camera ray leaves a point of the lens disk chosen uniformly (Shirley and Chiu's concentric
//! map) towards the point of the focus plane that the pinhole ray through the lens centre and the
//! chosen film point would hit, so the focus plane is sharp and the field of view is the pinhole's.
//! The pixel measurement is the mean over the pixel area *and* the lens area, so a camera ray still
//! carries weight 1. Seen from a scene point `x` through a lens point `p` chosen uniformly, the
//! film area maps to the solid angle at `p` by `dA_film = dw / cos^3(theta)` (the focus-plane
//! scaling `focus_distance^2` cancels against the distance `focus_distance / cos(theta)` to the
//! focus plane), and the lens density `1 / (pi r^2)` cancels against the measurement's lens mean:
//! the estimate is `L(x -> p) * cos(theta_x) / (|x - p|^2 * cos^3(theta) * pixel_area)`, the
//! pinhole's formula with the distance and angle taken from `p`, returned by
//! [`PinholeCamera::sample_wi`]. [`PinholeCamera::project`] keeps projecting through the lens
//! centre (a pinhole), which is the right pixel only for points on the focus plane; integrators
//! connect to a lens camera with `sample_wi`.

use std::f64::consts::PI;

use glam::DVec3;
use serde::{Deserialize, Serialize};
use spectrace_sampling::{clamp_uniform, sample_uniform_disk_concentric};

/// The image axis a field of view is measured along.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FovAxis {
    /// The image width.
    #[default]
    Horizontal,
    /// The image height.
    Vertical,
    /// The image diagonal.
    Diagonal,
}

/// Why a camera description is invalid.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum CameraError {
    /// A field is out of range; names the field.
    #[error("camera.{field} = {value}: {reason}")]
    Invalid {
        /// The field.
        field: &'static str,
        /// The rejected value, formatted.
        value: String,
        /// What it must satisfy.
        reason: &'static str,
    },
}

fn invalid(field: &'static str, value: impl std::fmt::Debug, reason: &'static str) -> CameraError {
    CameraError::Invalid { field, value: format!("{value:?}"), reason }
}

/// A pinhole camera, or a thin-lens camera when it has an aperture.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "CameraRepr", into = "CameraRepr")]
pub struct PinholeCamera {
    repr: CameraRepr,
    /// Camera frame: right, up, forward (unit, right-handed with forward = -z of the camera).
    right: DVec3,
    up: DVec3,
    forward: DVec3,
    /// Half extents of the image on the plane at distance 1.
    half_width: f64,
    half_height: f64,
    /// Lens radius (m); 0 for a pinhole.
    lens_radius: f64,
    /// `lens_radius / focus_distance`: a lens offset seen on the image plane at distance 1 from
    /// the focus plane; 0 for a pinhole.
    lens_over_focus: f64,
    /// `1 / (pi lens_radius^2)`, the density of a lens point per unit area; 1 for a pinhole.
    lens_pdf: f64,
}

/// Scene-file form of [`PinholeCamera`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraRepr {
    /// The pinhole (m).
    pub position: DVec3,
    /// The point at the image centre (m).
    pub look_at: DVec3,
    /// A direction that appears up in the image.
    #[serde(default = "default_up")]
    pub up: DVec3,
    /// Full field of view (degrees) along `fov_axis`.
    pub fov: f64,
    /// Which image axis `fov` spans.
    #[serde(default)]
    pub fov_axis: FovAxis,
    /// Image width (pixels).
    pub width: u32,
    /// Image height (pixels).
    pub height: u32,
    /// Thin-lens radius (m); 0 (the default, omitted when written) is a pinhole.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub aperture_radius: f64,
    /// Distance of the plane in focus along the view direction (m); required with an aperture.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub focus_distance: Option<f64>,
}

/// Whether an aperture radius is the default (a pinhole), so scene files without a lens are
/// written (and fingerprinted) exactly as before lenses existed.
fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

/// The unit vector along a finite `v`, scaled by its largest component first so huge or tiny
/// components neither overflow nor underflow; `None` for zero.
fn unit(v: DVec3) -> Option<DVec3> {
    let m = v.abs().max_element();
    if !(m > 0.0) {
        return None;
    }
    let scaled = v / m;
    Some(scaled / scaled.length())
}

fn default_up() -> DVec3 {
    DVec3::Y
}

impl TryFrom<CameraRepr> for PinholeCamera {
    type Error = CameraError;
    fn try_from(r: CameraRepr) -> Result<Self, CameraError> {
        Self::new(r)
    }
}

impl From<PinholeCamera> for CameraRepr {
    fn from(c: PinholeCamera) -> Self {
        c.repr
    }
}

/// A ray leaving the camera.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraRay {
    /// Where it leaves: the pinhole, or a point of the lens.
    pub origin: DVec3,
    /// Unit direction into the scene.
    pub direction: DVec3,
}

/// The camera seen from a scene point, for connecting a path vertex to the camera (see
/// [`PinholeCamera::sample_wi`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraSample {
    /// Pixel column hit (0 = left).
    pub x: u32,
    /// Pixel row hit (0 = top).
    pub y: u32,
    /// The point on the lens (the pinhole for a pinhole camera).
    pub position: DVec3,
    /// Unit direction from the scene point to `position`.
    pub to_camera: DVec3,
    /// Distance from the scene point to `position` (m).
    pub distance: f64,
    /// `We / pdf` in the units of [`Projection::importance`]: multiply by the radiance leaving the
    /// point towards `position` and by `cos(theta_x)` to get the pixel's estimate.
    pub importance: f64,
    /// Density per steradian, at the scene point, of having chosen `position` (1 for a pinhole,
    /// a delta), for MIS.
    pub pdf: f64,
}

/// A scene point as the camera sees it (see [`PinholeCamera::project`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Projection {
    /// Pixel column (0 = left).
    pub x: u32,
    /// Pixel row (0 = top).
    pub y: u32,
    /// Unit direction from the scene point to the pinhole.
    pub to_camera: DVec3,
    /// Distance from the scene point to the pinhole (m).
    pub distance: f64,
    /// `1 / (distance^2 * cos^3(theta_camera) * pixel_area)`: multiply by the radiance leaving
    /// the point towards the camera and by `cos(theta_x)` to get the pixel's estimate.
    pub importance: f64,
}

impl PinholeCamera {
    /// Builds the camera.
    ///
    /// # Errors
    /// [`CameraError::Invalid`] naming `position`, `look_at` (equal to the position), `up`
    /// (parallel to the view direction or zero), `fov` (outside (0, 180)), `width` or `height`
    /// (zero), `aperture_radius` (negative, not finite, or so small or large that the lens area
    /// is not a normal number) or `focus_distance` (not finite and positive, missing with an
    /// aperture, or so small that `aperture_radius / focus_distance` overflows).
    pub fn new(repr: CameraRepr) -> Result<Self, CameraError> {
        if !repr.position.is_finite() {
            return Err(invalid("position", repr.position.to_array(), "must be finite"));
        }
        if !repr.look_at.is_finite() {
            return Err(invalid("look_at", repr.look_at.to_array(), "must be finite"));
        }
        let view = repr.look_at - repr.position;
        if !view.is_finite() {
            let (field, value) =
                if repr.position.abs().max_element() >= repr.look_at.abs().max_element() {
                    ("position", repr.position)
                } else {
                    ("look_at", repr.look_at)
                };
            return Err(invalid(
                field,
                value.to_array(),
                "too large: position and look_at are too far apart (look_at - position overflows)",
            ));
        }
        let Some(forward) = unit(view) else {
            return Err(invalid("look_at", repr.look_at.to_array(), "must differ from position"));
        };
        if !repr.up.is_finite() {
            return Err(invalid("up", repr.up.to_array(), "must be finite"));
        }
        let Some(up_dir) = unit(repr.up) else {
            return Err(invalid("up", repr.up.to_array(), "must be non-zero"));
        };
        // Both unit vectors: judged on direction, whatever their magnitudes.
        let right = forward.cross(up_dir);
        if !(right.length() > 1e-9) {
            return Err(invalid(
                "up",
                repr.up.to_array(),
                "must not be parallel to the view direction (look_at - position)",
            ));
        }
        let right = right.normalize();
        let up = right.cross(forward);
        if !(repr.fov > 0.0 && repr.fov < 180.0) {
            return Err(invalid("fov", repr.fov, "must lie in (0, 180) degrees"));
        }
        if repr.width == 0 {
            return Err(invalid("width", repr.width, "must be at least 1"));
        }
        if repr.height == 0 {
            return Err(invalid("height", repr.height, "must be at least 1"));
        }
        let tan = (repr.fov.to_radians() / 2.0).tan();
        let aspect = f64::from(repr.width) / f64::from(repr.height);
        let (half_width, half_height) = match repr.fov_axis {
            FovAxis::Horizontal => (tan, tan / aspect),
            FovAxis::Vertical => (tan * aspect, tan),
            FovAxis::Diagonal => {
                let d = (aspect * aspect + 1.0).sqrt();
                (tan * aspect / d, tan / d)
            }
        };
        let (lens_radius, lens_over_focus, lens_pdf) = lens(&repr)?;
        Ok(Self {
            repr,
            right,
            up,
            forward,
            half_width,
            half_height,
            lens_radius,
            lens_over_focus,
            lens_pdf,
        })
    }

    /// Image width in pixels.
    pub fn width(&self) -> u32 {
        self.repr.width
    }

    /// Image height in pixels.
    pub fn height(&self) -> u32 {
        self.repr.height
    }

    /// The pinhole (the lens centre for a thin lens).
    pub fn position(&self) -> DVec3 {
        self.repr.position
    }

    /// Area of one pixel on the image plane at distance 1.
    pub fn pixel_area(&self) -> f64 {
        (2.0 * self.half_width / f64::from(self.repr.width))
            * (2.0 * self.half_height / f64::from(self.repr.height))
    }

    /// The unit direction through raster position `(px, py)` (pixels, continuous; `(0, 0)` is the
    /// top-left corner of the image).
    pub fn direction(&self, px: f64, py: f64) -> DVec3 {
        let sx = (2.0 * px / f64::from(self.repr.width) - 1.0) * self.half_width;
        let sy = (1.0 - 2.0 * py / f64::from(self.repr.height)) * self.half_height;
        (self.forward + self.right * sx + self.up * sy).normalize()
    }

    /// Where a scene point appears: its pixel, the direction and distance to the pinhole, and the
    /// importance of a connection from it. `None` if it is behind the camera or outside the image.
    /// For a thin lens this projects through the lens centre, as a pinhole would: the right pixel
    /// only for points on the focus plane (use [`Self::sample_wi`] to connect to a lens).
    pub fn project(&self, point: DVec3) -> Option<Projection> {
        let to = self.repr.position - point;
        let distance = to.length();
        if !(distance > 0.0 && distance.is_finite()) {
            return None;
        }
        let d = -to / distance; // from the pinhole towards the point
        let cos = d.dot(self.forward);
        if !(cos > 0.0) {
            return None;
        }
        let (sx, sy) = (d.dot(self.right) / cos, d.dot(self.up) / cos);
        let px = (sx / self.half_width + 1.0) / 2.0 * f64::from(self.repr.width);
        let py = (1.0 - sy / self.half_height) / 2.0 * f64::from(self.repr.height);
        if !(px >= 0.0
            && py >= 0.0
            && px < f64::from(self.repr.width)
            && py < f64::from(self.repr.height))
        {
            return None;
        }
        let importance = 1.0 / (distance * distance * cos * cos * cos * self.pixel_area());
        Some(Projection {
            x: px as u32,
            y: py as u32,
            to_camera: to / distance,
            distance,
            importance,
        })
    }

    /// True for a pinhole (delta position), false with an aperture.
    pub fn is_pinhole(&self) -> bool {
        self.lens_radius == 0.0
    }

    /// Area of the whole image on the plane at distance 1 (= width*height*pixel_area()).
    pub fn image_area(&self) -> f64 {
        f64::from(self.repr.width) * f64::from(self.repr.height) * self.pixel_area()
    }

    /// The lens point for `u_lens` as an offset along (right, up) in lens radii (unit disk).
    fn lens_disk(u_lens: [f64; 2]) -> [f64; 2] {
        sample_uniform_disk_concentric(u_lens)
    }

    /// The world point of the lens at disk coordinates `l` (unit disk).
    fn lens_point(&self, l: [f64; 2]) -> DVec3 {
        self.repr.position
            + self.right * (self.lens_radius * l[0])
            + self.up * (self.lens_radius * l[1])
    }

    /// The continuous raster position `(px, py)` of a ray leaving the lens at disk coordinates
    /// `l` in unit direction `w`, with `cos(theta)` to the view direction; `None` if it points
    /// backwards or misses the image. The ray crosses the focus plane where the pinhole ray
    /// through the image-plane point `w_perp / cos + l * r / f` does.
    fn raster(&self, l: [f64; 2], w: DVec3) -> Option<(f64, f64, f64)> {
        let cos = w.dot(self.forward);
        if !(cos > 0.0) {
            return None;
        }
        let sx = w.dot(self.right) / cos + self.lens_over_focus * l[0];
        let sy = w.dot(self.up) / cos + self.lens_over_focus * l[1];
        let px = (sx / self.half_width + 1.0) / 2.0 * f64::from(self.repr.width);
        let py = (1.0 - sy / self.half_height) / 2.0 * f64::from(self.repr.height);
        if !(px >= 0.0
            && py >= 0.0
            && px < f64::from(self.repr.width)
            && py < f64::from(self.repr.height))
        {
            return None;
        }
        Some((px, py, cos))
    }

    /// Ray through pixel (px, py) at the uniform offset u_film in [0,1)^2 within the pixel, through the
    /// lens point chosen by u_lens (ignored for a pinhole).
    ///
    /// Uniforms outside `[0, 1)` are clamped into it. For a pinhole this is
    /// `direction(px + u_film[0], py + u_film[1])` from [`Self::position`], bit for bit.
    pub fn generate_ray(&self, px: u32, py: u32, u_film: [f64; 2], u_lens: [f64; 2]) -> CameraRay {
        let fx = f64::from(px) + clamp_uniform(u_film[0]);
        let fy = f64::from(py) + clamp_uniform(u_film[1]);
        if self.is_pinhole() {
            return CameraRay { origin: self.repr.position, direction: self.direction(fx, fy) };
        }
        let sx = (2.0 * fx / f64::from(self.repr.width) - 1.0) * self.half_width;
        let sy = (1.0 - 2.0 * fy / f64::from(self.repr.height)) * self.half_height;
        let l = Self::lens_disk(u_lens);
        // From the lens point to the focus-plane point `position + f * (forward + s)`, divided by
        // the focus distance `f`: no overflow whatever the scale of the scene.
        let v = self.forward
            + self.right * (sx - self.lens_over_focus * l[0])
            + self.up * (sy - self.lens_over_focus * l[1]);
        // The forward component is 1, so `v` is never zero.
        let direction = unit(v).unwrap_or(self.forward);
        CameraRay { origin: self.lens_point(l), direction }
    }

    /// Sample the lens towards `point` (u_lens ignored for a pinhole); None if the point does not
    /// project into the image, is behind the camera, or on the lens.
    ///
    /// For a pinhole, `importance` equals [`Self::project`]'s bit for bit and `pdf` is 1; for a
    /// thin lens, the lens point is uniform on the disk, `importance` is
    /// `1 / (distance^2 cos^3(theta) pixel_area)` with `theta` the angle of the ray at the lens
    /// (see the module docs), and `pdf = distance^2 / (cos(theta) pi r^2)`.
    pub fn sample_wi(&self, point: DVec3, u_lens: [f64; 2]) -> Option<CameraSample> {
        if self.is_pinhole() {
            let p = self.project(point)?;
            return Some(CameraSample {
                x: p.x,
                y: p.y,
                position: self.repr.position,
                to_camera: p.to_camera,
                distance: p.distance,
                importance: p.importance,
                pdf: 1.0,
            });
        }
        let l = Self::lens_disk(u_lens);
        let position = self.lens_point(l);
        let to = position - point;
        let distance = to.length();
        if !(distance > 0.0 && distance.is_finite()) {
            return None;
        }
        let to_camera = to / distance;
        let (px, py, cos) = self.raster(l, -to_camera)?;
        let d2 = distance * distance;
        let importance = 1.0 / (d2 * cos * cos * cos * self.pixel_area());
        let pdf = self.lens_pdf * d2 / cos;
        Some(CameraSample {
            x: px as u32,
            y: py as u32,
            position,
            to_camera,
            distance,
            importance,
            pdf,
        })
    }

    /// Densities of a camera ray for MIS (pbrt's PDF_We): (pdf_position, pdf_direction) where
    /// pdf_position = 1 for a pinhole (delta) or 1/(pi r^2) for a lens, and pdf_direction (sr^-1)
    /// = 1 / (A_image * cos^3 theta) with A_image the area of the WHOLE image on the plane at
    /// distance 1 (not one pixel), 0 outside the image.
    ///
    /// The ray's origin is taken to be on the lens (the pinhole for a pinhole camera); its
    /// direction need not be exactly unit.
    pub fn pdf_we(&self, ray: &CameraRay) -> (f64, f64) {
        let Some(w) = unit(ray.direction) else {
            return (self.lens_pdf, 0.0);
        };
        let l = if self.is_pinhole() {
            [0.0, 0.0]
        } else {
            let offset = ray.origin - self.repr.position;
            [offset.dot(self.right) / self.lens_radius, offset.dot(self.up) / self.lens_radius]
        };
        match self.raster(l, w) {
            Some((_, _, cos)) => (self.lens_pdf, 1.0 / (self.image_area() * cos * cos * cos)),
            None => (self.lens_pdf, 0.0),
        }
    }
}

/// The lens of a camera description: `(radius, radius / focus_distance, 1 / (pi radius^2))`,
/// `(0, 0, 1)` for a pinhole.
fn lens(repr: &CameraRepr) -> Result<(f64, f64, f64), CameraError> {
    let r = repr.aperture_radius;
    if !(r.is_finite() && r >= 0.0) {
        return Err(invalid("aperture_radius", r, "must be finite and >= 0 (m; 0 is a pinhole)"));
    }
    if let Some(f) = repr.focus_distance
        && !(f.is_finite() && f > 0.0)
    {
        return Err(invalid("focus_distance", f, "must be finite and > 0 (m)"));
    }
    if r == 0.0 {
        return Ok((0.0, 0.0, 1.0));
    }
    let area = PI * r * r;
    if !(area.is_normal() && area.is_finite()) {
        return Err(invalid(
            "aperture_radius",
            r,
            "out of range: the lens area pi * aperture_radius^2 must be a finite normal number",
        ));
    }
    let Some(f) = repr.focus_distance else {
        return Err(CameraError::Invalid {
            field: "focus_distance",
            value: "missing".to_owned(),
            reason: "required (m, > 0) when aperture_radius > 0",
        });
    };
    let ratio = r / f;
    if !ratio.is_finite() {
        return Err(invalid(
            "focus_distance",
            f,
            "too small for aperture_radius (aperture_radius / focus_distance overflows)",
        ));
    }
    Ok((r, ratio, 1.0 / area))
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_pcg::Pcg64;
    use spectrace_sampling::uniform;

    fn camera(fov_axis: FovAxis) -> PinholeCamera {
        PinholeCamera::new(CameraRepr {
            position: DVec3::new(0.0, 1.0, 4.0),
            look_at: DVec3::new(0.0, 1.0, 0.0),
            up: DVec3::Y,
            fov: 40.0,
            fov_axis,
            width: 64,
            height: 48,
            aperture_radius: 0.0,
            focus_distance: None,
        })
        .unwrap()
    }

    #[test]
    fn rays_and_projections_are_inverse() {
        let cam = camera(FovAxis::Vertical);
        for (px, py) in [(0.5, 0.5), (32.0, 24.0), (63.9, 47.9), (10.25, 40.75)] {
            let d = cam.direction(px, py);
            let p = cam.position() + d * 3.7;
            let proj = cam.project(p).unwrap();
            assert_eq!((proj.x, proj.y), (px as u32, py as u32));
            assert!((proj.to_camera + d).length() < 1e-12);
        }
        // The image centre looks at look_at; up is up and right is +x.
        assert!((cam.direction(32.0, 24.0) - DVec3::new(0.0, 0.0, -1.0)).length() < 1e-12);
        assert!(cam.direction(32.0, 0.0).y > 0.0 && cam.direction(63.0, 24.0).x > 0.0);
        assert!(cam.project(DVec3::new(0.0, 1.0, 5.0)).is_none(), "behind the camera");
    }

    #[test]
    fn fov_axes_span_the_named_axis() {
        let h = camera(FovAxis::Horizontal);
        let edge = h.direction(0.0, 24.0);
        assert!((edge.dot(DVec3::new(0.0, 0.0, -1.0)).acos().to_degrees() - 20.0).abs() < 1e-9);
        let v = camera(FovAxis::Vertical);
        let edge = v.direction(32.0, 0.0);
        assert!((edge.dot(DVec3::new(0.0, 0.0, -1.0)).acos().to_degrees() - 20.0).abs() < 1e-9);
        let d = camera(FovAxis::Diagonal);
        let corner = d.direction(0.0, 0.0);
        assert!((corner.dot(DVec3::new(0.0, 0.0, -1.0)).acos().to_degrees() - 20.0).abs() < 1e-9);
    }

    #[test]
    fn importance_integrates_to_the_pixel_measurement() {
        // A point of unit radiance filling the view at distance r, facing the camera: the sum of
        // importance * cos_x * dA over the plane behind one pixel equals 1 (mean radiance 1).
        let cam = camera(FovAxis::Vertical);
        let z = -2.0; // the plane z = -2, 6 m in front of the pinhole
        let (mut sum, n) = (0.0, 400);
        // Integrate over the plane patch seen by pixel (40, 10) with the midpoint rule.
        let corners = [cam.direction(40.0, 10.0), cam.direction(41.0, 11.0)];
        let hit = |d: DVec3| cam.position() + d * ((z - cam.position().z) / d.z);
        let (a, b) = (hit(corners[0]), hit(corners[1]));
        let (dx, dy) = ((b.x - a.x) / n as f64, (b.y - a.y) / n as f64);
        for i in 0..n {
            for j in 0..n {
                let p = DVec3::new(a.x + dx * (i as f64 + 0.5), a.y + dy * (j as f64 + 0.5), z);
                let proj = cam.project(p).unwrap();
                let cos_x = proj.to_camera.z.abs();
                sum += proj.importance * cos_x * (dx * dy).abs();
            }
        }
        assert!((sum - 1.0).abs() < 1e-3, "{sum}");
    }

    #[test]
    fn invalid_cameras_name_the_field() {
        let mut r = camera(FovAxis::Vertical).repr;
        r.fov = 180.0;
        assert!(PinholeCamera::new(r.clone()).unwrap_err().to_string().starts_with("camera.fov"));
        r.fov = 40.0;
        r.up = DVec3::new(0.0, 0.0, 1.0);
        assert!(PinholeCamera::new(r.clone()).unwrap_err().to_string().starts_with("camera.up"));
        r.up = DVec3::Y;
        r.look_at = r.position;
        assert!(
            PinholeCamera::new(r.clone()).unwrap_err().to_string().starts_with("camera.look_at")
        );
        let e = serde_json::from_str::<PinholeCamera>(
            r#"{"position": [0,0,0], "look_at": [0,0,-1], "fov": 40, "width": 0, "height": 4}"#,
        )
        .unwrap_err();
        assert!(e.to_string().contains("camera.width"), "{e}");
    }

    fn camera_error(position: [f64; 3], look_at: [f64; 3], up: [f64; 3]) -> String {
        let mut r = camera(FovAxis::Vertical).repr;
        r.position = DVec3::from_array(position);
        r.look_at = DVec3::from_array(look_at);
        r.up = DVec3::from_array(up);
        PinholeCamera::new(r).map_or_else(|e| e.to_string(), |_| String::new())
    }

    #[test]
    fn huge_or_tiny_vectors_are_judged_on_direction_and_overflow_blames_the_points() {
        // A far but finite pinhole is a valid camera; the old check blamed `up`.
        assert_eq!(camera_error([0.0, 0.0, 1e300], [0.0; 3], [0.0, 1.0, 0.0]), "");
        assert_eq!(camera_error([0.0, 0.0, 1e-320], [0.0; 3], [0.0, 1e300, 0.0]), "");
        assert_eq!(camera_error([0.0, 0.0, 1.0], [0.0; 3], [0.0, 1e-320, 0.0]), "");
        let e = camera_error([0.0, 0.0, 1.7e308], [0.0, 0.0, -1.7e308], [0.0, 1.0, 0.0]);
        assert!(e.starts_with("camera.position") && e.contains("too far apart"), "{e}");
        let e = camera_error([0.0, 0.0, 1.0e308], [0.0, 0.0, -1.7e308], [0.0, 1.0, 0.0]);
        assert!(e.starts_with("camera.look_at") && e.contains("too far apart"), "{e}");
        let e = camera_error([0.0, 0.0, 1e300], [0.0; 3], [0.0, 0.0, 1e300]);
        assert!(e.starts_with("camera.up") && e.contains("parallel"), "{e}");
        let e = camera_error([0.0, 0.0, 1.0], [0.0; 3], [0.0, -0.0, 0.0]);
        assert!(e.starts_with("camera.up") && e.contains("non-zero"), "{e}");
        let e = camera_error([0.0, 0.0, f64::INFINITY], [0.0; 3], [0.0, 1.0, 0.0]);
        assert!(e.starts_with("camera.position") && e.contains("finite"), "{e}");
        let e = camera_error([0.0, 0.0, 1.0], [0.0, f64::NAN, 0.0], [0.0, 1.0, 0.0]);
        assert!(e.starts_with("camera.look_at") && e.contains("finite"), "{e}");
    }

    fn lens_camera(aperture_radius: f64, focus_distance: f64) -> PinholeCamera {
        let mut r = camera(FovAxis::Vertical).repr;
        r.aperture_radius = aperture_radius;
        r.focus_distance = Some(focus_distance);
        PinholeCamera::new(r).unwrap()
    }

    fn u2(rng: &mut Pcg64) -> [f64; 2] {
        [uniform(rng), uniform(rng)]
    }

    /// A random pixel and an offset in [0.05, 0.95)^2 within it (away from the pixel's edges,
    /// where rounding may move a point to the neighbour).
    fn pixel_and_offset(cam: &PinholeCamera, rng: &mut Pcg64) -> (u32, u32, [f64; 2]) {
        let x = ((uniform(rng) * f64::from(cam.width())) as u32).min(cam.width() - 1);
        let y = ((uniform(rng) * f64::from(cam.height())) as u32).min(cam.height() - 1);
        (x, y, [0.05 + 0.9 * uniform(rng), 0.05 + 0.9 * uniform(rng)])
    }

    #[test]
    fn pinhole_generate_ray_is_direction_from_the_pinhole() {
        let mut rng = Pcg64::seed_from_u64(1);
        for cam in [camera(FovAxis::Horizontal), camera(FovAxis::Diagonal)] {
            assert!(cam.is_pinhole());
            for _ in 0..1000 {
                let (x, y) = ((uniform(&mut rng) * 64.0) as u32, (uniform(&mut rng) * 48.0) as u32);
                let (u, u_lens) = (u2(&mut rng), u2(&mut rng));
                let ray = cam.generate_ray(x, y, u, u_lens);
                assert_eq!(ray.origin, cam.position());
                assert_eq!(ray.direction, cam.direction(f64::from(x) + u[0], f64::from(y) + u[1]));
            }
        }
    }

    #[test]
    fn sample_wi_round_trips_through_generate_ray() {
        let mut rng = Pcg64::seed_from_u64(2);
        for cam in [camera(FovAxis::Vertical), lens_camera(0.05, 3.0), lens_camera(0.3, 7.0)] {
            for _ in 0..2000 {
                // A point in view: on a camera ray, 0.5 to 10 m from the lens.
                let (x, y, u_film) = pixel_and_offset(&cam, &mut rng);
                let u_lens = u2(&mut rng);
                let ray = cam.generate_ray(x, y, u_film, u_lens);
                assert!((ray.direction.length() - 1.0).abs() < 1e-12);
                let t = 0.5 + 9.5 * uniform(&mut rng);
                let point = ray.origin + ray.direction * t;
                // Seen from the point through the same lens point: the same pixel and lens point.
                let s = cam.sample_wi(point, u_lens).unwrap();
                assert_eq!((s.x, s.y), (x, y), "{cam:?}");
                assert!((s.position - ray.origin).length() < 1e-12);
                assert!((s.to_camera + ray.direction).length() < 1e-9);
                assert!((s.distance - t).abs() < 1e-9 * t);
                // And back: the film offset that sample_wi found regenerates the ray to the point.
                let l = PinholeCamera::lens_disk(u_lens);
                let l = if cam.is_pinhole() { [0.0, 0.0] } else { l };
                let (px, py, _) = cam.raster(l, -s.to_camera).unwrap();
                assert_eq!((px as u32, py as u32), (s.x, s.y));
                let offset = [px - f64::from(s.x), py - f64::from(s.y)];
                assert!(
                    (offset[0] - u_film[0]).abs() < 1e-6 && (offset[1] - u_film[1]).abs() < 1e-6
                );
                let back = cam.generate_ray(s.x, s.y, offset, u_lens);
                assert_eq!(back.origin, s.position);
                assert!((back.direction + s.to_camera).length() < 1e-9);
            }
        }
    }

    #[test]
    fn sample_wi_rejects_points_behind_on_or_outside_the_camera() {
        for cam in [camera(FovAxis::Vertical), lens_camera(0.1, 3.0)] {
            let u = [0.3, 0.7];
            assert!(cam.sample_wi(DVec3::new(0.0, 1.0, 5.0), u).is_none(), "behind");
            assert!(cam.sample_wi(cam.lens_point(PinholeCamera::lens_disk(u)), u).is_none());
            assert!(cam.sample_wi(DVec3::new(0.0, 1.0, 4.0), [0.5, 0.5]).is_none(), "lens centre");
            assert!(cam.sample_wi(DVec3::new(10.0, 1.0, 3.0), u).is_none(), "outside the image");
            assert!(cam.sample_wi(DVec3::new(0.0, 1.0, 1.0), u).is_some());
        }
    }

    #[test]
    fn pinhole_sample_wi_is_project() {
        let cam = camera(FovAxis::Vertical);
        let mut rng = Pcg64::seed_from_u64(3);
        for _ in 0..1000 {
            let (x, y, u) = pixel_and_offset(&cam, &mut rng);
            let d = cam.direction(f64::from(x) + u[0], f64::from(y) + u[1]);
            let point = cam.position() + d * (0.1 + 20.0 * uniform(&mut rng));
            let p = cam.project(point).unwrap();
            let s = cam.sample_wi(point, u2(&mut rng)).unwrap();
            assert_eq!((s.x, s.y, s.position), (p.x, p.y, cam.position()));
            assert_eq!((s.to_camera, s.distance), (p.to_camera, p.distance));
            assert_eq!(s.importance, p.importance);
            assert_eq!(s.pdf, 1.0);
        }
    }

    /// Monte Carlo estimate of the integral of `pdf_we`'s direction density over all directions
    /// from `origin`, by uniform directions in a cone about the view that covers the image; returns
    /// (mean, standard error).
    fn integrate_pdf_we(cam: &PinholeCamera, origin: DVec3, seed: u64) -> (f64, f64) {
        let corner = cam.half_width.hypot(cam.half_height).atan() * 1.05;
        let one_minus_cos = spectrace_sampling::one_minus_cos(corner);
        let frame = spectrace_sampling::Frame::from_normal(cam.forward);
        let mut rng = Pcg64::seed_from_u64(seed);
        let n = 200_000;
        let (mut sum, mut sum2) = (0.0, 0.0);
        for _ in 0..n {
            let local = spectrace_sampling::sample_uniform_cone(u2(&mut rng), one_minus_cos);
            let ray = CameraRay { origin, direction: frame.to_world(local) };
            let v = cam.pdf_we(&ray).1 / spectrace_sampling::pdf_uniform_cone(one_minus_cos);
            sum += v;
            sum2 += v * v;
        }
        let mean = sum / f64::from(n);
        (mean, ((sum2 / f64::from(n) - mean * mean) / f64::from(n)).sqrt())
    }

    #[test]
    fn pdf_we_direction_integrates_to_one_over_the_image() {
        let cam = camera(FovAxis::Diagonal);
        assert_eq!(cam.pdf_we(&cam.generate_ray(3, 4, [0.5, 0.5], [0.0; 2])).0, 1.0);
        let (mean, sigma) = integrate_pdf_we(&cam, cam.position(), 4);
        assert!((mean - 1.0).abs() < 3.0 * sigma, "pinhole: {mean} +- {sigma}");
        // From any point of a lens, the image spans the same solid-angle measure.
        let cam = lens_camera(0.2, 2.5);
        let ray = cam.generate_ray(3, 4, [0.5, 0.5], [0.9, 0.2]);
        assert!((cam.pdf_we(&ray).0 * PI * 0.2 * 0.2 - 1.0).abs() < 1e-12);
        let (mean, sigma) = integrate_pdf_we(&cam, ray.origin, 5);
        assert!((mean - 1.0).abs() < 3.0 * sigma, "lens: {mean} +- {sigma}");
        // Backwards and outside the image: 0.
        let back = CameraRay { origin: cam.position(), direction: -cam.forward };
        assert_eq!(cam.pdf_we(&back).1, 0.0);
        let side = CameraRay { origin: cam.position(), direction: cam.right };
        assert_eq!(cam.pdf_we(&side).1, 0.0);
        assert!((cam.image_area() - 4.0 * cam.half_width * cam.half_height).abs() < 1e-12);
    }

    #[test]
    fn pdf_we_matches_the_image_area_density_of_generated_rays() {
        // pdf_direction * image_area * cos^3 = 1 inside the image, for pinhole and lens rays.
        let mut rng = Pcg64::seed_from_u64(6);
        for cam in [camera(FovAxis::Horizontal), lens_camera(0.1, 2.0)] {
            for _ in 0..200 {
                let (x, y, u) = pixel_and_offset(&cam, &mut rng);
                let ray = cam.generate_ray(x, y, u, u2(&mut rng));
                let cos = ray.direction.dot(cam.forward);
                let (_, pdf) = cam.pdf_we(&ray);
                assert!((pdf * cam.image_area() * cos.powi(3) - 1.0).abs() < 1e-9, "{pdf}");
            }
        }
    }

    #[test]
    fn thin_lens_focus_plane_is_sharp() {
        let cam = lens_camera(0.1, 3.0);
        assert!(!cam.is_pinhole());
        let mut rng = Pcg64::seed_from_u64(7);
        for _ in 0..200 {
            let (x, y, u) = pixel_and_offset(&cam, &mut rng);
            let d = cam.direction(f64::from(x) + u[0], f64::from(y) + u[1]);
            let point = cam.position() + d * (3.0 / d.dot(cam.forward));
            let p = cam.project(point).unwrap();
            assert_eq!((p.x, p.y), (x, y));
            for _ in 0..64 {
                let s = cam.sample_wi(point, u2(&mut rng)).unwrap();
                assert_eq!((s.x, s.y), (x, y));
            }
        }
        // Off the focus plane the lens blurs: some lens points see a neighbouring pixel.
        let d = cam.direction(40.5, 10.5);
        let near = cam.position() + d * (1.0 / d.dot(cam.forward));
        let pixels: std::collections::HashSet<(u32, u32)> =
            (0..64).filter_map(|_| cam.sample_wi(near, u2(&mut rng))).map(|s| (s.x, s.y)).collect();
        assert!(pixels.len() > 1, "{pixels:?}");
    }

    #[test]
    fn thin_lens_importance_of_an_in_focus_patch_equals_the_pinhole_answer() {
        // A Lambertian patch of unit radiance on the focus plane covering pixel (40, 10) exactly:
        // the pixel's value is 1 for a pinhole and for a lens focused on it. Midpoint rule over the
        // patch, one random lens point per quadrature point.
        let pinhole = camera(FovAxis::Vertical);
        let lens = lens_camera(0.2, 3.0);
        let z = 1.0; // the focus plane, 3 m in front of the lens
        let hit = |d: DVec3| pinhole.position() + d * ((z - pinhole.position().z) / d.z);
        let (a, b) = (hit(pinhole.direction(40.0, 10.0)), hit(pinhole.direction(41.0, 11.0)));
        let n = 200;
        let (dx, dy) = ((b.x - a.x) / f64::from(n), (b.y - a.y) / f64::from(n));
        let mut rng = Pcg64::seed_from_u64(8);
        let (mut with_pinhole, mut with_lens) = (0.0, 0.0);
        for i in 0..n {
            for j in 0..n {
                let p =
                    DVec3::new(a.x + dx * (f64::from(i) + 0.5), a.y + dy * (f64::from(j) + 0.5), z);
                let area = (dx * dy).abs();
                let pr = pinhole.project(p).unwrap();
                if (pr.x, pr.y) == (40, 10) {
                    with_pinhole += pr.importance * pr.to_camera.z.abs() * area;
                }
                let s = lens.sample_wi(p, u2(&mut rng)).unwrap();
                if (s.x, s.y) == (40, 10) {
                    with_lens += s.importance * s.to_camera.z.abs() * area;
                }
            }
        }
        assert!((with_pinhole - 1.0).abs() < 1e-3, "{with_pinhole}");
        assert!((with_lens - with_pinhole).abs() < 1e-3, "{with_lens} vs {with_pinhole}");
    }

    #[test]
    fn thin_lens_light_tracing_estimate_matches_camera_rays_out_of_focus() {
        // A square Lambertian patch of unit radiance facing the camera, 5 m away while the lens
        // focuses at 3 m: the blurred value of a pixel at its edge, once from camera rays (the
        // fraction of rays that hit the patch) and once from points on the patch connected by
        // sample_wi (importance * cos_x * area). Agreement within 4 combined standard errors,
        // which are checked to be under 0.4% of the value (so a 2% error in the importance fails).
        let cam = lens_camera(0.3, 3.0);
        let (depth, z) = (5.0, -1.0);
        let (half, centre) = (0.2, DVec3::new(0.0, 1.0, z));
        let (px, py) = (34, 22);
        let n = 4_000_000_u32;
        let mut rng = Pcg64::seed_from_u64(9);
        let mut hits = 0_u32;
        for _ in 0..n {
            let ray = cam.generate_ray(px, py, u2(&mut rng), u2(&mut rng));
            let t = (z - ray.origin.z) / ray.direction.z;
            let q = ray.origin + ray.direction * t;
            if (q.x - centre.x).abs() < half && (q.y - centre.y).abs() < half {
                hits += 1;
            }
        }
        let camera_rays = f64::from(hits) / f64::from(n);
        let sigma_rays = (camera_rays * (1.0 - camera_rays) / f64::from(n)).sqrt();
        // Seen through lens point l (unit disk), a point at depth D whose pinhole image is s0
        // lands at s0 + r (1/f - 1/D) l on the image plane: only the patch points whose pinhole
        // image lies within that blur radius of the pixel can reach it, so sample those alone.
        let blur = 0.3 * (1.0 / 3.0 - 1.0 / depth) * 1.001;
        let to_plane = |raster_x: f64, raster_y: f64| {
            let sx = (2.0 * raster_x / 64.0 - 1.0) * cam.half_width;
            let sy = (1.0 - 2.0 * raster_y / 48.0) * cam.half_height;
            (sx, sy)
        };
        let (s_left, s_top) = to_plane(f64::from(px), f64::from(py));
        let (s_right, s_bottom) = to_plane(f64::from(px + 1), f64::from(py + 1));
        let x_range = (
            (depth * (s_left - blur)).max(centre.x - half),
            (depth * (s_right + blur)).min(centre.x + half),
        );
        let y_range = (
            (1.0 + depth * (s_bottom - blur)).max(centre.y - half),
            (1.0 + depth * (s_top + blur)).min(centre.y + half),
        );
        let area = (x_range.1 - x_range.0) * (y_range.1 - y_range.0);
        assert!(area > 0.0 && area < 0.6 * 4.0 * half * half, "{x_range:?} {y_range:?}");
        let (mut sum, mut sum2) = (0.0, 0.0);
        for _ in 0..n {
            let [a, b] = u2(&mut rng);
            let p = DVec3::new(
                x_range.0 + a * (x_range.1 - x_range.0),
                y_range.0 + b * (y_range.1 - y_range.0),
                z,
            );
            if let Some(s) = cam.sample_wi(p, u2(&mut rng))
                && (s.x, s.y) == (px, py)
            {
                let v = s.importance * s.to_camera.z * area;
                sum += v;
                sum2 += v * v;
            }
        }
        let light = sum / f64::from(n);
        let sigma_light = ((sum2 / f64::from(n) - light * light) / f64::from(n)).sqrt();
        assert!(camera_rays > 0.1 && camera_rays < 0.9, "not at the blurred edge: {camera_rays}");
        let sigma = sigma_rays.hypot(sigma_light);
        assert!(
            (light - camera_rays).abs() < 4.0 * sigma,
            "{light} vs {camera_rays} (sigma {sigma})"
        );
        assert!(sigma < 0.004 * camera_rays, "too noisy to detect a 2% error: {sigma}");
    }

    #[test]
    fn invalid_lenses_name_the_field() {
        let error = |aperture_radius: f64, focus_distance: Option<f64>| {
            let mut r = camera(FovAxis::Vertical).repr;
            r.aperture_radius = aperture_radius;
            r.focus_distance = focus_distance;
            PinholeCamera::new(r).map_or_else(|e| e.to_string(), |_| String::new())
        };
        for bad in [-0.1, f64::NAN, f64::INFINITY, -f64::INFINITY, 1e-200, 1e200] {
            let e = error(bad, Some(2.0));
            assert!(e.starts_with("camera.aperture_radius"), "{bad}: {e}");
        }
        let e = error(0.1, None);
        assert!(e.starts_with("camera.focus_distance") && e.contains("required"), "{e}");
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let e = error(0.1, Some(bad));
            assert!(e.starts_with("camera.focus_distance"), "{bad}: {e}");
            // Checked even without an aperture, where it has no effect.
            let e = error(0.0, Some(bad));
            assert!(e.starts_with("camera.focus_distance"), "{bad}: {e}");
        }
        let e = error(1e100, Some(1e-300));
        assert!(e.starts_with("camera.focus_distance") && e.contains("overflows"), "{e}");
        assert_eq!(error(0.0, None), "");
        assert_eq!(error(-0.0, None), "");
        assert_eq!(error(0.01, Some(1e6)), "");
        let e = error(1e200, Some(1.0));
        assert!(e.contains("lens area"), "{e}");

        let json = |extra: &str| {
            serde_json::from_str::<PinholeCamera>(&format!(
                r#"{{"position": [0,0,0], "look_at": [0,0,-1], "fov": 40, "width": 4, "height": 4{extra}}}"#
            ))
        };
        let e = json(r#", "aperture_radius": -1"#).unwrap_err().to_string();
        assert!(e.contains("camera.aperture_radius"), "{e}");
        let e = json(r#", "aperture_radius": 0.1"#).unwrap_err().to_string();
        assert!(e.contains("camera.focus_distance"), "{e}");
        let e = json(r#", "aperture_radius": 0.1, "focus_distance": 0"#).unwrap_err().to_string();
        assert!(e.contains("camera.focus_distance"), "{e}");
        let e = json(r#", "aperture": 0.1"#).unwrap_err().to_string();
        assert!(e.contains("unknown field") && e.contains("aperture"), "{e}");
    }

    #[test]
    fn lens_fields_round_trip_and_pinholes_are_written_as_before() {
        let base = r#"{"position":[0.0,0.0,0.0],"look_at":[0.0,0.0,-1.0],"up":[0.0,1.0,0.0],"fov":40.0,"fov_axis":"horizontal","width":4,"height":4"#;
        let pinhole: PinholeCamera = serde_json::from_str(&format!("{base}}}")).unwrap();
        assert_eq!(serde_json::to_string(&pinhole).unwrap(), format!("{base}}}"));
        let text = format!(r#"{base},"aperture_radius":0.05,"focus_distance":2.5}}"#);
        let lens: PinholeCamera = serde_json::from_str(&text).unwrap();
        assert!(!lens.is_pinhole());
        assert_eq!(serde_json::to_string(&lens).unwrap(), text);
    }
}
