//! Observers in a render: the light at each eye position (horizontal, vertical, cylindrical and
//! semi-cylindrical illuminance, melanopic EDI at the eye) and the unified glare rating for the
//! line of sight, as the sidecar reports them.
//!
//! After the image (and the sensors), an *observer pass* runs the path tracer from every eye,
//! `settings.observer_spp` samples per quantity ([`spectrace_tracer::ObserverTracer`]). The glare
//! rating then follows CIE 117-1995:
//!
//! `UGR = 8 log10( 0.25 / L_b * sum over luminaires of L^2 omega / p^2 )`
//!
//! - `L` (cd/m^2) is a luminaire's luminance towards the eye: its intensity towards the eye over
//!   the projected area of its luminous opening, `omega = A_p / r^2` (sr) the solid angle of that
//!   opening (the light's [`spectrace_lights::LightSource::glare_view`]; lights without a
//!   luminous opening, such as point lights or emitting surfaces, are background, not glare
//!   sources);
//! - `p` is the Guth position index ([`guth_position_index`]) of the luminaire's direction
//!   relative to the line of sight. Only luminaires in front of the eye and at or above the
//!   horizontal plane through the line of sight count (the upper field the index is defined
//!   over), and only those the eye sees (an unblocked segment to their centre);
//! - `L_b = E_ind / pi` (cd/m^2) is the background luminance, from the observer's vertical
//!   illuminance without the point, spot and luminaire lights seen directly (`vertical_indirect`).

use std::time::Instant;

use glam::DVec3;
use serde::{Deserialize, Serialize};
use spectrace_lights::LightSource;
use spectrace_tracer::{
    Effects, OBSERVER_QUANTITIES, Observer, ObserverTracer, PathTracer, RenderPlan,
    render as render_plan,
};

use crate::sensors::{PassShare, per_item_plan};
use crate::{DEFAULT_OBSERVER_SPP, RenderError, Scene, tracer_scene};

/// One quantity at an observer: its value and how well it is known.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ObservedLux {
    /// Illuminance (lux).
    pub lux: f64,
    /// Melanopic equivalent daylight illuminance (lux, CIE S 026) of the same receiver.
    pub melanopic_edi_lux: f64,
    /// Estimated relative standard error of `lux` (one sigma); `null` when no light arrived.
    pub relative_error: Option<f64>,
}

/// One luminaire in an observer's glare rating.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GlareTerm {
    /// The light's index in the scene's `lights`.
    pub light: usize,
    /// Its luminance towards the eye (cd/m^2).
    pub luminance_cd_m2: f64,
    /// The solid angle of its luminous opening seen from the eye (sr).
    pub solid_angle_sr: f64,
    /// Its Guth position index.
    pub position_index: f64,
}

/// One observer's figures in the sidecar.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ObserverReport {
    /// The observer's name.
    pub name: String,
    /// The eye (m).
    pub position: [f64; 3],
    /// The unit line of sight.
    pub view: [f64; 3],
    /// Horizontal illuminance at the eye (facing up).
    pub horizontal: ObservedLux,
    /// Vertical illuminance facing the line of sight's horizontal direction: its
    /// `melanopic_edi_lux` is the melanopic EDI at the eye (CIE S 026).
    pub vertical: ObservedLux,
    /// Cylindrical illuminance (EN 12464-1).
    pub cylindrical: ObservedLux,
    /// Semi-cylindrical illuminance facing the line of sight (EN 12464-1, CIE 136).
    pub semicylindrical: ObservedLux,
    /// Vertical illuminance without the point, spot and luminaire lights seen directly: the
    /// glare rating's background.
    pub vertical_indirect: ObservedLux,
    /// Melanopic daylight efficacy ratio at the eye: vertical m-EDI over vertical illuminance.
    pub melanopic_der: Option<f64>,
    /// Background luminance `L_b = vertical_indirect / pi` (cd/m^2).
    pub background_luminance_cd_m2: f64,
    /// The unified glare rating (CIE 117) for the line of sight; `null` when no luminaire
    /// with a luminous opening is in view, or the background is black.
    pub ugr: Option<f64>,
    /// The luminaires that make up the rating.
    pub glare_sources: Vec<GlareTerm>,
    /// Samples per quantity.
    pub samples: u64,
    /// Seconds the observer pass took (all observers).
    pub seconds: f64,
}

/// The Guth position index (CIE 117-1995) of a glare source at `source` seen from `eye` with
/// the unit line of sight `view` and the unit vertical `up`, from the widely used fit to Guth's
/// table (the form in, for example, Radiance's `evalglare`):
///
/// `p = exp[(35.2 - 0.31889 tau - 1.22 e^(-2 tau / 9)) 1e-3 sigma
///          + (21 + 0.26667 tau - 0.002963 tau^2) 1e-5 sigma^2]`
///
/// with `sigma` the angle (degrees) between the line of sight and the direction to the source,
/// and `tau` the angle (degrees) between the vertical and the plane through the line of sight
/// and the source. It reproduces Guth's table (1.00 on the line of sight, 2.86 at H/R = 0.5
/// and 7.0 at H/R = 1 straight above it). `None` for a source behind the eye's frontal plane
/// or below the horizontal plane through the line of sight.
pub fn guth_position_index(eye: DVec3, view: DVec3, up: DVec3, source: DVec3) -> Option<f64> {
    let d = source - eye;
    let r = d.dot(view);
    let above = (up - view * up.dot(view)).normalize_or_zero();
    let h = d.dot(above);
    if !(r > 0.0) || !(h >= -1e-9 * d.length()) || above == DVec3::ZERO {
        return None;
    }
    let h = h.max(0.0);
    let t = d.dot(view.cross(above)).abs();
    let sigma = (h.hypot(t)).atan2(r).to_degrees();
    let tau = if h == 0.0 && t == 0.0 { 0.0 } else { t.atan2(h).to_degrees() };
    let a = (35.2 - 0.31889 * tau - 1.22 * (-2.0 * tau / 9.0).exp()) * 1e-3 * sigma;
    let b = (21.0 + 0.26667 * tau - 0.002963 * tau * tau) * 1e-5 * sigma * sigma;
    let p = (a + b).exp();
    p.is_finite().then_some(p)
}

/// The unified glare rating of `terms` against the background luminance `background`
/// (cd/m^2): `8 log10(0.25 / L_b sum L^2 omega / p^2)`; `None` without terms or with a black
/// background.
pub fn unified_glare_rating(background: f64, terms: &[GlareTerm]) -> Option<f64> {
    let sum: f64 = terms
        .iter()
        .map(|g| g.luminance_cd_m2.powi(2) * g.solid_angle_sr / g.position_index.powi(2))
        .sum();
    let ugr = 8.0 * (0.25 / background * sum).log10();
    (sum > 0.0 && background > 0.0 && ugr.is_finite()).then_some(ugr)
}

/// The glare sources of `scene` for each of its observers: every light with a luminous opening
/// that the eye sees in front of it and at or above its line of sight.
pub(crate) fn glare_terms(scene: &Scene, effects: Effects) -> Vec<Vec<GlareTerm>> {
    let traced = tracer_scene(scene);
    let tracer = ObserverTracer::new(
        PathTracer::new(&traced, scene.path_settings(), effects),
        &scene.observers,
    );
    scene.observers.iter().map(|o| glare_terms_of(scene, &tracer, o)).collect()
}

/// [`glare_terms`] for one observer.
fn glare_terms_of(
    scene: &Scene,
    tracer: &ObserverTracer<'_>,
    observer: &Observer,
) -> Vec<GlareTerm> {
    let eye = observer.position();
    let mut terms = Vec::new();
    for (light, source) in scene.lights.lights().iter().enumerate() {
        let Some(view) = source.glare_view(eye) else { continue };
        let Some(p) = guth_position_index(eye, observer.view(), observer.up(), view.centre) else {
            continue;
        };
        if !tracer.sees(eye, light, view.centre) {
            continue;
        }
        terms.push(GlareTerm {
            light,
            luminance_cd_m2: view.luminance,
            solid_angle_sr: view.solid_angle,
            position_index: p,
        });
    }
    terms
}

/// The observer pass of `scene` (`settings.observer_spp` samples of every quantity of every
/// observer), on `shard`'s chunks of it (all of them for `None`).
///
/// # Errors
/// [`RenderError::Options`] if the pass's film cannot be made.
pub(crate) fn observer_pass(
    scene: &Scene,
    threads: usize,
    effects: Effects,
    shard: Option<(u64, u64)>,
) -> Result<PassShare, RenderError> {
    let started = Instant::now();
    let traced = tracer_scene(scene);
    let tracer = ObserverTracer::new(
        PathTracer::new(&traced, scene.path_settings(), effects),
        &scene.observers,
    );
    let receivers = (scene.observers.len() * OBSERVER_QUANTITIES.len()) as u64;
    let passes = scene.settings.observer_spp.unwrap_or(DEFAULT_OBSERVER_SPP);
    let plan = per_item_plan(passes, receivers, scene, threads);
    let mut output = render_plan(&tracer, &RenderPlan { shard, ..plan }, &|_| {})
        .map_err(|e| RenderError::Options(e.to_string()))?;
    output.seconds = started.elapsed().as_secs_f64();
    Ok(PassShare { plan: RenderPlan { threads: 0, ..plan }, output, items_per_sample: receivers })
}

/// Runs the observer pass of `scene` (nothing for a scene without observers) on `threads`
/// threads and returns every observer's figures.
///
/// # Errors
/// [`RenderError::Options`] if the pass's film cannot be made.
pub fn render_observers(
    scene: &Scene,
    threads: usize,
    effects: Effects,
) -> Result<Vec<ObserverReport>, RenderError> {
    if scene.observers.is_empty() {
        return Ok(Vec::new());
    }
    let pass = observer_pass(scene, threads, effects, None)?;
    let glare = glare_terms(scene, effects);
    Ok(observer_reports(&scene.observers, &pass, scene.lights.power(), &glare))
}

/// Every observer's figures from a whole observer pass (or the merged shares of one), the
/// lights' power and each observer's glare terms.
pub(crate) fn observer_reports(
    observers: &[Observer],
    pass: &PassShare,
    power: f64,
    glare: &[Vec<GlareTerm>],
) -> Vec<ObserverReport> {
    let n = pass.output.beams / pass.items_per_sample.max(1);
    let sums = pass.output.film.sensor_sums(1.0);
    let scale = if n > 0 { power / n as f64 } else { 0.0 };
    let per = OBSERVER_QUANTITIES.len();
    observers
        .iter()
        .enumerate()
        .map(|(index, observer)| {
            let quantity = |k: usize| {
                let c = sums.get(index * per + k).copied().unwrap_or_default();
                let variance = (c[2] - c[1] * c[1] / n.max(1) as f64).max(0.0);
                ObservedLux {
                    lux: c[1] * scale,
                    melanopic_edi_lux: c[3] * scale,
                    relative_error: (c[1] > 0.0).then(|| variance.sqrt() / c[1]),
                }
            };
            let [horizontal, vertical, cylindrical, semicylindrical, vertical_indirect] =
                [0, 1, 2, 3, 4].map(quantity);
            let background = vertical_indirect.lux / std::f64::consts::PI;
            let glare_sources = glare.get(index).cloned().unwrap_or_default();
            ObserverReport {
                name: observer.name().to_owned(),
                position: observer.position().to_array(),
                view: observer.view().to_array(),
                horizontal,
                vertical,
                cylindrical,
                semicylindrical,
                vertical_indirect,
                melanopic_der: (vertical.lux > 0.0)
                    .then(|| vertical.melanopic_edi_lux / vertical.lux),
                background_luminance_cd_m2: background,
                ugr: unified_glare_rating(background, &glare_sources),
                glare_sources,
                samples: n,
                seconds: pass.output.seconds,
            }
        })
        .collect()
}

/// An observer's figures in words, for the terminal.
pub fn observer_summary(r: &ObserverReport) -> String {
    let ugr = r.ugr.map_or("UGR none (no luminaire in view)".to_owned(), |u| format!("UGR {u:.1}"));
    format!(
        "observer {}: horizontal {:.1} lx, vertical {:.1} lx, cylindrical {:.1} lx, \
         semi-cylindrical {:.1} lx, melanopic EDI at the eye {:.1} lx, {ugr}",
        r.name,
        r.horizontal.lux,
        r.vertical.lux,
        r.cylindrical.lux,
        r.semicylindrical.lux,
        r.vertical.melanopic_edi_lux
    )
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn the_position_index_reproduces_guths_table() {
        let (eye, view, up) = (DVec3::ZERO, DVec3::NEG_Z, DVec3::Y);
        let p = |h: f64, t: f64| guth_position_index(eye, view, up, DVec3::new(t, h, -1.0));
        // Guth's table (CIE 117, T/R = 0): 1.00 at H/R 0, 2.86 at 0.5, 7.00 at 1.0.
        assert!((p(0.0, 0.0).unwrap() - 1.0).abs() < 1e-12);
        assert!((p(0.5, 0.0).unwrap() - 2.86).abs() < 0.01);
        assert!((p(1.0, 0.0).unwrap() - 7.00).abs() < 0.1);
        // Left and right are alike; below the line of sight or behind the eye: none.
        assert_eq!(p(0.5, 0.5), p(0.5, -0.5));
        assert!(p(0.5, 0.5).unwrap() > p(0.5, 0.0).unwrap());
        assert_eq!(p(-0.1, 0.0), None);
        assert_eq!(guth_position_index(eye, view, up, DVec3::new(0.0, 1.0, 1.0)), None);
    }

    #[test]
    fn the_glare_rating_follows_cie_117() {
        // One source of 10,000 cd/m^2 over 0.01 sr at p = 2 against 20 cd/m^2:
        // 8 log10(0.25 / 20 * 1e8 * 0.01 / 4) = 8 log10(3125) = 27.96.
        let term =
            GlareTerm { light: 0, luminance_cd_m2: 1e4, solid_angle_sr: 0.01, position_index: 2.0 };
        let ugr = unified_glare_rating(20.0, &[term]).unwrap();
        assert!((ugr - 8.0 * 3125f64.log10()).abs() < 1e-12 && (ugr - 27.96).abs() < 0.01);
        // Two equal sources add 8 log10 2 = 2.41.
        let two = unified_glare_rating(20.0, &[term, term]).unwrap();
        assert!((two - ugr - 8.0 * 2f64.log10()).abs() < 1e-12);
        assert_eq!(unified_glare_rating(0.0, &[term]), None);
        assert_eq!(unified_glare_rating(20.0, &[]), None);
    }
}
