//! The sensors' and observers' share of a sharded render: what a part file carries for them,
//! how it is checked, and how the merge turns the parts' sums into the files and figures one
//! machine would write.
//!
//! Each receiver pass (the sensor pass after a camera integrator's image, the observer pass) is
//! a render plan of its own; a shard renders its chunks of that plan (`--shard K/N` picks the
//! same chunks of it as of the image's), and since a chunk's random numbers depend only on the
//! seed and the chunk's index, the merged sums are bit for bit the unsharded pass's. When the
//! light tracer renders the image, its own beams fill the sensors in the image film's cells, which
//! the parts carry and the merge adds like pixels. The glare terms of each observer (geometry
//! and the luminaires' files, no sampling) are computed by every shard and must agree.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use spectrace_tracer::{
    Effects, IrradianceSensor, OBSERVER_QUANTITIES, Observer, RenderOutput, SENSOR_SLOTS, SensorSet,
};

use crate::observers::{glare_terms, observer_pass, observer_reports};
use crate::sensors::{
    FILLED_BY_IMAGE, FILLED_BY_LIGHT_PASS, FILLED_BY_PATH_PASS, LitSensors, PassShare,
    SensorSource, fixed_sensor_pass, write_lit_sensors,
};
use crate::{GlareTerm, ObserverReport, RenderError, Scene, SensorReport};

/// A sensor as a part file stores it (the scene form is tagged by `type`, which the part's
/// binary encoding cannot read back).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SensorDefinition {
    /// `name`.
    pub name: String,
    /// `corner` (m).
    pub corner: [f64; 3],
    /// `edge_u` (m).
    pub edge_u: [f64; 3],
    /// `edge_v` (m).
    pub edge_v: [f64; 3],
    /// `cells`.
    pub cells: [u32; 2],
}

impl SensorDefinition {
    /// The stored form of `s`.
    fn of(s: &IrradianceSensor) -> Self {
        Self {
            name: s.name().to_owned(),
            corner: s.corner().to_array(),
            edge_u: s.edge_u().to_array(),
            edge_v: s.edge_v().to_array(),
            cells: s.cells(),
        }
    }

    /// The sensor, checked as a scene's would be.
    fn sensor(&self) -> Result<IrradianceSensor, String> {
        let v = glam::DVec3::from_array;
        IrradianceSensor::new(
            self.name.clone(),
            v(self.corner),
            v(self.edge_u),
            v(self.edge_v),
            self.cells,
        )
    }
}

/// The sensors' and observers' share of one shard.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct ReceiversPart {
    /// The scene's sensors.
    pub sensors: Vec<SensorDefinition>,
    /// `settings.sensor_floor_lux`.
    pub sensor_floor_lux: f64,
    /// How the sensors are filled: `"image beams (light tracer)"` (the image film's cells),
    /// `"sensor pass (light tracer)"` or `"points sampled on the sensor (path tracer)"`
    /// (`sensor_pass`); empty without sensors.
    pub sensor_filled_by: String,
    /// The shard's share of the sensor pass; `None` when the image's beams fill the sensors or
    /// there are none.
    pub sensor_pass: Option<PassShare>,
    /// The scene's observers.
    pub observers: Vec<Observer>,
    /// The shard's share of the observer pass; `None` without observers.
    pub observer_pass: Option<PassShare>,
    /// Each observer's glare terms.
    pub glare: Vec<Vec<GlareTerm>>,
}

/// Renders shard `shard`'s share of `scene`'s receiver passes; `image_fills_sensors` when the
/// image's estimator (the light tracer) filled the sensors in its own film.
///
/// # Errors
/// [`RenderError::Options`] if a pass's film cannot be made.
pub(crate) fn shard_receivers(
    scene: &Scene,
    image_fills_sensors: bool,
    threads: usize,
    effects: Effects,
    shard: (u64, u64),
) -> Result<ReceiversPart, RenderError> {
    let mut part = ReceiversPart {
        sensors: scene.sensors.sensors().iter().map(SensorDefinition::of).collect(),
        sensor_floor_lux: scene.settings.sensor_floor_lux,
        observers: scene.observers.clone(),
        ..ReceiversPart::default()
    };
    if !scene.sensors.is_empty() {
        if image_fills_sensors {
            part.sensor_filled_by = FILLED_BY_IMAGE.to_owned();
        } else {
            let (pass, filled_by) = fixed_sensor_pass(scene, threads, effects, Some(shard))?;
            part.sensor_filled_by = filled_by.to_owned();
            part.sensor_pass = Some(pass);
        }
    }
    if !scene.observers.is_empty() {
        part.observer_pass = Some(observer_pass(scene, threads, effects, Some(shard))?);
        part.glare = glare_terms(scene, effects);
    }
    Ok(part)
}

/// The error for `field` of a part's receivers.
fn bad<T>(field: &str, why: String) -> Result<T, String> {
    Err(format!("receivers.{field}: {why}"))
}

impl ReceiversPart {
    /// The sensor cells the image film must hold after its pixels.
    pub(crate) fn image_cells(&self) -> usize {
        if self.sensor_filled_by == FILLED_BY_IMAGE {
            let cells = self.sensors.iter().map(|s| u64::from(s.cells[0]) * u64::from(s.cells[1]));
            cells.sum::<u64>().try_into().unwrap_or(usize::MAX)
        } else {
            0
        }
    }

    /// The sensors, checked as a scene's are.
    fn sensor_set(&self) -> Result<SensorSet, String> {
        let sensors = self
            .sensors
            .iter()
            .enumerate()
            .map(|(i, d)| d.sensor().or_else(|e| bad(&format!("sensors[{i}]"), e)));
        SensorSet::new(sensors.collect::<Result<_, _>>()?).or_else(|e| bad("sensors", e))
    }

    /// Checks every field as a scene field would be checked.
    ///
    /// # Errors
    /// The first field no render could have written, named as `receivers.field`.
    pub(crate) fn validate(&self) -> Result<(), String> {
        let set = self.sensor_set()?;
        for (i, s) in self.sensors.iter().enumerate() {
            crate::files::check_output_name(&s.name)
                .or_else(|e| bad(&format!("sensors[{i}].name"), e))?;
        }
        if !(self.sensor_floor_lux >= 0.0 && self.sensor_floor_lux.is_finite()) {
            return bad(
                "sensor_floor_lux",
                format!("{}: must be finite, >= 0", self.sensor_floor_lux),
            );
        }
        let cells = u64::from(set.total_cells());
        let expected: &[&str] = if self.sensors.is_empty() {
            &[""]
        } else {
            &[FILLED_BY_IMAGE, FILLED_BY_LIGHT_PASS, FILLED_BY_PATH_PASS]
        };
        if !expected.contains(&self.sensor_filled_by.as_str()) {
            return bad(
                "sensor_filled_by",
                format!("{:?} is none of {expected:?}", self.sensor_filled_by),
            );
        }
        let per_sample = |light: bool| if light { 1 } else { cells };
        match (&self.sensor_pass, self.sensor_filled_by.as_str()) {
            (None, "" | FILLED_BY_IMAGE) => {}
            (Some(pass), kind @ (FILLED_BY_LIGHT_PASS | FILLED_BY_PATH_PASS)) => {
                let light = kind == FILLED_BY_LIGHT_PASS;
                validate_pass("sensor_pass", pass, cells, per_sample(light), !light)?;
            }
            _ => return bad("sensor_pass", "does not match sensor_filled_by".to_owned()),
        }
        spectrace_tracer::check_observers(&self.observers).or_else(|e| bad("observers", e))?;
        let receivers = (self.observers.len() * OBSERVER_QUANTITIES.len()) as u64;
        match &self.observer_pass {
            None if self.observers.is_empty() => {}
            Some(pass) if !self.observers.is_empty() => {
                validate_pass("observer_pass", pass, receivers, receivers, true)?;
            }
            _ => return bad("observer_pass", "does not match the observers".to_owned()),
        }
        let want = if self.observers.is_empty() { 0 } else { self.observers.len() };
        if self.glare.len() != want {
            return bad("glare", format!("{} lists for {want} observers", self.glare.len()));
        }
        let finite = |g: &GlareTerm| {
            g.luminance_cd_m2 >= 0.0
                && g.luminance_cd_m2.is_finite()
                && g.solid_angle_sr > 0.0
                && g.solid_angle_sr.is_finite()
                && g.position_index >= 1.0
                && g.position_index.is_finite()
        };
        if self.glare.iter().flatten().any(|g| !finite(g)) {
            return bad("glare", "a term is negative, zero or not finite".to_owned());
        }
        Ok(())
    }
}

/// A receiver pass's share: its plan, a film holding `cells` receivers after a one-pixel image
/// (`one_pixel`; a light-tracer pass's film has the camera's size), `per_sample` items per
/// independent sample, and chunks as the image's are checked.
fn validate_pass(
    field: &str,
    pass: &PassShare,
    cells: u64,
    per_sample: u64,
    one_pixel: bool,
) -> Result<(), String> {
    crate::part::validate_plan(&pass.plan).or_else(|e| bad(field, e))?;
    if pass.plan.time_budget.is_some()
        || pass.plan.target_error.is_some()
        || pass.plan.error_estimate
    {
        return bad(field, "a receiver pass has no time budget, target or estimate".to_owned());
    }
    if pass.items_per_sample != per_sample || (per_sample > 1 && pass.plan.chunk_beams != cells) {
        return bad(
            &format!("{field}.items_per_sample"),
            format!(
                "{} (chunks of {}) for {cells} receivers",
                pass.items_per_sample, pass.plan.chunk_beams
            ),
        );
    }
    let out = &pass.output;
    let film = &out.film;
    let size = (film.width(), film.height());
    if (one_pixel && size != (1, 1)) || film.has_pass_layer() || out.moments.is_some() {
        return bad(
            &format!("{field}.output.film"),
            format!("a {}x{} film, or layers a receiver pass does not keep", size.0, size.1),
        );
    }
    film.check_sums().or_else(|e| bad(&format!("{field}.output.film"), e))?;
    let sums = film.sums_after_pixels() as u64;
    if sums != SENSOR_SLOTS as u64 * cells {
        return bad(
            &format!("{field}.output.film"),
            format!("holds {sums} receiver sums for {cells} receivers of {SENSOR_SLOTS} each"),
        );
    }
    crate::part::validate_chunks(&pass.plan, out).or_else(|e| bad(field, e))
}

/// The receivers of the parts being merged: the first part's definitions, and the passes'
/// shares added up.
#[derive(Debug)]
pub(crate) struct MergedReceivers {
    first: ReceiversPart,
    /// Which part holds each chunk of the sensor and the observer pass.
    owners: [BTreeMap<u64, usize>; 2],
}

impl MergedReceivers {
    /// Starts from the first part's receivers.
    pub(crate) fn new(first: ReceiversPart) -> Self {
        let owners = [&first.sensor_pass, &first.observer_pass]
            .map(|p| p.iter().flat_map(|p| p.output.chunks.iter().map(|&c| (c, 0))).collect());
        Self { first, owners }
    }

    /// Whether `part` describes the same receivers (definitions, passes' plans, glare).
    pub(crate) fn same_kind(&self, part: &ReceiversPart) -> bool {
        let plans = |r: &ReceiversPart| {
            [&r.sensor_pass, &r.observer_pass]
                .map(|p| p.as_ref().map(|p| (p.plan, p.items_per_sample)))
        };
        let a = &self.first;
        a.sensors == part.sensors
            && a.sensor_floor_lux.to_bits() == part.sensor_floor_lux.to_bits()
            && a.sensor_filled_by == part.sensor_filled_by
            && a.observers == part.observers
            && a.glare == part.glare
            && plans(a) == plans(part)
    }

    /// Adds part `index`'s passes (at `paths[index]`).
    ///
    /// # Errors
    /// A chunk another part holds, or sums that overflow.
    pub(crate) fn add(
        &mut self,
        part: &ReceiversPart,
        index: usize,
        paths: &[PathBuf],
    ) -> Result<(), RenderError> {
        let mine = [&mut self.first.sensor_pass, &mut self.first.observer_pass];
        let theirs = [&part.sensor_pass, &part.observer_pass];
        for ((mine, theirs), owner) in mine.into_iter().zip(theirs).zip(&mut self.owners) {
            let (Some(mine), Some(theirs)) = (mine, theirs) else { continue };
            for &c in &theirs.output.chunks {
                if let Some(&other) = owner.get(&c) {
                    return Err(RenderError::Options(format!(
                        "{}: receiver chunk {c} is also in {} (the same shard twice?)",
                        paths[index].display(),
                        paths[other].display()
                    )));
                }
                owner.insert(c, index);
            }
            add_output(&mut mine.output, &theirs.output, &paths[index])?;
        }
        Ok(())
    }

    /// Checks that the parts cover every chunk of each pass.
    ///
    /// # Errors
    /// The pass and the chunks missing.
    pub(crate) fn check_coverage(&self) -> Result<(), RenderError> {
        let passes = [&self.first.sensor_pass, &self.first.observer_pass];
        for (pass, owner) in passes.into_iter().zip(&self.owners) {
            if let Some(pass) = pass {
                crate::shard::check_coverage(&pass.plan, owner)?;
            }
        }
        Ok(())
    }

    /// The output files the merged sensors will write into `dir`.
    pub(crate) fn planned_files(&self, dir: &Path) -> Vec<PathBuf> {
        self.first
            .sensors
            .iter()
            .flat_map(|s| ["csv", "exr", "png"].map(|e| dir.join(format!("{}.{e}", s.name))))
            .collect()
    }

    /// Writes the sensors' files and returns the sensors' and the observers' figures, from the
    /// merged passes (and, for image beams, the merged image `image`).
    ///
    /// # Errors
    /// [`RenderError::File`] when a sensor file cannot be written or would replace a part.
    pub(crate) fn finish(
        &self,
        dir: &Path,
        image: &RenderOutput,
        light_power: f64,
        parts: &[PathBuf],
    ) -> Result<(Vec<SensorReport>, Vec<ObserverReport>), RenderError> {
        let r = &self.first;
        let mut sensors = Vec::new();
        if !r.sensors.is_empty() {
            let set = r.sensor_set().map_err(RenderError::Options)?;
            let lit = LitSensors {
                sensors: &set,
                light_power,
                floor_lux: r.sensor_floor_lux,
                inputs: parts,
            };
            let (film, beams, seconds) = match &r.sensor_pass {
                Some(p) => {
                    (&p.output.film, p.output.beams / p.items_per_sample.max(1), p.output.seconds)
                }
                None => (&image.film, image.beams, image.seconds),
            };
            let source =
                SensorSource { film, beams, seconds, filled_by: &r.sensor_filled_by, target: None };
            sensors = write_lit_sensors(&lit, dir, source)?;
        }
        let observers = match &r.observer_pass {
            Some(pass) => observer_reports(&r.observers, pass, light_power, &r.glare),
            None => Vec::new(),
        };
        Ok((sensors, observers))
    }
}

/// Adds `part` to `merged` (a receiver pass's outputs), checking the counters cannot overflow.
fn add_output(
    merged: &mut RenderOutput,
    part: &RenderOutput,
    path: &Path,
) -> Result<(), RenderError> {
    let overflow = merged.beams.checked_add(part.beams).is_none()
        || merged.stats.beams.checked_add(part.stats.beams).is_none()
        || merged.film.accepted().checked_add(part.film.accepted()).is_none()
        || merged.film.rejected().checked_add(part.film.rejected()).is_none();
    if overflow {
        return Err(RenderError::Options(format!(
            "{}: adding its receiver passes to the other parts' overflows: not parts of one render",
            path.display()
        )));
    }
    let seconds = merged.seconds + part.seconds;
    merged.merge(part).map_err(|e| RenderError::Options(format!("{}: {e}", path.display())))?;
    // A pass's time is the shards' sum (its figures predict one machine's time).
    merged.seconds = seconds;
    Ok(())
}
