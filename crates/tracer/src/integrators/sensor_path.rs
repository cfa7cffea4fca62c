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
/// `[radiant, luminous, luminous^2]`, so that the light tracer's normalisation (`P / N / area`,
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

    /// One sample of the cell `cell` (numbered over all sensors): `[radiant, luminous]`
    /// irradiance times the cell's area over the lights' power.
    fn sample_cell(&self, cell: u32, rng: &mut dyn rand::Rng, stats: &mut TraceStats) -> [f64; 2] {
        let scene = self.tracer.scene();
        let sensors = self.sensors.sensors();
        let Some(index) = (0..sensors.len()).rev().find(|&i| self.sensors.offset(i) <= cell) else {
            return [0.0; 2];
        };
        let sensor = &sensors[index];
        let local = cell - self.sensors.offset(index);
        let [nu, nv] = sensor.cells();
        let (iu, iv) = (local % nu, local / nu);
        let (a, b) = (uniform(rng), uniform(rng));
        let x = sensor.corner()
            + sensor.edge_u() * ((f64::from(iu) + a) / f64::from(nu))
            + sensor.edge_v() * ((f64::from(iv) + b) / f64::from(nv));
        let n = sensor.front();
        // Wavelengths from the lights' spectrum, stratified.
        let u = uniform(rng);
        let mut lambdas = [0.0; HERO];
        let mut weights = [0.0; HERO];
        for j in 0..HERO {
            let stratum = ((j as f64 + u) / HERO as f64).min(spectrace_sampling::ONE_MINUS_EPSILON);
            let lambda = self.spectrum.sample_lambda(stratum);
            let q = self.spectrum.value(lambda);
            lambdas[j] = lambda;
            weights[j] = if q > 0.0 { 1.0 / (HERO as f64 * q) } else { 0.0 };
        }
        let mut irradiance = [0.0; HERO];
        // Point and spot lights, exactly.
        for &id in scene.delta_lights() {
            let Some(s) = sample_light(scene, id, x, [0.5, 0.5]) else { continue };
            let cos = -s.direction.dot(n);
            if !(cos > 0.0) || !unoccluded(scene, End::Point(x), End::Light(id, s.position)) {
                continue;
            }
            let Some(spd) = scene.light_spd(id) else { continue };
            let e = s.intensity * cos / (s.distance * s.distance);
            for j in 0..HERO {
                irradiance[j] += e * spd.value(lambdas[j]);
            }
        }
        // Everything else along one cosine-weighted direction: E = pi L.
        let local_dir = spectrace_sampling::sample_cosine_hemisphere([uniform(rng), uniform(rng)]);
        let direction = spectrace_sampling::Frame::from_normal(n).to_world(local_dir).normalize();
        let ray = Ray { origin: x, direction };
        let radiance = self.tracer.radiance(ray, &lambdas, &mut weights, rng, stats);
        for j in 0..HERO {
            irradiance[j] += std::f64::consts::PI * radiance[j];
        }
        let scale = sensor.cell_area() / LightSource::power(scene.lights);
        let (mut radiant, mut luminous) = (0.0, 0.0);
        for j in 0..HERO {
            if weights[j] > 0.0 && irradiance[j] != 0.0 {
                radiant += irradiance[j] * weights[j];
                luminous +=
                    irradiance[j] * weights[j] * spectrace_spectrum::lumens_per_watt(lambdas[j]);
            }
        }
        [radiant * scale, luminous * scale]
    }
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
        let [radiant, luminous] = self.sample_cell(cell, rng, stats);
        if radiant != 0.0 || luminous != 0.0 {
            film.splat_sensor(cell, [radiant, luminous, luminous * luminous]);
        }
    }
}
