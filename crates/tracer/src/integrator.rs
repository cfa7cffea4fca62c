//! The estimator interface the render loop drives: [`Integrator`].
//!
//! [`crate::render`] knows chunks, threads, shards, the time budget, the shared exact film and
//! the memory check, but not which estimator runs. An integrator supplies the rest:
//! - [`Integrator::render_chunk`]: the unit of work, `samples` work items of chunk `chunk`
//!   (light paths for the light tracer; camera samples for the path tracer and BDPT, whose
//!   samples each trace a light path too), drawn from the chunk's own random stream ([`crate::chunk_rng`]`(seed, chunk)`) and
//!   splatted into the film through [`Splat`];
//! - [`Integrator::image_scale`]: the normalisation, the factor that turns the film's exact sums
//!   into the image once `samples_done` work items have been done (for the light tracer, the
//!   lights' power over the beams, [`crate::image_scale`]).
//!
//! # Film and normalisation
//! The film holds exact, unscaled fixed-point sums; the integrator owns the scale, applied once
//! when the image is made. This is what keeps images bit-identical for any thread count and
//! shard split: a chunk's contributions do not depend on how many items the whole render does.
//!
//! Pixel samples and light splats (pbrt's `AddSample` and `AddSplat`) share this one film with
//! their own normalisations folded into one factor: camera estimators work in *passes* (a chunk
//! is one sample of every pixel, never cut), so a pixel sample's normalisation `1 / passes` is the
//! same for every pixel, and BDPT divides its light splats (`t = 1`) by the pixel count, the
//! light paths of a pass, so that `image = film x power x pixels / samples` holds for both. The
//! light tracer's `image = film x power / beams` is the same formula with the factor 1. A film
//! layer with per-pixel weight sums would only be needed to cut passes short.

use std::time::Instant;

use spectrace_lights::LightSource;

use crate::light_tracer::{LightTracerScene, LightTracerSettings, image_scale, trace_chunk_until};
use crate::{Effects, Splat, TraceStats};

/// An estimator the render loop drives: it renders chunks of work items into a film and says
/// how to normalise the film's sums.
pub trait Integrator: Send + Sync {
    /// A short name for reports: `"light"`, `"path"` or `"bdpt"`.
    fn name(&self) -> &'static str;

    /// The film's size in pixels (width, height): the camera's resolution.
    fn resolution(&self) -> (u32, u32);

    /// Renders `samples` work items of chunk `chunk` of a render with seed `seed` into `film`,
    /// drawing every random number from the chunk's own stream, so that the result depends only
    /// on `(seed, chunk, samples)`. With a `deadline`, stops early once it has passed (checking
    /// the clock every few microseconds of work, between items, after at least one item). The
    /// returned `stats.beams` is the number of items done, which the normalisation must use.
    fn render_chunk(
        &self,
        seed: u64,
        chunk: u64,
        samples: u64,
        deadline: Option<Instant>,
        film: &mut dyn Splat,
    ) -> TraceStats;

    /// The factor that turns the film's exact sums into the image after `samples_done` work
    /// items over the whole render (all chunks, all shards); 0 for none.
    fn image_scale(&self, samples_done: u64) -> f64;

    /// Sensor cells this integrator fills after the film's pixels (see
    /// [`crate::Film::with_sensor_cells`]); 0 (the default) when it fills none. Their sums
    /// are normalised by the same [`image_scale`](Self::image_scale).
    fn sensor_cells(&self) -> u32 {
        0
    }
}

/// The light tracer as an [`Integrator`]: beams from the lights, every non-specular hit
/// connected to the camera (see [`crate::trace_chunk`]); a work item is one beam.
#[derive(Debug, Clone)]
pub struct LightTracer<'a> {
    scene: &'a LightTracerScene<'a>,
    settings: LightTracerSettings,
    effects: Effects,
}

impl<'a> LightTracer<'a> {
    /// The light tracer's [`Integrator::name`].
    pub const NAME: &'static str = "light";

    /// A light tracer of `scene` with `settings`, following the `effects` decision.
    pub fn new(
        scene: &'a LightTracerScene<'a>,
        settings: LightTracerSettings,
        effects: Effects,
    ) -> Self {
        Self { scene, settings, effects }
    }

    /// The scene it traces.
    pub fn scene(&self) -> &'a LightTracerScene<'a> {
        self.scene
    }

    /// Its settings.
    pub fn settings(&self) -> &LightTracerSettings {
        &self.settings
    }

    /// The effects decision it follows.
    pub fn effects(&self) -> &Effects {
        &self.effects
    }
}

impl Integrator for LightTracer<'_> {
    fn name(&self) -> &'static str {
        Self::NAME
    }

    fn resolution(&self) -> (u32, u32) {
        (self.scene.camera.width(), self.scene.camera.height())
    }

    fn render_chunk(
        &self,
        seed: u64,
        chunk: u64,
        samples: u64,
        deadline: Option<Instant>,
        film: &mut dyn Splat,
    ) -> TraceStats {
        trace_chunk_until(
            self.scene,
            &self.settings,
            &self.effects,
            seed,
            chunk,
            samples,
            deadline,
            film,
        )
    }

    fn image_scale(&self, samples_done: u64) -> f64 {
        image_scale(self.scene.lights.power(), samples_done)
    }

    fn sensor_cells(&self) -> u32 {
        self.scene.sensors().map_or(0, crate::SensorSet::total_cells)
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]

    use std::sync::atomic::{AtomicU64, Ordering};

    use spectrace_spectrum::Xyz;

    use super::*;
    use crate::{ExactSum, Film, RenderOutput, RenderPlan, render};

    /// A trivial estimator: item `i` of chunk `c` splats X = 1/2 and Y = 1 / (1 + c + i) (sums of
    /// which depend on the order in floating point, never in the exact film) into pixel
    /// `(c % width, 0)`.
    struct Constant {
        width: u32,
    }

    impl Constant {
        fn value(chunk: u64, item: u64) -> Xyz {
            Xyz::new(0.5, 1.0 / (1.0 + chunk as f64 + item as f64), 0.0)
        }
    }

    impl Integrator for Constant {
        fn name(&self) -> &'static str {
            "constant"
        }

        fn resolution(&self) -> (u32, u32) {
            (self.width, 2)
        }

        fn render_chunk(
            &self,
            _seed: u64,
            chunk: u64,
            samples: u64,
            _deadline: Option<Instant>,
            film: &mut dyn Splat,
        ) -> TraceStats {
            let mut stats = TraceStats::default();
            for i in 0..samples {
                stats.beams += 1;
                if film.splat((chunk % u64::from(self.width)) as u32, 0, Self::value(chunk, i)) {
                    stats.splats += 1;
                }
            }
            stats
        }

        fn image_scale(&self, samples_done: u64) -> f64 {
            if samples_done == 0 { 0.0 } else { 1.0 / samples_done as f64 }
        }
    }

    fn plan(threads: usize, shard: Option<(u64, u64)>) -> RenderPlan {
        // 23 chunks of 1000 items, the last one of 700.
        RenderPlan {
            beams: 22_700,
            chunk_beams: 1000,
            seed: 7,
            threads,
            shard,
            time_budget: None,
            error_estimate: false,
            target_error: None,
        }
    }

    fn run(integrator: &dyn Integrator, plan: &RenderPlan) -> RenderOutput {
        let progressed = AtomicU64::new(0);
        let out = render(integrator, plan, &|done| {
            progressed.fetch_max(done, Ordering::Relaxed);
        })
        .unwrap();
        assert_eq!(progressed.load(Ordering::Relaxed), out.beams, "progress reaches the total");
        out
    }

    #[test]
    fn the_render_loop_is_bit_identical_for_any_estimator_thread_count_and_shard_split() {
        let integrator = Constant { width: 5 };
        let one = run(&integrator, &plan(1, None));
        // The exact expected sums: every item of every chunk, added one by one.
        let whole = plan(1, None);
        let mut expected = [[ExactSum::default(); 2]; 5];
        for c in 0..whole.chunks() {
            for i in 0..whole.beams_in_chunk(c) {
                let v = Constant::value(c, i);
                let pixel = &mut expected[(c % 5) as usize];
                assert!(pixel[0].add(v.x) && pixel[1].add(v.y));
            }
        }
        let image = one.film.to_xyz(1.0);
        for (x, sums) in expected.iter().enumerate() {
            assert_eq!(image[x], Xyz::new(sums[0].value(), sums[1].value(), 0.0), "pixel {x}");
            assert_eq!(image[5 + x], Xyz::default(), "row 1 stays black");
        }
        // Pixel 0 gets chunks 0, 5, 10, 15 and 20 (1000 items each): X = 5000 / 2 exactly.
        assert_eq!(image[0].x, 2500.0);
        // Pixel 2 gets chunk 22, the short one.
        assert_eq!(image[2].x, 0.5 * 4000.0 + 0.5 * 700.0);
        assert_eq!((one.beams, one.stats.beams, one.stats.splats), (22_700, 22_700, 22_700));
        assert_eq!(one.chunks, (0..23).collect::<Vec<_>>());
        assert_eq!(one.film.accepted(), 22_700);

        for threads in [2, 3] {
            let many = run(&integrator, &plan(threads, None));
            assert_eq!(many.film, one.film, "{threads} threads");
            assert_eq!((many.stats, &many.chunks), (one.stats, &one.chunks), "{threads} threads");
        }
        for (n, threads) in [(2, 1), (3, 2), (4, 3)] {
            let mut merged: Option<RenderOutput> = None;
            for k in (0..n).rev() {
                let part = run(&integrator, &plan(threads, Some((k, n))));
                match merged.as_mut() {
                    None => merged = Some(part),
                    Some(m) => m.merge(&part).unwrap(),
                }
            }
            let merged = merged.unwrap();
            assert_eq!(merged.film, one.film, "{n} shards");
            assert_eq!((merged.beams, &merged.chunks), (one.beams, &one.chunks), "{n} shards");
        }
        assert_eq!(integrator.image_scale(one.beams), 1.0 / 22_700.0);
        // The film's size is the integrator's.
        let mut film = Film::new(5, 2).unwrap();
        integrator.render_chunk(7, 3, 2, None, &mut film);
        assert_eq!(film.to_xyz(1.0)[3], Constant::value(3, 0) + Constant::value(3, 1));
        assert!(render(&Constant { width: 0 }, &plan(1, None), &|_| {}).is_err());
    }
}
