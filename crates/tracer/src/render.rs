//! Running the light tracer over work chunks on several threads (and, with shards, machines).

use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use serde::{Deserialize, Serialize};

use crate::light_tracer::{LightTracerScene, LightTracerSettings, TraceStats, trace_chunk};
use crate::{Effects, Film, FilmError};

/// Beams per work chunk by default: small enough to balance threads, large enough that the
/// per-chunk cost (a generator, a film merge) is negligible.
pub const DEFAULT_CHUNK_BEAMS: u64 = 1 << 14;

/// How much to render and how to split it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RenderPlan {
    /// Beams in the whole image (all shards together); with a time budget, the upper limit.
    pub beams: u64,
    /// Beams per chunk (the unit of work, of random streams, and of sharding).
    pub chunk_beams: u64,
    /// Seed of every random stream.
    pub seed: u64,
    /// Worker threads (at least 1).
    pub threads: usize,
    /// Render only the chunks whose index is `k` mod `n` (`(k, n)`), for one machine of many.
    pub shard: Option<(u64, u64)>,
    /// Stop claiming new chunks after this many seconds (the chunks already claimed finish).
    pub time_budget: Option<f64>,
}

impl RenderPlan {
    /// Number of chunks in the whole image.
    pub fn chunks(&self) -> u64 {
        self.beams.div_ceil(self.chunk_beams.max(1))
    }

    /// Beams in chunk `c` (the last chunk may be short).
    pub fn beams_in_chunk(&self, c: u64) -> u64 {
        let size = self.chunk_beams.max(1);
        self.beams.saturating_sub(c * size).min(size)
    }

    /// How many chunks this shard renders (all of them without a shard).
    pub fn shard_chunk_count(&self) -> u64 {
        let (k, n) = self.shard.unwrap_or((0, 1));
        let total = self.chunks();
        if k >= total { 0 } else { (total - k).div_ceil(n.max(1)) }
    }

    /// The `i`-th chunk this shard renders (`k + i n`), if there is one.
    pub fn shard_chunk(&self, i: u64) -> Option<u64> {
        let (k, n) = self.shard.unwrap_or((0, 1));
        (i < self.shard_chunk_count()).then(|| k + i * n.max(1))
    }

    /// Beams in this shard's chunks (without materialising the list: with a time budget the
    /// plan may hold ~10^14 chunks).
    pub fn shard_beams(&self) -> u64 {
        let count = self.shard_chunk_count();
        if count == 0 {
            return 0;
        }
        let last = self.shard_chunk(count - 1).unwrap_or(0);
        (count - 1)
            .saturating_mul(self.chunk_beams.max(1))
            .saturating_add(self.beams_in_chunk(last))
    }
}

/// The result of a render (or of one shard).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RenderOutput {
    /// The film: exact sums, not yet scaled by the light's power over the beams.
    pub film: Film,
    /// Counters.
    pub stats: TraceStats,
    /// The chunks that were rendered, sorted.
    pub chunks: Vec<u64>,
    /// Beams in those chunks.
    pub beams: u64,
    /// Wall time (s).
    pub seconds: f64,
}

impl RenderOutput {
    /// Adds another shard's output (same film size); chunks must not overlap.
    ///
    /// # Errors
    /// [`FilmError::SizeMismatch`] when the films differ in size.
    pub fn merge(&mut self, other: &RenderOutput) -> Result<(), FilmError> {
        self.film.merge(&other.film)?;
        self.stats.merge(&other.stats);
        self.chunks.extend(&other.chunks);
        self.chunks.sort_unstable();
        self.beams += other.beams;
        self.seconds = self.seconds.max(other.seconds);
        Ok(())
    }
}

/// Renders the plan's chunks on `plan.threads` threads; `progress(beams_done)` is called after
/// every chunk (from worker threads).
///
/// # Errors
/// [`FilmError::InvalidSize`] for a camera whose resolution cannot be allocated.
pub fn render(
    scene: &LightTracerScene<'_>,
    settings: &LightTracerSettings,
    effects: &Effects,
    plan: &RenderPlan,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<RenderOutput, FilmError> {
    let started = Instant::now();
    let (w, h) = (scene.camera.width(), scene.camera.height());
    let next = AtomicU64::new(0);
    let done = AtomicU64::new(0);
    // A budget too large to represent is no budget at all.
    let deadline = plan
        .time_budget
        .and_then(|s| Duration::try_from_secs_f64(s.max(0.0)).ok())
        .and_then(|d| started.checked_add(d));
    let results: Mutex<Vec<(Film, TraceStats, Vec<u64>)>> = Mutex::new(Vec::new());
    let mut first_error = None;
    // More threads than chunks would only wait.
    let threads = (plan.threads.max(1) as u64).min(plan.shard_chunk_count().max(1)) as usize;
    std::thread::scope(|scope| {
        let mut handles = Vec::new();
        for _ in 0..threads {
            handles.push(scope.spawn(|| -> Result<(), FilmError> {
                // The film is allocated with the first chunk: idle threads cost no memory.
                let mut film: Option<Film> = None;
                let mut stats = TraceStats::default();
                let mut mine = Vec::new();
                loop {
                    // The time budget stops new claims, but the first chunk always runs.
                    if deadline.is_some_and(|d| Instant::now() >= d)
                        && next.load(Ordering::Relaxed) > 0
                    {
                        break;
                    }
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    let Some(c) = plan.shard_chunk(i) else { break };
                    let n = plan.beams_in_chunk(c);
                    let film = match &mut film {
                        Some(f) => f,
                        None => film.insert(Film::new(w, h)?),
                    };
                    let s = trace_chunk(scene, settings, effects, plan.seed, c, n, film);
                    stats.merge(&s);
                    mine.push(c);
                    progress(done.fetch_add(n, Ordering::Relaxed) + n);
                }
                if let (Some(film), Ok(mut r)) = (film, results.lock()) {
                    r.push((film, stats, mine));
                }
                Ok(())
            }));
        }
        for handle in handles {
            if let Ok(Err(e)) = handle.join() {
                first_error.get_or_insert(e);
            }
        }
    });
    if let Some(e) = first_error {
        return Err(e);
    }
    let mut film = Film::new(w, h)?;
    let mut stats = TraceStats::default();
    let mut rendered = Vec::new();
    for (f, s, c) in results.into_inner().unwrap_or_default() {
        film.merge(&f)?;
        stats.merge(&s);
        rendered.extend(c);
    }
    rendered.sort_unstable();
    // With a time budget, chunks are claimed in order and every claimed chunk finishes, so the
    // rendered set is a prefix of the shard's chunks; the output reports exactly that set.
    let beams = rendered.iter().map(|&c| plan.beams_in_chunk(c)).sum();
    Ok(RenderOutput {
        film,
        stats,
        chunks: rendered,
        beams,
        seconds: started.elapsed().as_secs_f64(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plan(beams: u64, chunk_beams: u64, shard: Option<(u64, u64)>) -> RenderPlan {
        RenderPlan { beams, chunk_beams, seed: 1, threads: 1, shard, time_budget: None }
    }

    #[test]
    fn shards_partition_the_chunks() {
        let p = plan(10_500, 1000, None);
        assert_eq!(p.chunks(), 11);
        assert_eq!(p.beams_in_chunk(10), 500);
        assert_eq!(p.shard_beams(), 10_500);
        let mut seen = Vec::new();
        let mut beams = 0;
        for k in 0..3 {
            let s = plan(10_500, 1000, Some((k, 3)));
            for i in 0..s.shard_chunk_count() {
                seen.push(s.shard_chunk(i).unwrap());
            }
            assert_eq!(s.shard_chunk(s.shard_chunk_count()), None);
            beams += s.shard_beams();
        }
        seen.sort_unstable();
        assert_eq!(seen, (0..11).collect::<Vec<_>>());
        assert_eq!(beams, 10_500);
        assert_eq!(plan(500, 1000, Some((3, 4))).shard_chunk_count(), 0);
        // A time-budget plan with ~10^14 chunks costs nothing to describe.
        let huge = plan(u64::MAX / 2, 1 << 14, Some((1, 2)));
        assert!(huge.shard_chunk_count() > 1 << 40);
        assert_eq!(huge.shard_chunk(5), Some(11));
    }
}
