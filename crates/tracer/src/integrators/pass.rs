//! The camera estimators' unit of work, written once: a *pass*, one sample of every item (the
//! pixels of the image, or the cells of the sensors), each item a path of its own.
//!
//! Item `i` of pass `c` is `(i + pass_start(c)) mod items`: whole passes cover every item once,
//! and the one-item chunks of the pre-render probe spread over the image. Each item starts its
//! own path with a sampler of its own ([`ChunkSampler::for_path`]: the stream of `(seed, c, i)`;
//! Sobol: point `c` of the item's own sequence), so its result does not depend on the items
//! traced before it or beside it.
//!
//! # Normalisation, and passes cut short
//! When every pass is whole, every pixel has the same sample count and the image is their plain
//! mean: `image = film x power x items / samples` ([`camera_image_scale`]). A time budget may
//! cut a pass short (the clock is read every [`DEADLINE_CHECK_ITEMS`] items); the items done
//! are then a prefix of the pass's order, so each pixel's sample count follows from the chunk
//! list and each cut chunk's item count ([`SampleCounts`]), and [`camera_image`] divides each
//! pixel's sum by its own count. Contributions normalised per pass rather than per pixel sample
//! (BDPT's light paths splatted to the camera, [`PassEstimator::end_pass`]) go to the film's
//! pass layer ([`Splat::splat_pass`]) and are normalised by the samples over the items, the
//! passes' worth of work done. Each part is unbiased on its own (MIS weights still sum to one
//! whatever the strategies' sample counts), so the image stays exact.

use std::time::Instant;

use spectrace_spectrum::Xyz;

use crate::sampler::PassSamplers;
use crate::{
    ChunkSampler, ChunkWork, Integrator, LightTracerScene, RenderOutput, Splat, TraceStats,
};

/// Items between two looks at the clock inside a pass: a camera sample costs a microsecond or
/// more, a clock read some 25 ns, so the check costs under 0.1% and a pass stops within
/// 64 samples of its deadline.
pub(crate) const DEADLINE_CHECK_ITEMS: u64 = 64;

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

    /// `true` if [`Self::end_pass`] splats (through [`Splat::splat_pass`]), or samples do:
    /// the render then gives the film a pass layer when a pass may be cut short.
    fn pass_splats(&self) -> bool {
        false
    }

    /// Work done once per pass, after its items (not for the probe's one-item chunks), drawing
    /// from the chunk's stream outside any path; its splats are weighted by `share`, the part
    /// of the pass's items done (1 for a whole pass; less for a pass cut by a time budget),
    /// and go through [`Splat::splat_pass`].
    fn end_pass(
        &self,
        _share: f64,
        _rng: &mut ChunkSampler,
        _film: &mut dyn Splat,
        _stats: &mut TraceStats,
    ) {
    }

    /// Renders the `work.items` items of pass `work.chunk` into `film` (counted in
    /// `stats.beams`), or a prefix of them when `work.deadline` passes ([`pass_items_until`]):
    /// by default the scalar kernel, [`Self::sample`] for one item after the other, each with
    /// its own sampler.
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

    /// One pass (see the module docs), cut short after a multiple of
    /// `DEADLINE_CHECK_ITEMS` items once `work.deadline` has passed, or a prefix of one when
    /// the render's budget ends inside it; its once-per-pass work follows when
    /// `work.ends_pass`.
    fn render_chunk(&self, work: ChunkWork, film: &mut dyn Splat) -> TraceStats {
        let mut stats = self.render_items(work, film);
        let items = self.items().max(1);
        if work.ends_pass && stats.beams > 0 {
            let kind = self.scene().sampler().resolve(true);
            let mut rng = ChunkSampler::new(kind, work.seed, work.chunk);
            let mut pass = TraceStats::default();
            self.end_pass(stats.beams as f64 / items as f64, &mut rng, film, &mut pass);
            stats.merge(&pass);
        }
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

    fn pass_splats(&self) -> bool {
        PassEstimator::pass_splats(self)
    }

    fn chunks_are_passes(&self) -> bool {
        true
    }

    fn image(&self, output: &RenderOutput) -> Vec<Xyz> {
        let power = spectrace_lights::LightSource::power(self.scene().lights);
        camera_image(output, power, self.items())
    }
}

/// The image (XYZ per pixel, row-major) of a camera render of `items` pixels lit by lights of
/// total power `power`, from its film, its chunks (each a pass) and the passes cut short: each
/// pixel's sum over its own sample count, the pass layer over the passes' worth of samples (see
/// the module docs). A pixel no sample reached has only its pass layer. Without cut passes this
/// is exactly `film.to_xyz(camera_image_scale(power, items, samples))`.
pub fn camera_image(output: &RenderOutput, power: f64, items: u64) -> Vec<Xyz> {
    let pass_scale = camera_image_scale(power, items, output.beams);
    if output.cut.is_empty() {
        return output.film.to_xyz(pass_scale);
    }
    let counts = SampleCounts::of(output, items);
    output.film.to_xyz_layers(
        |pixel| match counts.get(pixel) {
            0 => 0.0,
            n => power / n as f64,
        },
        pass_scale,
    )
}

/// Camera samples per item of a render whose chunks are passes: one per whole pass, plus one
/// for each item a cut pass reached.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SampleCounts {
    /// Whole passes.
    whole: u64,
    /// Samples of the cut passes per item (empty without cut passes).
    extra: Vec<u32>,
}

impl SampleCounts {
    /// The counts of `output` over `items` items: its chunks not in `output.cut` are whole
    /// passes; each cut chunk `(c, m)` reached the first `m` items of pass `c`'s order.
    pub fn of(output: &RenderOutput, items: u64) -> Self {
        let whole = (output.chunks.len() as u64).saturating_sub(output.cut.len() as u64);
        let mut extra = Vec::new();
        if !output.cut.is_empty() {
            extra = vec![0u32; items as usize];
            for &(chunk, done) in &output.cut {
                for item in pass_items(chunk, done.min(items), items) {
                    if let Some(n) = extra.get_mut(item as usize) {
                        *n = n.saturating_add(1);
                    }
                }
            }
        }
        Self { whole, extra }
    }

    /// Samples of item `item`.
    pub fn get(&self, item: usize) -> u64 {
        self.whole + self.extra.get(item).map_or(0, |&n| u64::from(n))
    }

    /// Items no sample reached (none once a pass is whole).
    pub fn unsampled(&self) -> u64 {
        if self.whole > 0 { 0 } else { self.extra.iter().filter(|&&n| n == 0).count() as u64 }
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
    let samplers = PassSamplers::new(estimator.scene().sampler(), work.seed, work.chunk);
    run_pass(work, estimator.items(), |item, stats| {
        let mut rng = samplers.get(item);
        estimator.sample(item, &mut scratch, &mut rng, film, stats);
    })
}

/// The items of a chunk: `samples` items of pass `chunk` over `items` items, in order.
pub(crate) fn pass_items(chunk: u64, samples: u64, items: u64) -> impl Iterator<Item = u64> {
    let items = items.max(1);
    let start = pass_start(chunk, items);
    (0..samples).map(move |i| (i + start) % items)
}

/// The items of a chunk as [`pass_items`], but stopping once `deadline` has passed: the clock
/// is read before every [`DEADLINE_CHECK_ITEMS`]-th item after the first, so a chunk always does
/// at least that many items (all of them, if fewer) and a cut chunk a multiple of them.
pub(crate) fn pass_items_until(
    chunk: u64,
    samples: u64,
    items: u64,
    deadline: Option<Instant>,
) -> impl Iterator<Item = u64> {
    pass_items(chunk, samples, items)
        .enumerate()
        .take_while(move |&(i, _)| {
            let check = i > 0 && (i as u64).is_multiple_of(DEADLINE_CHECK_ITEMS);
            !(check && deadline.is_some_and(|d| Instant::now() >= d))
        })
        .map(|(_, item)| item)
}

/// Runs the items of pass `work.chunk` over `items` items, up to `work.deadline`
/// ([`pass_items_until`]): `sample(item, stats)` for each; counts the items in `stats.beams`.
pub(crate) fn run_pass(
    work: ChunkWork,
    items: u64,
    mut sample: impl FnMut(u64, &mut TraceStats),
) -> TraceStats {
    let mut stats = TraceStats::default();
    for item in pass_items_until(work.chunk, work.items, items, work.deadline) {
        sample(item, &mut stats);
        stats.beams += 1;
    }
    stats
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]

    use super::*;

    #[test]
    fn a_whole_pass_visits_every_item_once_from_a_scrambled_start() {
        for chunk in [0, 1, 7, 1000] {
            let mut seen = [0u32; 37];
            let work = ChunkWork { seed: 0, chunk, items: 37, deadline: None, ends_pass: true };
            let stats = run_pass(work, 37, |item, _| {
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

    #[test]
    fn a_pass_past_its_deadline_stops_at_the_first_look_at_the_clock() {
        let passed = Some(Instant::now());
        let cut: Vec<u64> = pass_items_until(3, 1000, 1000, passed).collect();
        assert_eq!(cut.len() as u64, DEADLINE_CHECK_ITEMS);
        // A prefix of the pass's order.
        assert!(cut.iter().copied().eq(pass_items(3, DEADLINE_CHECK_ITEMS, 1000)));
        // Fewer items than a check's worth, or no deadline: all of them.
        assert_eq!(pass_items_until(3, 50, 1000, passed).count(), 50);
        assert_eq!(pass_items_until(3, 1000, 1000, None).count(), 1000);
        let later = Instant::now().checked_add(std::time::Duration::from_secs(3600));
        assert_eq!(pass_items_until(3, 1000, 1000, later).count(), 1000);
    }

    /// A render output of `whole` whole passes over `items` items and the given cut passes.
    fn output(items: u64, whole: u64, cut: Vec<(u64, u64)>) -> RenderOutput {
        let film = crate::Film::with_pass_layer(items as u32, 1, 0).unwrap();
        let beams = whole * items + cut.iter().map(|c| c.1).sum::<u64>();
        RenderOutput {
            film,
            stats: TraceStats { beams, ..TraceStats::default() },
            chunks: (0..whole).chain(cut.iter().map(|c| c.0)).collect(),
            beams,
            seconds: 0.0,
            moments: None,
            cut,
        }
    }

    #[test]
    fn each_item_counts_the_whole_passes_and_the_cut_passes_that_reached_it() {
        let items = 10;
        let (c1, c2) = (5, 6);
        let out = output(items, 2, vec![(c1, 3), (c2, 4)]);
        let counts = SampleCounts::of(&out, items);
        let mut expected = [2u64; 10];
        for (chunk, done) in [(c1, 3), (c2, 4)] {
            for item in pass_items(chunk, done, items) {
                expected[item as usize] += 1;
            }
        }
        assert!((0..10).all(|i| counts.get(i) == expected[i]), "{counts:?}");
        assert_eq!((0..10).map(|i| counts.get(i)).sum::<u64>(), out.beams);
        assert_eq!(counts.unsampled(), 0);
        // Only cut passes: the items none reached.
        let first = SampleCounts::of(&output(items, 0, vec![(c1, 3)]), items);
        assert_eq!(first.unsampled(), 7);
        assert_eq!(SampleCounts::of(&output(items, 3, Vec::new()), items).get(9), 3);
    }

    #[test]
    fn a_pixel_is_its_sum_over_its_own_count_and_the_pass_layer_over_the_passes() {
        let items = 10;
        let mut out = output(items, 1, vec![(5, 3)]);
        let counts = SampleCounts::of(&out, items);
        for x in 0..10 {
            assert!(out.film.add(x, 0, Xyz::new(1.0, 0.0, 0.0) * counts.get(x as usize) as f64));
            assert!(out.film.add_pass(x, 0, Xyz::new(0.0, 1.3, 0.0)));
        }
        // Pixel: (n_p / n_p) x power; pass layer: 1.3 x power x items / samples.
        let image = camera_image(&out, 2.0, items);
        for p in &image {
            assert!((p.x - 2.0).abs() < 1e-15, "{p:?}");
            assert!((p.y - 1.3 * 2.0 * 10.0 / 13.0).abs() < 1e-15, "{p:?}");
        }
        // Without a cut pass: exactly the whole-pass scale.
        out.cut.clear();
        out.chunks.pop();
        out.beams = items;
        assert_eq!(camera_image(&out, 2.0, items), out.film.to_xyz(2.0 * 10.0 / 10.0));
    }
}
