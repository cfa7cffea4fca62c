//! [`ObserverTracer`]: the light observers receive at their eyes, estimated with the path
//! tracer's radiance as the sensor pass estimates illuminance on sensor cells.

use spectrace_lights::LightSource;

use super::common::{End, unoccluded};
use super::pass::PassEstimator;
use super::sensor_path::gather;
use crate::{ChunkSampler, LightTracerScene, Observer, PathTracer, Splat, TraceStats};

/// The path tracer estimating what observers receive (no image): a work item is one sample of
/// one receiver of one observer (observer `i`'s receiver `k` is item and film cell `5 i + k`, in
/// the order of [`crate::OBSERVER_QUANTITIES`]), a chunk one pass over all of them.
///
/// # Estimator
/// Each sample is the sensor pass's (`gather`): point and spot lights exactly, everything
/// else along one direction drawn in proportion to the receiver's response. The film keeps
/// `E / P` per sample in the cell's [`crate::SensorSums`] (`P` the lights' power), so that
/// `P / N` times the sums (with `N` the passes) gives the mean, as for a sensor cell of area 1.
#[derive(Debug, Clone)]
pub struct ObserverTracer<'a> {
    tracer: PathTracer<'a>,
    observers: &'a [Observer],
    spectrum: std::sync::Arc<dyn spectrace_spectrum::SpectralPowerDistribution>,
}

impl<'a> ObserverTracer<'a> {
    /// Its [`crate::Integrator::name`].
    pub const NAME: &'static str = "path (observers)";

    /// The path tracer `tracer`, estimating `observers`.
    pub fn new(tracer: PathTracer<'a>, observers: &'a [Observer]) -> Self {
        let spectrum = LightSource::spd(tracer.scene().lights);
        Self { tracer, observers, spectrum }
    }

    /// Whether nothing blocks the segment from `eye` to the point `at` of light `light` (its
    /// index in the scene's lights; its own surface, if it has one, is skipped).
    pub fn sees(&self, eye: glam::DVec3, light: usize, at: glam::DVec3) -> bool {
        let id = spectrace_lights::LightId(light as u32);
        unoccluded(self.tracer.scene(), End::Point(eye), End::Light(id, at))
    }
}

/// Receivers per observer.
const RECEIVERS: u64 = crate::OBSERVER_QUANTITIES.len() as u64;

impl PassEstimator for ObserverTracer<'_> {
    const NAME: &'static str = ObserverTracer::NAME;
    type Scratch = ();

    fn scene(&self) -> &LightTracerScene<'_> {
        self.tracer.scene()
    }

    /// Items are the receivers of every observer.
    fn items(&self) -> u64 {
        self.observers.len() as u64 * RECEIVERS
    }

    /// No image: a film of one pixel, which stays black.
    fn film_size(&self) -> (u32, u32) {
        (1, 1)
    }

    fn cells(&self) -> u32 {
        self.items() as u32
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
        let Some(observer) = self.observers.get((item / RECEIVERS) as usize) else { return };
        let response = observer.responses()[(item % RECEIVERS) as usize];
        let [radiant, luminous, melanopic] =
            gather(&self.tracer, &*self.spectrum, observer.position(), (response, 1.0), rng, stats);
        if radiant != 0.0 || luminous != 0.0 || melanopic != 0.0 {
            film.splat_sensor(item as u32, [radiant, luminous, luminous * luminous, melanopic]);
        }
    }
}
