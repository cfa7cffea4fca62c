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
        let (px, py) = self.to_raster(sx, sy)?;
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

    /// The raster position (continuous pixel coordinates) of a point `(sx, sy)` on the plane at
    /// distance 1 in front of the pinhole, or `None` outside the image.
    #[inline]
    fn to_raster(&self, sx: f64, sy: f64) -> Option<(f64, f64)> {
        let (width, height) = (f64::from(self.repr.width), f64::from(self.repr.height));
        let px = (sx / self.half_width + 1.0) / 2.0 * width;
        let py = (1.0 - sy / self.half_height) / 2.0 * height;
        (px >= 0.0 && py >= 0.0 && px < width && py < height).then_some((px, py))
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
        let (px, py) = self.to_raster(sx, sy)?;
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
mod tests;
