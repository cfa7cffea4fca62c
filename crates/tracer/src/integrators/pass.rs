//! The camera estimators' unit of work, written once: a *pass*, one sample of every item (the
//! pixels of the image, or the cells of the sensors), each item a path of its own.
//!
//! Item `i` of pass `c` is `(i + pass_start(c)) mod items`: whole passes cover every item once,
//! and the one-item chunks of the pre-render probe spread over the image. Each item starts its
//! own path in the chunk's sampler (Sobol: point `c` of the item's own sequence). A pass is never
//! cut short, so every pixel has the same sample count and the image is their plain mean:
//! `image = film x power x items / samples` ([`camera_image_scale`]).

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

    /// One sample of item `item`, its path already started in `rng`.
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
        let mut rng = ChunkSampler::new(self.scene().sampler(), work.seed, work.chunk);
        let items = self.items();
        let mut before = TraceStats::default();
        if work.items >= items.max(1) {
            self.start_pass(&mut rng, film, &mut before);
        }
        let mut scratch = self.scratch();
        let mut stats = run_pass(&mut rng, work.chunk, work.items, items, |item, rng, stats| {
            self.sample(item, &mut scratch, rng, film, stats);
        });
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

/// Runs `samples` items of pass `chunk` over `items` items, drawing from `rng` (the chunk's
/// sampler): `sample(item, rng, stats)` for each, with the item's path started in the sampler;
/// counts the items in `stats.beams`.
pub(crate) fn run_pass(
    rng: &mut ChunkSampler,
    chunk: u64,
    samples: u64,
    items: u64,
    mut sample: impl FnMut(u64, &mut ChunkSampler, &mut TraceStats),
) -> TraceStats {
    let mut stats = TraceStats::default();
    let items = items.max(1);
    let start = pass_start(chunk, items);
    for i in 0..samples {
        let item = (i + start) % items;
        // Sobol: the item's own sequence, one point per pass.
        rng.start_path(item, chunk);
        sample(item, rng, &mut stats);
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
            let mut rng = ChunkSampler::new(crate::SamplerKind::Independent, 1, chunk);
            let stats = run_pass(&mut rng, chunk, 37, 37, |item, _, _| {
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
