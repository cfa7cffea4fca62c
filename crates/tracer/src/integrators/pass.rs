//! The camera estimators' unit of work, written once: a *pass*, one sample of every item (the
//! pixels of the image, or the cells of the sensors), each item a path of its own.
//!
//! Item `i` of pass `c` is `(i + pass_start(c)) mod items`: whole passes cover every item once,
//! and the one-item chunks of the pre-render probe spread over the image. Each item starts its
//! own path with a sampler of its own ([`ChunkSampler::for_path`]: the stream of `(seed, c, i)`;
//! Sobol: point `c` of the item's own sequence), so its result does not depend on the items
//! traced before it or beside it. A pass is never cut short, so every pixel has the same sample
//! count and the image is their plain mean: `image = film x power x items / samples`
//! ([`camera_image_scale`]).

use crate::{ChunkSampler, ChunkWork, Integrator, LightTracerScene, Splat, TraceStats};

/// A camera estimator, whose chunk is a pass over its items: it says how to sample one item,
/// and the [`Integrator`] around it (the pass loop, the resolution, the normalisation) is
/// written once, here.
pub(crate) trait PassEstimator: Send + Sync {
    /// [`Integrator::name`].
    const NAME: &'static str;
    /// Scratch storage reused by every sample of a chunk.
    type Scratch;

    /// The scene it renders.
    fn scene(&self) -> &LightTracerScene<'_>;

    /// Items of one pass: the pixels of the image (or the cells of the sensors).
    fn items(&self) -> u64 {
        let camera = self.scene().camera;
        u64::from(camera.width()) * u64::from(camera.height())
    }

    /// The film's size: the camera's resolution.
    fn film_size(&self) -> (u32, u32) {
        (self.scene().camera.width(), self.scene().camera.height())
    }

    /// Sensor cells it fills after the film's pixels (none by default).
    fn cells(&self) -> u32 {
        0
    }

    /// Fresh scratch storage for a chunk.
    fn scratch(&self) -> Self::Scratch;

    /// Work done once before a whole pass (not before the probe's one-item chunks), drawing
    /// from the chunk's stream outside any path.
    fn start_pass(&self, _rng: &mut ChunkSampler, _film: &mut dyn Splat, _stats: &mut TraceStats) {}

    /// Renders the `work.items` items of pass `work.chunk` into `film` (counted in
    /// `stats.beams`): by default the scalar kernel, [`Self::sample`] for one item after the
    /// other, each with its own sampler.
    fn render_items(&self, work: ChunkWork, film: &mut dyn Splat) -> TraceStats {
        scalar_items(self, work, film)
    }

    /// One sample of item `item`, drawing from `rng`, the path's own sampler.
    fn sample(
        &self,
        item: u64,
        scratch: &mut Self::Scratch,
        rng: &mut ChunkSampler,
        film: &mut dyn Splat,
        stats: &mut TraceStats,
    );
}

impl<E: PassEstimator> Integrator for E {
    fn name(&self) -> &'static str {
        E::NAME
    }

    fn resolution(&self) -> (u32, u32) {
        self.film_size()
    }

    /// One pass (see the module docs). The deadline is not looked at: a pass is never cut.
    fn render_chunk(&self, work: ChunkWork, film: &mut dyn Splat) -> TraceStats {
        let kind = self.scene().sampler().resolve(true);
        let mut rng = ChunkSampler::new(kind, work.seed, work.chunk);
        let items = self.items();
        let mut before = TraceStats::default();
        if work.items >= items.max(1) {
            self.start_pass(&mut rng, film, &mut before);
        }
        let mut stats = self.render_items(work, film);
        stats.merge(&before);
        stats
    }

    /// The lights' power times the items over the samples: the film holds each sample's
    /// estimate divided by the lights' total power (so that lights of any power keep the exact
    /// film in range), and the image is the mean per item.
    fn image_scale(&self, samples_done: u64) -> f64 {
        let power = spectrace_lights::LightSource::power(self.scene().lights);
        camera_image_scale(power, self.items(), samples_done)
    }

    fn sensor_cells(&self) -> u32 {
        self.cells()
    }
}

/// The item a pass starts at: the chunk index scrambled (a Fibonacci hash), so that passes of
/// one sample spread over the image.
pub(crate) fn pass_start(chunk: u64, items: u64) -> u64 {
    chunk.wrapping_mul(0x9E37_79B9_7F4A_7C15).rotate_left(32) % items.max(1)
}

/// The pixel `(x, y)` of image item `item` (row-major) of an image `width` pixels wide.
#[inline]
pub(crate) fn pixel_of(item: u64, width: u64) -> (u32, u32) {
    let width = width.max(1);
    ((item % width) as u32, (item / width) as u32)
}

/// The image scale of a camera estimator: the lights' `power` times the `items` over the
/// samples done (its film holds estimates relative to the lights' power, one per item sample).
pub(crate) fn camera_image_scale(power: f64, items: u64, samples_done: u64) -> f64 {
    if samples_done == 0 { 0.0 } else { power * items as f64 / samples_done as f64 }
}

/// The scalar kernel of a pass: [`PassEstimator::sample`] for one item after the other, each
/// with its own sampler ([`ChunkSampler::for_path`]); counts them in `stats.beams`.
pub(crate) fn scalar_items<E: PassEstimator + ?Sized>(
    estimator: &E,
    work: ChunkWork,
    film: &mut dyn Splat,
) -> TraceStats {
    let mut scratch = estimator.scratch();
    let kind = estimator.scene().sampler();
    run_pass(work.chunk, work.items, estimator.items(), |item, stats| {
        let mut rng = ChunkSampler::for_path(kind, work.seed, work.chunk, item);
        estimator.sample(item, &mut scratch, &mut rng, film, stats);
    })
}

/// The items of a chunk: `samples` items of pass `chunk` over `items` items, in order.
pub(crate) fn pass_items(chunk: u64, samples: u64, items: u64) -> impl Iterator<Item = u64> {
    let items = items.max(1);
    let start = pass_start(chunk, items);
    (0..samples).map(move |i| (i + start) % items)
}

/// Runs `samples` items of pass `chunk` over `items` items: `sample(item, stats)` for each;
/// counts the items in `stats.beams`.
pub(crate) fn run_pass(
    chunk: u64,
    samples: u64,
    items: u64,
    mut sample: impl FnMut(u64, &mut TraceStats),
) -> TraceStats {
    let mut stats = TraceStats::default();
    for item in pass_items(chunk, samples, items) {
        sample(item, &mut stats);
        stats.beams += 1;
    }
    stats
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_whole_pass_visits_every_item_once_from_a_scrambled_start() {
        for chunk in [0, 1, 7, 1000] {
            let mut seen = [0u32; 37];
            let stats = run_pass(chunk, 37, 37, |item, _| {
                seen[item as usize] += 1;
            });
            assert!(seen.iter().all(|&n| n == 1), "chunk {chunk}");
            assert_eq!(stats.beams, 37);
        }
        // Passes of one item start at different places.
        let starts: std::collections::BTreeSet<u64> = (0..20).map(|c| pass_start(c, 37)).collect();
        assert!(starts.len() > 10);
        assert_eq!(pixel_of(17, 5), (2, 3));
        assert_eq!(camera_image_scale(2.0, 10, 5), 4.0);
        assert_eq!(camera_image_scale(2.0, 10, 0), 0.0);
    }
}
