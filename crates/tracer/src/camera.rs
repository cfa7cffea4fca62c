//! [`PinholeCamera`]: rays out of the camera, and the projection of scene points into it for
//! light-tracing connections.
//!
//! | field | unit | default | meaning |
//! |---|---|---|---|
//! | `position` | m | required | the pinhole |
//! | `look_at` | m | required | a point the camera looks at (the image centre) |
//! | `up` | | `[0, 1, 0]` | a direction that appears upwards in the image (not parallel to the view) |
//! | `fov` | degrees | required | full field of view along `fov_axis`, in (0, 180) |
//! | `fov_axis` | | `"horizontal"` | `"horizontal"`, `"vertical"` or `"diagonal"` |
//! | `width`, `height` | pixels | required | resolution, each at least 1 |
//!
//! ```json
//! {"position": [0, 1, 4], "look_at": [0, 1, 0], "fov": 40, "fov_axis": "vertical", "width": 640, "height": 480}
//! ```
//!
//! # Film units
//! A pixel holds the mean spectral radiance over its area on the image plane (at distance 1 from
//! the pinhole; a box filter one pixel wide), so a camera ray through a uniformly chosen point of
//! the pixel estimates it directly. Seen from a scene point `x`, the same measurement is
//! `L(x -> camera) * cos(theta_x) / (d^2 * cos^3(theta_camera) * pixel_area)`, which
//! [`PinholeCamera::project`] returns as `importance` (without `L`).

use glam::DVec3;
use serde::{Deserialize, Serialize};

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

/// A pinhole camera.
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
    /// (zero).
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
        Ok(Self { repr, right, up, forward, half_width, half_height })
    }

    /// Image width in pixels.
    pub fn width(&self) -> u32 {
        self.repr.width
    }

    /// Image height in pixels.
    pub fn height(&self) -> u32 {
        self.repr.height
    }

    /// The pinhole.
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
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera(fov_axis: FovAxis) -> PinholeCamera {
        PinholeCamera::new(CameraRepr {
            position: DVec3::new(0.0, 1.0, 4.0),
            look_at: DVec3::new(0.0, 1.0, 0.0),
            up: DVec3::Y,
            fov: 40.0,
            fov_axis,
            width: 64,
            height: 48,
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
}
