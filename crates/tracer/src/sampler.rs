//! Where the integrators' random numbers come from: an independent stream per chunk or
//! Owen-scrambled Sobol points ([`spectrace_sampling::SobolSampler`]); by default
//! ([`SamplerKind::Auto`]) Sobol points for camera paths and independent streams for the light
//! tracer.
//!
//! Lights, materials and cameras draw their uniforms one `next_u64` at a time from a
//! `&mut dyn Rng`; [`ChunkSampler`] is that generator. With [`SamplerKind::Sobol`], every path
//! (a beam, or a camera sample with its light path) first calls
//! [`ChunkSampler::start_path`]`(stream, index)`, and its `k`-th draw is dimension `k` of point
//! `index` of a sequence scrambled for `(seed, stream)`:
//! - the light tracer: stream = the chunk, index = the beam's index in its chunk (each chunk is
//!   an independently scrambled sequence, stratified over its beams);
//! - the path tracer and BDPT: stream = the pixel, index = the pass (the chunk), so the samples
//!   of one pixel over the passes are the points of one sequence, stratified pixel by pixel.
//!
//! Camera paths each have a stream of their own ([`ChunkSampler::for_path`]): the independent
//! stream of `(seed, pass, pixel)`, or the Sobol point over it, so a camera path's result does
//! not depend on which paths were traced before it or beside it (the batched kernel interleaves
//! them). Light paths draw from their chunk's stream, one after the other.
//!
//! Both depend only on the seed and the chunk, so images stay bit-identical for any thread count
//! or shard split. Draws past the sampler's table (256 dimensions), the low bits of every draw
//! and draws outside a path come from the independent stream (`chunk_rng`, or the camera path's
//! own).
//! Lights that draw a variable number of uniforms (rejection loops) shift the dimensions of the
//! rest of their path: unbiased, but those draws lose their stratification.

use std::convert::Infallible;

use rand::{Rng, TryRng};
use rand_pcg::Pcg64;
use serde::{Deserialize, Serialize};
use spectrace_sampling::{GOLDEN_GAMMA, SobolSampler, mix64, split_mix64};

use rand::SeedableRng;

/// The generator of chunk `chunk` of a render with seed `seed` (SplitMix64 of both, so nearby
/// seeds and chunks give unrelated streams).
pub(crate) fn chunk_rng(seed: u64, chunk: u64) -> Pcg64 {
    Pcg64::seed_from_u64(mix64(seed ^ chunk.wrapping_mul(GOLDEN_GAMMA)))
}

/// The part of every camera path's stream of chunk `chunk` that depends on the seed and the
/// chunk alone.
fn pass_key(seed: u64, chunk: u64) -> u64 {
    split_mix64(split_mix64(seed ^ 0x5851_F42D_4C95_7F2D) ^ chunk)
}

/// The independent stream of item `item` of a chunk whose [`pass_key`] is `z` (a camera path's
/// own stream): unrelated to every chunk stream and to every other item's.
#[inline]
fn keyed_path_rng(z: u64, item: u64) -> Pcg64 {
    let hi = split_mix64(z ^ item.wrapping_mul(0xD6E8_FEB8_6659_FD93));
    let lo = split_mix64(hi ^ item);
    // The state from both halves; the stream (increment) from the item too, so that two paths
    // never share a sequence at an offset.
    Pcg64::new((u128::from(hi) << 64) | u128::from(lo), u128::from(split_mix64(lo ^ z)))
}

/// Which random numbers the integrators draw (`settings.sampler` in scene files).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SamplerKind {
    /// Chosen per estimator ([`SamplerKind::resolve`]): Sobol points for camera paths (the
    /// path tracer, BDPT, the path-traced sensor pass), independent uniforms for the light
    /// tracer. The default.
    #[default]
    Auto,
    /// Independent uniforms from each chunk's own stream.
    Independent,
    /// Owen-scrambled Sobol points, one dimension per draw of a path (see the module docs).
    Sobol,
}

impl SamplerKind {
    /// The name used in scene files and reports.
    pub fn name(self) -> &'static str {
        match self {
            Self::Auto => "auto",
            Self::Independent => "independent",
            Self::Sobol => "sobol",
        }
    }

    /// The sampler an estimator draws from: `self` unless [`Auto`](Self::Auto), which is Sobol
    /// for estimators whose work items are camera passes (`camera_passes`: one sample per pixel
    /// per pass, so a pixel's samples are the points of one sequence) and independent sampling
    /// for the light tracer.
    ///
    /// Why (the accuracy report, `docs/accuracy.md`, `path` against `path_sobol` and `bdpt`
    /// against `bdpt_sobol` at equal samples): a pixel's passes stratified over its sequence
    /// lower the path tracer's and BDPT's error on every shipped scene where the difference is
    /// measurable, and never raise it beyond the sweep's noise. The light tracer's chunks
    /// spread a sequence over the whole image (no pixel sees more than a few of its points):
    /// its time to 10% there was mixed (0.49x to 3x across the shipped scenes), so it stays
    /// independent here; the renderer passes `true` for it where its beams stop after a
    /// diffuse hit, where Sobol points pay (`spectrace_renderer`'s `sampler_of`).
    pub fn resolve(self, camera_passes: bool) -> SamplerKind {
        match self {
            Self::Auto if camera_passes => Self::Sobol,
            Self::Auto => Self::Independent,
            other => other,
        }
    }
}

/// The generator of one chunk: the chunk's independent stream, or Sobol points over it.
#[derive(Debug, Clone)]
pub enum ChunkSampler {
    /// `chunk_rng` alone.
    Independent(Pcg64),
    /// Sobol points; `chunk_rng` for the low bits and beyond the table.
    Sobol(SobolSampler<Pcg64>),
}

impl ChunkSampler {
    /// The generator of chunk `chunk` of a render with seed `seed` (`kind` already resolved:
    /// [`SamplerKind::Auto`] is independent sampling here).
    pub fn new(kind: SamplerKind, seed: u64, chunk: u64) -> Self {
        let rng = chunk_rng(seed, chunk);
        match kind {
            SamplerKind::Auto | SamplerKind::Independent => Self::Independent(rng),
            SamplerKind::Sobol => Self::Sobol(SobolSampler::new(seed, rng)),
        }
    }

    /// The sampler of one camera path (`kind` resolved for camera passes), item `item` of pass
    /// (chunk) `chunk` of a render with seed `seed`, already started: its own independent
    /// stream (`keyed_path_rng` of the seed and chunk's `pass_key` and the item), or point
    /// `chunk` of the item's Sobol sequence over it. It depends on nothing else, so a path
    /// gives the same result whichever paths are traced before it or beside it.
    pub fn for_path(kind: SamplerKind, seed: u64, chunk: u64, item: u64) -> Self {
        PassSamplers::new(kind, seed, chunk).get(item)
    }

    /// Starts a path: point `index` of the sequence of `stream` (nothing for independent
    /// sampling).
    #[inline]
    pub fn start_path(&mut self, stream: u64, index: u64) {
        if let Self::Sobol(s) = self {
            s.start_path(stream, index);
        }
    }
}

/// The samplers of the camera paths of one chunk: [`ChunkSampler::for_path`] of each of its
/// items, with what depends on the seed and the chunk alone (three of a path's seven mixing
/// steps) computed once.
#[derive(Debug, Clone)]
pub(crate) struct PassSamplers {
    chunk: u64,
    /// [`pass_key`] of the seed and the chunk.
    key: u64,
    /// Sobol points (the seed mixed in, no fallback yet), or independent sampling.
    sobol: Option<SobolSampler<()>>,
}

impl PassSamplers {
    /// The samplers of chunk `chunk` of a render with seed `seed` (`kind` resolved for camera
    /// passes).
    pub(crate) fn new(kind: SamplerKind, seed: u64, chunk: u64) -> Self {
        let sobol = match kind.resolve(true) {
            SamplerKind::Auto | SamplerKind::Independent => None,
            SamplerKind::Sobol => Some(SobolSampler::new(seed, ())),
        };
        Self { chunk, key: pass_key(seed, chunk), sobol }
    }

    /// The sampler of item `item`, already started ([`ChunkSampler::for_path`]).
    #[inline]
    pub(crate) fn get(&self, item: u64) -> ChunkSampler {
        let rng = keyed_path_rng(self.key, item);
        match &self.sobol {
            None => ChunkSampler::Independent(rng),
            Some(template) => {
                let mut sobol = template.with_fallback(rng);
                sobol.start_path(item, self.chunk);
                ChunkSampler::Sobol(sobol)
            }
        }
    }
}

impl TryRng for ChunkSampler {
    type Error = Infallible;

    #[inline]
    fn try_next_u32(&mut self) -> Result<u32, Infallible> {
        Ok(match self {
            Self::Independent(r) => r.next_u32(),
            Self::Sobol(s) => s.next_u32(),
        })
    }

    #[inline]
    fn try_next_u64(&mut self) -> Result<u64, Infallible> {
        Ok(match self {
            Self::Independent(r) => r.next_u64(),
            Self::Sobol(s) => s.next_u64(),
        })
    }

    fn try_fill_bytes(&mut self, dst: &mut [u8]) -> Result<(), Infallible> {
        match self {
            Self::Independent(r) => r.fill_bytes(dst),
            Self::Sobol(s) => s.fill_bytes(dst),
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn independent_sampling_is_the_chunk_stream_and_ignores_paths() {
        let mut a = ChunkSampler::new(SamplerKind::Independent, 3, 8);
        let mut b = chunk_rng(3, 8);
        a.start_path(1, 2);
        for _ in 0..10 {
            assert_eq!(a.next_u64(), b.next_u64());
        }
    }

    #[test]
    fn camera_path_streams_depend_on_seed_pass_and_item_alone() {
        for kind in [SamplerKind::Independent, SamplerKind::Sobol] {
            let mut a = ChunkSampler::for_path(kind, 3, 8, 5);
            let mut b = ChunkSampler::for_path(kind, 3, 8, 5);
            let first: Vec<u64> = (0..6).map(|_| a.next_u64()).collect();
            assert_eq!(first, (0..6).map(|_| b.next_u64()).collect::<Vec<_>>(), "{kind:?}");
            // Another item, pass or seed: another stream.
            for (seed, chunk, item) in [(3, 8, 6), (3, 9, 5), (4, 8, 5)] {
                let mut c = ChunkSampler::for_path(kind, seed, chunk, item);
                assert_ne!(c.next_u64(), first[0], "{kind:?} {seed} {chunk} {item}");
            }
        }
        // Unrelated to the chunk's own stream.
        let mut chunk = chunk_rng(3, 8);
        assert_ne!(keyed_path_rng(pass_key(3, 8), 0).next_u64(), chunk.next_u64());
    }

    #[test]
    fn sobol_sampling_depends_on_the_path_not_on_what_came_before() {
        let mut a = ChunkSampler::new(SamplerKind::Sobol, 3, 8);
        let mut b = ChunkSampler::new(SamplerKind::Sobol, 3, 8);
        for _ in 0..5 {
            let _ = b.next_u64();
        }
        a.start_path(4, 9);
        b.start_path(4, 9);
        // The top 23 bits are the Sobol coordinate: the same whatever the stream's position.
        assert_eq!(a.next_u64() >> 41, b.next_u64() >> 41);
    }
}
