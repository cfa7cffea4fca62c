//! Illuminance sensors estimated from points sampled on them: [`SensorPathTracer`], the path
//! tracer's radiance estimate gathered over the sensors' cells instead of the image.

use spectrace_geometry::Ray;
use spectrace_lights::{LightSource, uniform};

use super::common::{End, sample_light, unoccluded};
use super::pass::PassEstimator;
use crate::{ChunkSampler, HERO, LightTracerScene, PathTracer, Splat, TraceStats};

/// The path tracer estimating the scene's illuminance sensors by sampling points on them (no
/// image): a work item is one sample of one sensor cell, a chunk one pass over every cell of
/// every sensor.
///
/// # Estimator
/// At a point `x` drawn uniformly in the cell, with the sensor's front normal `n`, the
/// irradiance is `E = integral of L_i(x, w) (w . n) dw` over the front hemisphere. Point and
/// spot lights (which no ray can hit) add exactly `I(w) cos / d^2` when visible; everything else
/// arrives along one cosine-weighted direction, `E = pi L` in expectation, with `L` the path
/// tracer's radiance estimate along that ray (emitters it hits count fully, since nothing else
/// samples them at `x`). Wavelengths are drawn from the lights' own spectrum, [`HERO`] of them
/// stratified, each weighted by one over its density, so the radiant and the luminous sums are
/// both unbiased over the lights' whole range. The sensor blocks nothing: rays start at `x`.
/// The film keeps `E x cell area / P` per sample (`P` the lights' power) in the cell's
/// [`crate::SensorSums`], so that the light tracer's normalisation (`P / N / area`,
/// with `N` the passes) gives the mean irradiance.
#[derive(Debug, Clone)]
pub struct SensorPathTracer<'a> {
    tracer: PathTracer<'a>,
    sensors: &'a crate::SensorSet,
    /// The lights' spectrum, which the wavelengths are drawn from.
    spectrum: std::sync::Arc<dyn spectrace_spectrum::SpectralPowerDistribution>,
}

impl<'a> SensorPathTracer<'a> {
    /// Its [`crate::Integrator::name`].
    pub const NAME: &'static str = "path (sensors)";

    /// The path tracer `tracer`, estimating `sensors`.
    pub fn new(tracer: PathTracer<'a>, sensors: &'a crate::SensorSet) -> Self {
        let spectrum = LightSource::spd(tracer.scene().lights);
        Self { tracer, sensors, spectrum }
    }

    /// One sample of the cell `cell` (numbered over all sensors): `[radiant, luminous,
    /// melanopic]` irradiance times the cell's area over the lights' power.
    fn sample_cell(&self, cell: u32, rng: &mut dyn rand::Rng, stats: &mut TraceStats) -> [f64; 3] {
        let sensors = self.sensors.sensors();
        let Some(index) = (0..sensors.len()).rev().find(|&i| self.sensors.offset(i) <= cell) else {
            return [0.0; 3];
        };
        let sensor = &sensors[index];
        let local = cell - self.sensors.offset(index);
        let [nu, nv] = sensor.cells();
        let (iu, iv) = (local % nu, local / nu);
        let (a, b) = (uniform(rng), uniform(rng));
        let x = sensor.corner()
            + sensor.edge_u() * ((f64::from(iu) + a) / f64::from(nu))
            + sensor.edge_v() * ((f64::from(iv) + b) / f64::from(nv));
        let receiver = (Response::Planar(sensor.front()), sensor.cell_area());
        gather(&self.tracer, &*self.spectrum, x, receiver, rng, stats)
    }
}

/// How a receiver at a point weighs light by the direction it arrives from: its irradiance is
/// `integral of L_i(w) r(w) dw` over the sphere of directions `w` the light travels along
/// (pointing *into* the receiver), and every response here integrates to `pi` over a uniform
/// sphere of radiance 1 (`E = pi L`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Response {
    /// A plane with the unit front normal `n`: `r = max(0, -w . n)` (horizontal illuminance for
    /// `n` up, vertical illuminance for a horizontal `n`).
    Planar(glam::DVec3),
    /// A plane as [`Response::Planar`], counting everything but the point and spot lights seen
    /// directly: the indirect (and area-light) part, the background of a glare rating.
    PlanarExceptDeltaLights(glam::DVec3),
    /// A small cylinder with the unit vertical axis `up` (cylindrical illuminance, EN 12464-1):
    /// the flux on its curved surface over that surface's area, `r = sin theta / pi` with
    /// `theta` the angle between `-w` and `up`.
    Cylindrical(glam::DVec3),
    /// The curved half of such a cylinder facing the horizontal unit direction `facing`
    /// (semi-cylindrical illuminance, EN 12464-1 / CIE 136): `r = sin theta (1 + cos phi) / pi`
    /// with `phi` the horizontal angle between `-w` and `facing`.
    SemiCylindrical {
        /// The cylinder's vertical axis.
        up: glam::DVec3,
        /// The horizontal direction its curved half faces.
        facing: glam::DVec3,
    },
}

impl Response {
    /// The response `r` to light arriving from the unit direction `from` (pointing from the
    /// receiver towards where the light comes from, `-w`).
    pub fn weight(self, from: glam::DVec3) -> f64 {
        use std::f64::consts::PI;
        match self {
            Response::Planar(n) | Response::PlanarExceptDeltaLights(n) => from.dot(n).max(0.0),
            Response::Cylindrical(up) => horizontal(from, up).length() / PI,
            Response::SemiCylindrical { up, facing } => {
                let h = horizontal(from, up);
                let (sin_theta, along) = (h.length(), h.dot(facing));
                // sin theta (1 + cos phi) = sin theta + (horizontal part . facing).
                (sin_theta + along).max(0.0) / PI
            }
        }
    }

    /// A direction towards the light (`-w`) drawn with density `r(w) / pi` (two uniforms from
    /// `rng` for a plane, three for a cylinder), and the estimator's factor `r / pdf` (`pi`
    /// where the density is exact).
    fn sample(self, rng: &mut dyn rand::Rng) -> (glam::DVec3, f64) {
        use spectrace_sampling::{Frame, sample_cosine_hemisphere};
        use std::f64::consts::PI;
        let u = [uniform(rng), uniform(rng)];
        let lobe = |axis: glam::DVec3| {
            Frame::from_normal(axis).to_world(sample_cosine_hemisphere(u)).normalize()
        };
        match self {
            Response::Planar(n) | Response::PlanarExceptDeltaLights(n) => (lobe(n), PI),
            // A cylinder's response is the mean of vertical planes' over the horizontal
            // directions: a uniform azimuth, then a cosine lobe about it, has density
            // sin theta / pi^2 exactly.
            Response::Cylindrical(up) | Response::SemiCylindrical { up, .. } => {
                let frame = Frame::from_normal(up);
                let psi = 2.0 * PI * uniform(rng);
                let axis = frame.to_world(glam::DVec3::new(psi.cos(), psi.sin(), 0.0)).normalize();
                let from = lobe(axis);
                let pdf = horizontal(from, up).length() / (PI * PI);
                let factor = if pdf > 0.0 { self.weight(from) / pdf } else { 0.0 };
                (from, factor)
            }
        }
    }

    /// Whether point and spot lights seen directly count.
    fn counts_delta_lights(self) -> bool {
        !matches!(self, Response::PlanarExceptDeltaLights(_))
    }
}

/// The part of the unit `v` perpendicular to the unit `up`.
fn horizontal(v: glam::DVec3, up: glam::DVec3) -> glam::DVec3 {
    v - up * v.dot(up)
}

/// One sample of the irradiance at `x` with the response `response`, times `area` over the
/// lights' power `P`: `[radiant, luminous, melanopic]` (W/m^2, lux, melanopic EDI lux).
///
/// Point and spot lights (which no ray can hit) add exactly `I(w) r(w) / d^2` when visible;
/// everything else arrives along one direction drawn with density `r / pi` (see
/// [`Response::sample`]), `E = pi L` in expectation, with `L` the path tracer's radiance
/// estimate along that ray (emitters it hits count fully, since nothing else samples them at
/// `x`). Wavelengths are drawn from the lights' own spectrum, [`HERO`] of them stratified, each
/// weighted by one over its density, so every sum is unbiased over the lights' whole range.
pub(crate) fn gather(
    tracer: &PathTracer<'_>,
    spectrum: &dyn spectrace_spectrum::SpectralPowerDistribution,
    x: glam::DVec3,
    (response, area): (Response, f64),
    rng: &mut dyn rand::Rng,
    stats: &mut TraceStats,
) -> [f64; 3] {
    let scene = tracer.scene();
    let u = uniform(rng);
    let mut lambdas = [0.0; HERO];
    let mut weights = [0.0; HERO];
    for j in 0..HERO {
        let stratum = ((j as f64 + u) / HERO as f64).min(spectrace_sampling::ONE_MINUS_EPSILON);
        let lambda = spectrum.sample_lambda(stratum);
        let q = spectrum.value(lambda);
        lambdas[j] = lambda;
        weights[j] = if q > 0.0 { 1.0 / (HERO as f64 * q) } else { 0.0 };
    }
    let mut irradiance = [0.0; HERO];
    if response.counts_delta_lights() {
        let mut add = |choice: crate::LightChoice| {
            let id = choice.id;
            let Some(s) = sample_light(scene, id, x, [0.5, 0.5]).filter(|s| s.delta) else {
                return;
            };
            let r = response.weight(-s.direction);
            if !(r > 0.0) || !unoccluded(scene, End::Point(x), End::Light(id, s.position)) {
                return;
            }
            let Some(spd) = scene.light_spd(id) else { return };
            let e = s.intensity * r / (s.distance * s.distance * choice.pmf);
            for j in 0..HERO {
                irradiance[j] += e * spd.value(lambdas[j]);
            }
        };
        // Every delta light under `each`; otherwise one light chosen as next-event estimation
        // chooses it (an area light chosen here adds nothing: the sampled direction finds it).
        match scene.next_event() {
            crate::NextEventLights::Each { delta, .. } => {
                for &id in delta {
                    add(crate::LightChoice { id, pmf: 1.0, u: [0.5; 2] });
                }
            }
            chooser => chooser.for_each((x, glam::DVec3::ZERO), [uniform(rng), 0.5], &mut add),
        }
    }
    let (direction, factor) = response.sample(rng);
    if factor > 0.0 {
        let ray = Ray { origin: x, direction };
        let radiance = tracer.radiance(ray, &lambdas, &mut weights, rng, stats);
        for j in 0..HERO {
            irradiance[j] += factor * radiance[j];
        }
    }
    let scale = area / LightSource::power(scene.lights);
    let mut sums = [0.0; 3];
    for j in 0..HERO {
        if weights[j] > 0.0 && irradiance[j] != 0.0 {
            let e = irradiance[j] * weights[j];
            sums[0] += e;
            sums[1] += e * spectrace_spectrum::lumens_per_watt(lambdas[j]);
            sums[2] += e * spectrace_spectrum::melanopic_edi_per_watt(lambdas[j]);
        }
    }
    sums.map(|v| v * scale)
}

impl PassEstimator for SensorPathTracer<'_> {
    const NAME: &'static str = SensorPathTracer::NAME;
    type Scratch = ();

    fn scene(&self) -> &LightTracerScene<'_> {
        self.tracer.scene()
    }

    /// Items are the cells of every sensor.
    fn items(&self) -> u64 {
        u64::from(self.sensors.total_cells())
    }

    /// No image: a film of one pixel, which stays black.
    fn film_size(&self) -> (u32, u32) {
        (1, 1)
    }

    fn cells(&self) -> u32 {
        self.sensors.total_cells()
    }

    fn scratch(&self) {}

    fn sample(
        &self,
        item: u64,
        _: &mut (),
        rng: &mut ChunkSampler,
        film: &mut dyn Splat,
        stats: &mut TraceStats,
    ) {
        let cell = item as u32;
        let [radiant, luminous, melanopic] = self.sample_cell(cell, rng, stats);
        if radiant != 0.0 || luminous != 0.0 || melanopic != 0.0 {
            film.splat_sensor(cell, [radiant, luminous, luminous * luminous, melanopic]);
        }
    }
}
