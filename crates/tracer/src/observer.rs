//! Observers: eye positions where lighting designers read the light a person receives, as
//! EN 12464-1, CIE S 026 and CIE 117 ask for it (vertical, cylindrical and semi-cylindrical
//! illuminance, melanopic EDI at the eye, the glare rating's background).
//!
//! | field | unit | default | meaning |
//! |---|---|---|---|
//! | `name` | | required | names the observer in the sidecar and the terminal |
//! | `position` | m | required | the eye (for a seated office worker typically 1.2 m above the floor) |
//! | `view` | | required | the line of sight (need not be unit length; not parallel to `up`) |
//! | `up` | | `[0, 1, 0]` | the vertical: the axis of the cylinders and the normal of the horizontal plane |
//!
//! ```json
//! "observers": [{"name": "desk_1", "position": [1.0, 1.2, -0.5], "view": [0, 0, -1]}]
//! ```
//!
//! # Quantities
//! Each observer is five receivers at the eye ([`OBSERVER_QUANTITIES`], see
//! [`Response`] for each one's weighting of directions): horizontal illuminance (facing up),
//! vertical illuminance facing the horizontal part of `view`, cylindrical illuminance about
//! `up`, semi-cylindrical illuminance facing the view, and the vertical illuminance without the
//! point and spot lights seen directly (the indirect light a glare rating takes as the
//! background). Observers block nothing.

use glam::DVec3;
use serde::{Deserialize, Serialize};

use crate::integrators::sensor_path::Response;

/// Most observers a scene may have.
pub const MAX_OBSERVERS: usize = 4096;

/// What each observer records, in the order of its receivers.
pub const OBSERVER_QUANTITIES: [&str; 5] =
    ["horizontal", "vertical", "cylindrical", "semicylindrical", "vertical_indirect"];

/// An eye position with a line of sight.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "ObserverRepr", into = "ObserverRepr")]
pub struct Observer {
    repr: ObserverRepr,
    view: DVec3,
    up: DVec3,
    facing: DVec3,
}

/// Scene-file form of an observer.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct ObserverRepr {
    name: String,
    position: DVec3,
    view: DVec3,
    #[serde(default = "default_up")]
    up: DVec3,
}

fn default_up() -> DVec3 {
    DVec3::Y
}

impl TryFrom<ObserverRepr> for Observer {
    type Error = String;
    fn try_from(r: ObserverRepr) -> Result<Self, String> {
        Observer::new(r.name, r.position, r.view, r.up)
    }
}

impl From<Observer> for ObserverRepr {
    fn from(o: Observer) -> Self {
        o.repr
    }
}

impl Observer {
    /// An observer at `position` looking along `view`, with the vertical `up`.
    ///
    /// # Errors
    /// Why, naming the field: an empty name, a vector not finite or of length 0, a `view`
    /// parallel to `up` (a line of sight straight up or down has no facing direction).
    pub fn new(name: String, position: DVec3, view: DVec3, up: DVec3) -> Result<Self, String> {
        if name.is_empty() {
            return Err("name: must not be empty (it names the observer's figures)".into());
        }
        for (field, v) in [("position", position), ("view", view), ("up", up)] {
            if !v.is_finite() {
                return Err(format!("{field}: {:?} must be finite", v.to_array()));
            }
        }
        let (v, u) = (view.normalize_or_zero(), up.normalize_or_zero());
        if v == DVec3::ZERO || u == DVec3::ZERO {
            return Err(format!(
                "view {:?} and up {:?}: must not be of length 0",
                view.to_array(),
                up.to_array()
            ));
        }
        let facing = (v - u * v.dot(u)).normalize_or_zero();
        if facing == DVec3::ZERO || facing.length_squared() < 0.5 || v.dot(u).abs() > 1.0 - 1e-9 {
            return Err(format!(
                "view {:?}: must not be parallel to up {:?} (the vertical quantities face the \
                 line of sight's horizontal direction)",
                view.to_array(),
                up.to_array()
            ));
        }
        Ok(Self { repr: ObserverRepr { name, position, view, up }, view: v, up: u, facing })
    }

    /// The observer's name.
    pub fn name(&self) -> &str {
        &self.repr.name
    }

    /// The eye.
    pub fn position(&self) -> DVec3 {
        self.repr.position
    }

    /// The unit line of sight.
    pub fn view(&self) -> DVec3 {
        self.view
    }

    /// The unit vertical.
    pub fn up(&self) -> DVec3 {
        self.up
    }

    /// The unit horizontal direction the vertical quantities face: `view` without its
    /// vertical part.
    pub fn facing(&self) -> DVec3 {
        self.facing
    }

    /// The receivers of [`OBSERVER_QUANTITIES`], in order.
    pub fn responses(&self) -> [Response; 5] {
        [
            Response::Planar(self.up),
            Response::Planar(self.facing),
            Response::Cylindrical(self.up),
            Response::SemiCylindrical { up: self.up, facing: self.facing },
            Response::PlanarExceptDeltaLights(self.facing),
        ]
    }
}

/// Checks a scene's observers: at most [`MAX_OBSERVERS`], names used once.
///
/// # Errors
/// Naming the observer.
pub fn check_observers(observers: &[Observer]) -> Result<(), String> {
    if observers.len() > MAX_OBSERVERS {
        return Err(format!(
            "observers: {} observers, more than the {MAX_OBSERVERS} a scene may have",
            observers.len()
        ));
    }
    for (i, o) in observers.iter().enumerate() {
        if observers[..i].iter().any(|p| p.name() == o.name()) {
            return Err(format!("observers[{i}].name: \"{}\" is used twice", o.name()));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn an_observer_faces_the_horizontal_part_of_its_view() {
        let o =
            Observer::new("a".into(), DVec3::ZERO, DVec3::new(0.0, -1.0, -1.0), DVec3::Y).unwrap();
        assert!((o.facing() - DVec3::NEG_Z).length() < 1e-12);
        let e = Observer::new("a".into(), DVec3::ZERO, DVec3::NEG_Y, DVec3::Y).unwrap_err();
        assert!(e.contains("parallel"), "{e}");
        let e = Observer::new(String::new(), DVec3::ZERO, DVec3::X, DVec3::Y).unwrap_err();
        assert!(e.contains("name"), "{e}");
        let json = r#"{"name": "a", "position": [0, 1.2, 0], "view": [1, 0, 0], "eye": 1}"#;
        let e = serde_json::from_str::<Observer>(json).unwrap_err().to_string();
        assert!(e.contains("eye"), "{e}");
        let twice = vec![o.clone(), o];
        assert!(check_observers(&twice).unwrap_err().contains("used twice"));
    }
}
