//! What a render did: the JSON sidecar's contents ([`RenderReport`]) and its accuracy estimate.

use serde::{Deserialize, Serialize};
use spectrace_tracer::{
    Effects, Kernel, LightTracer, RenderOutput, RenderPlan, SamplerKind, TraceStats,
};

use crate::warnings::rejected_warning;
use crate::{SensorReport, Written};

/// What a render did: the JSON sidecar's contents.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RenderReport {
    /// The scene file.
    pub scene: String,
    /// Image size.
    pub width: u32,
    /// Image size.
    pub height: u32,
    /// The plan after overrides (beams, chunk size, seed, threads, shard, time budget).
    pub plan: RenderPlan,
    /// The effects analysis' decision.
    pub effects: Effects,
    /// The decision in words.
    pub effects_summary: String,
    /// The estimator that rendered the image
    /// ([`Integrator::name`](spectrace_tracer::Integrator::name)): `"light"`, `"path"` or
    /// `"bdpt"`.
    #[serde(default = "light_integrator")]
    pub integrator: String,
    /// Why that estimator: asked for, or the effects analysis' reason.
    #[serde(default)]
    pub integrator_reason: String,
    /// Where the random numbers came from: `"independent"` or `"sobol"` (`settings.sampler`
    /// resolved for the estimator; `auto` gives Sobol to the path tracer and BDPT).
    #[serde(default = "independent_sampler")]
    pub sampler: String,
    /// The kernel that traced the paths (`settings.kernel`, `--kernel`): `"batched"` or
    /// `"scalar"` (the light tracer and BDPT are scalar).
    #[serde(default = "scalar_kernel")]
    pub kernel: String,
    /// How next-event estimation chose lights (`settings.light_sampler` resolved): `"each"`,
    /// `"power"` or `"tree"`.
    #[serde(default = "each_light_sampler")]
    pub light_sampler: String,
    /// When BDPT rendered the image: how many wavelengths a sample carried and why
    /// (`settings.bdpt_wavelengths`): `"hero: ..."` (four) or `"beam: ..."` (one).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bdpt_wavelengths: Option<String>,
    /// Beams traced.
    pub beams: u64,
    /// Work chunks a time budget cut short, and for `path` and `bdpt` the pass that a
    /// `--beams` budget ends inside (passes whose first pixels, in the pass's order, got a
    /// sample the others did not: each pixel is normalised by its own count).
    #[serde(default)]
    pub chunks_cut: u64,
    /// Wall time (s).
    pub wall_seconds: f64,
    /// Beams per second.
    pub beams_per_second: f64,
    /// Contributions rejected by the film as non-finite or out of range (0 on every shipped
    /// scene).
    pub rejected_contributions: u64,
    /// The EXR holds the image multiplied by `2^exr_scale_log2`: 0 unless the image lies beyond
    /// the range of 32-bit floats (see [`encode_image`](crate::encode_image)).
    pub exr_scale_log2: i32,
    /// Channel values that would have overflowed to infinity (or underflowed to zero) in the
    /// EXR without that scale.
    pub out_of_range_values: u64,
    /// Anything the user should know about the result (also printed).
    pub warnings: Vec<String>,
    /// How accurate the image is, estimated from the spread between its chunks (absent when
    /// the image was too large to keep the estimate's moments).
    #[serde(default)]
    pub error_estimate: Option<AccuracyEstimate>,
    /// Tracer counters.
    pub stats: TraceStats,
    /// Total power of the lights (W).
    pub light_power: f64,
    /// Files written.
    pub outputs: Vec<String>,
    /// The illuminance sensors' figures (empty for a scene without sensors).
    #[serde(default)]
    pub sensors: Vec<SensorReport>,
    /// The observers' figures (empty for a scene without observers).
    #[serde(default)]
    pub observers: Vec<crate::ObserverReport>,
    /// Every light of the scene, in the order of the light set: its type, power and flux.
    #[serde(default)]
    pub lights: Vec<LightReport>,
    /// Spectrace version.
    pub version: String,
}

/// One light of a render, as the sidecar lists it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LightReport {
    /// The light's type, as scene files name it (`"IesLight"`, `"Environment"`, ...).
    #[serde(rename = "type")]
    pub kind: String,
    /// Radiant power (W); `null` beyond the range of `f64`.
    pub watts: Option<f64>,
    /// Luminous flux (lm): the power times its spectrum's luminous efficacy; `null` beyond the
    /// range of `f64`.
    pub lumens: Option<f64>,
    /// For a measured luminaire: its lamps (`lamp_count`, their rated flux `lamp_lumens`, `null`
    /// for absolute photometry), the flux of the file's table at its own scale
    /// (`file_lumens`), `light_output_ratio` (that over the lamps' flux) and, for EULUMDAT, the
    /// ratio the file states; absent for other lights.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub luminaire: Option<LuminaireReport>,
}

/// A measured luminaire's lamps and light output ratio, in the sidecar.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LuminaireReport {
    /// Flux of the file's candela table at its own scale (lm).
    pub file_lumens: f64,
    /// Number of lamps.
    pub lamp_count: u32,
    /// Rated flux of all the lamps (lm); `null` for absolute photometry.
    pub lamp_lumens: Option<f64>,
    /// `file_lumens / lamp_lumens`; `null` for absolute photometry.
    pub light_output_ratio: Option<f64>,
    /// The light output ratio the file states (EULUMDAT's LORL, as a fraction).
    pub stated_light_output_ratio: Option<f64>,
}

impl LightReport {
    /// The sidecar's entry for `light`.
    pub fn of(light: &dyn spectrace_lights::LightSource) -> Self {
        Self::with_efficacy(light, spectrace_spectrum::luminous_efficacy(light.spd().as_ref()))
    }

    /// The reports of all `lights`, each distinct spectrum object's efficacy computed once.
    pub fn all(lights: &[Box<dyn spectrace_lights::LightSource>]) -> Vec<Self> {
        let mut efficacy: std::collections::HashMap<*const (), f64> =
            std::collections::HashMap::new();
        lights
            .iter()
            .map(|l| {
                let spd = l.spd();
                let k = *efficacy
                    .entry(std::sync::Arc::as_ptr(&spd) as *const ())
                    .or_insert_with(|| spectrace_spectrum::luminous_efficacy(spd.as_ref()));
                Self::with_efficacy(l.as_ref(), k)
            })
            .collect()
    }

    /// The report of `light`, whose spectrum has the luminous `efficacy` (lm/W).
    fn with_efficacy(light: &dyn spectrace_lights::LightSource, efficacy: f64) -> Self {
        let watts = light.power();
        let lumens = watts * efficacy;
        let finite = |v: f64| v.is_finite().then_some(v);
        let luminaire = light.photometric_summary().map(|s| LuminaireReport {
            file_lumens: s.file_lumens,
            lamp_count: s.lamp_count,
            lamp_lumens: s.lamp_lumens,
            light_output_ratio: s.light_output_ratio,
            stated_light_output_ratio: s.stated_light_output_ratio,
        });
        Self {
            kind: light.typetag_name().to_owned(),
            watts: finite(watts),
            lumens: finite(lumens),
            luminaire,
        }
    }
}

/// The relative errors the sidecar predicts render times for (10%, 5%, 2%, 1%).
pub const PREDICTED_ERRORS: [f64; 4] = [0.10, 0.05, 0.02, 0.01];

/// How accurate a rendered image is and what more accuracy costs: the sidecar's
/// `error_estimate`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AccuracyEstimate {
    /// The measure of the headline, `relative_error`: `"relmse"` (the default), `"energy"` or
    /// `"mean"` (`settings.error_measure`, `--error-measure`).
    pub measure: String,
    /// Estimated relative error against the converged image in `measure`; `null` with fewer
    /// than two batches or a black image.
    pub relative_error: Option<f64>,
    /// The estimate in every measure: `relmse`, `energy` and `mean`.
    pub relative_error_by_measure: spectrace_tracer::ByMeasure,
    /// The `energy` estimate (relative RMSE over all pixels and X, Y, Z), as before the
    /// measures were named.
    pub relative_rmse: Option<f64>,
    /// One-sigma relative uncertainty of the headline estimate itself.
    pub relative_uncertainty: f64,
    /// The headline's one-sigma interval `[low, high]` (`relative_error` times
    /// `1 -/+ relative_uncertainty`); `null` without an estimate.
    pub interval: Option<[f64; 2]>,
    /// Independent batches (work chunks) it comes from.
    pub batches: u64,
    /// `true` with at least [`spectrace_tracer::MIN_BATCHES`] batches and a relative
    /// uncertainty below [`spectrace_tracer::MAX_TRUSTED_UNCERTAINTY`] (10%).
    pub trusted: bool,
    /// The target asked for (`--target-error`, `settings.target_error`), if any.
    pub target_error: Option<f64>,
    /// Whether the estimate reached the target (`null` without one).
    pub target_reached: Option<bool>,
    /// Predicted total render time (s, at this render's speed) to reach each relative error in
    /// [`PREDICTED_ERRORS`], with error falling as `1 / sqrt(work)`; `[error, seconds]` pairs,
    /// only for errors below the current one.
    pub predicted_seconds: Vec<[f64; 2]>,
    /// More render time (s) that would halve the error (three times this render's: four
    /// times the work).
    pub seconds_to_halve: f64,
    /// With a target the render did not reach (a time cap): the predicted total render time
    /// (s) to reach it; `null` otherwise.
    #[serde(default)]
    pub seconds_to_target: Option<f64>,
}

impl AccuracyEstimate {
    /// The sidecar's estimate of a render of `seconds` that ended with `estimate`.
    pub fn new(
        estimate: &spectrace_tracer::ErrorEstimate,
        target: Option<f64>,
        seconds: f64,
    ) -> Self {
        let e = estimate.relative_error;
        let predicted_seconds = match e {
            Some(e) if e > 0.0 => PREDICTED_ERRORS
                .iter()
                .filter(|&&t| t < e)
                .map(|&t| [t, seconds * (e / t).powi(2)])
                .collect(),
            _ => Vec::new(),
        };
        Self {
            measure: estimate.measure.name().to_owned(),
            relative_error: e,
            relative_error_by_measure: estimate.by_measure,
            relative_rmse: estimate.by_measure.energy,
            relative_uncertainty: estimate.relative_uncertainty(),
            interval: estimate.interval().map(|(lo, hi)| [lo, hi]),
            batches: estimate.batches,
            trusted: estimate.is_trusted(),
            target_error: target,
            target_reached: target.map(|t| e.is_some_and(|e| e <= t) && estimate.is_trusted()),
            predicted_seconds,
            seconds_to_halve: 3.0 * seconds,
            seconds_to_target: match (e, target) {
                (Some(e), Some(t)) if e > t && t > 0.0 => Some(seconds * (e / t).powi(2)),
                _ => None,
            },
        }
    }

    /// One line for the terminal: `estimated error (relmse) 3.2% ±0.1% (64 batches); 2%
    /// would take ~41 s in all`.
    pub fn summary(&self) -> String {
        let Some(e) = self.relative_error else {
            return format!(
                "estimated error: none ({} batches; an estimate needs 2 and a lit image)",
                self.batches
            );
        };
        let mut line = format!(
            "estimated error ({}) {:.2}% ±{:.2}% ({} batches{})",
            self.measure,
            e * 100.0,
            e * self.relative_uncertainty * 100.0,
            self.batches,
            if self.trusted { "" } else { ", not yet trusted" }
        );
        if let (Some(t), Some(reached)) = (self.target_error, self.target_reached) {
            line.push_str(&format!(
                "; target {:.2}% {}",
                t * 100.0,
                if reached { "reached" } else { "not reached" }
            ));
        }
        if let Some([t, s]) = self.predicted_seconds.first() {
            line.push_str(&format!("; {:.0}% would take ~{} in all", t * 100.0, duration(*s)));
        }
        line
    }
}

/// Seconds in words: `850 ms`, `12.3 s`, `4.1 min`, `2.5 h`.
pub fn duration(seconds: f64) -> String {
    if !seconds.is_finite() {
        "forever".to_owned()
    } else if seconds < 1.0 {
        format!("{:.0} ms", seconds * 1e3)
    } else if seconds < 120.0 {
        format!("{seconds:.1} s")
    } else if seconds < 7200.0 {
        format!("{:.1} min", seconds / 60.0)
    } else {
        format!("{:.1} h", seconds / 3600.0)
    }
}

/// The integrator of sidecars written before the field existed: the light tracer.
fn light_integrator() -> String {
    LightTracer::NAME.to_owned()
}

/// The kernel of sidecars written before the field existed: one path at a time.
fn scalar_kernel() -> String {
    Kernel::Scalar.name().to_owned()
}

/// The light sampler of reports written before `light_sampler` was recorded.
fn each_light_sampler() -> String {
    "each".to_owned()
}

/// The sampler of sidecars written before the field existed.
fn independent_sampler() -> String {
    SamplerKind::Independent.name().to_owned()
}

#[allow(clippy::too_many_arguments)]
pub(crate) fn report(
    scene: String,
    (width, height): (u32, u32),
    plan: RenderPlan,
    effects: Effects,
    integrator: &str,
    output: &RenderOutput,
    wall: f64,
    light_power: f64,
    written: Written,
) -> RenderReport {
    let mut warnings = written.warnings;
    if output.film.rejected() > 0 {
        warnings.push(rejected_warning(output.film.rejected()));
    }
    RenderReport {
        scene,
        width,
        height,
        plan,
        effects,
        effects_summary: effects.summary(),
        integrator: integrator.to_owned(),
        integrator_reason: String::new(),
        sampler: independent_sampler(),
        kernel: scalar_kernel(),
        light_sampler: each_light_sampler(),
        bdpt_wavelengths: None,
        beams: output.beams,
        chunks_cut: output.cut.len() as u64,
        wall_seconds: wall,
        beams_per_second: if wall > 0.0 { output.beams as f64 / wall } else { 0.0 },
        rejected_contributions: output.film.rejected(),
        error_estimate: output
            .estimate(plan.error_measure)
            .map(|e| AccuracyEstimate::new(&e, plan.target_error, output.seconds)),
        stats: output.stats,
        light_power,
        outputs: written.files,
        exr_scale_log2: written.exr_scale_log2,
        out_of_range_values: written.out_of_range_values,
        warnings,
        sensors: Vec::new(),
        observers: Vec::new(),
        lights: Vec::new(),
        version: env!("CARGO_PKG_VERSION").to_owned(),
    }
}
