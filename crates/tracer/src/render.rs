//! Running an [`Integrator`] over work chunks on several threads (and, with shards, machines).

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Mutex, PoisonError};
use std::time::{Duration, Instant};

use serde::{Deserialize, Serialize};

use crate::film::moments::{ChunkTally, LiveEstimate};
use crate::{
    ChunkWork, ErrorEstimate, ErrorMeasure, Film, FilmError, FilmWriter, Integrator, Moments,
    TraceStats,
};

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
    /// Time budget (s): after it, no new chunk is claimed and the chunks being traced stop
    /// within a few microseconds of work (between beams; at least one beam is always traced).
    pub time_budget: Option<f64>,
    /// Keep the per-chunk moments of the error estimate ([`Moments`]; 120 bytes per pixel and
    /// 29 per pixel and thread).
    #[serde(default)]
    pub error_estimate: bool,
    /// Stop once the estimated relative error in `error_measure` is at most this (needs a
    /// trusted estimate, [`ErrorEstimate::is_trusted`]; implies `error_estimate`). Chunks being
    /// traced then finish.
    #[serde(default)]
    pub target_error: Option<f64>,
    /// The measure of the error estimate's headline and of the target
    /// ([`ErrorMeasure::RelMse`] by default).
    #[serde(default)]
    pub error_measure: ErrorMeasure,
}

/// Memory a render may use when the available memory cannot be read (no `/proc/meminfo`):
/// 4 GiB, which holds the largest film ([`crate::MAX_PIXELS`] pixels, 1.5 GiB) with room to spare.
pub const FALLBACK_MEMORY_LIMIT: u64 = 4 << 30;

/// How much memory a render may use, and where that figure comes from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MemoryLimit {
    /// Bytes.
    pub bytes: u64,
    /// Where the figure comes from, in words (for error messages).
    pub source: String,
}

impl MemoryLimit {
    /// The least of what the system allows a render, from what Linux says (each figure read
    /// fresh; [`FALLBACK_MEMORY_LIMIT`] where none can be read):
    /// - three quarters of the memory the system can give without swapping (`MemAvailable` in
    ///   `/proc/meminfo`): the film is written at random places all through the render, so it
    ///   must stay resident (a swapped film would crawl); the remaining quarter is for the
    ///   scene, the image conversion after the render and the rest of the system;
    /// - three quarters of what the process's cgroup may still use (`memory.max` less
    ///   `memory.current` under `/sys/fs/cgroup`), a container's limit;
    /// - the address-space limit (`ulimit -v`, `Max address space` in `/proc/self/limits`)
    ///   less the address space already in use (`VmSize` in `/proc/self/status`) and
    ///   [`THREAD_ADDRESS_RESERVE`] for each of up to [`RESERVED_THREADS`] threads (their
    ///   stacks and allocator arenas take address space, if little memory).
    pub fn system() -> Self {
        let read = |path: &str| std::fs::read_to_string(path).ok();
        let mut best: Option<Self> = None;
        let mut consider = |bytes: u64, source: String| {
            if best.as_ref().is_none_or(|b| bytes < b.bytes) {
                best = Some(Self { bytes, source });
            }
        };
        if let Some(available) = read("/proc/meminfo").as_deref().and_then(mem_available) {
            let source = format!(
                "3/4 of the {} available according to /proc/meminfo",
                spectrace_geometry::human_bytes(available)
            );
            consider(available / 4 * 3, source);
        }
        let (max, current) =
            (read("/sys/fs/cgroup/memory.max"), read("/sys/fs/cgroup/memory.current"));
        if let Some(free) = cgroup_free(max.as_deref(), current.as_deref()) {
            let source = format!(
                "3/4 of the {} the process's cgroup may still use (memory.max)",
                spectrace_geometry::human_bytes(free)
            );
            consider(free / 4 * 3, source);
        }
        let (limits, status) = (read("/proc/self/limits"), read("/proc/self/status"));
        if let Some((free, limit)) = address_space_free(limits.as_deref(), status.as_deref()) {
            let source = format!(
                "the address-space limit (ulimit -v) of {}, less what is in use and {} for \
                 threads",
                spectrace_geometry::human_bytes(limit),
                spectrace_geometry::human_bytes(THREAD_ADDRESS_RESERVE * RESERVED_THREADS)
            );
            consider(free, source);
        }
        best.unwrap_or_else(|| Self {
            bytes: FALLBACK_MEMORY_LIMIT,
            source: "the fallback limit: the available memory could not be read".to_owned(),
        })
    }
}

/// Address space a thread may take beyond the render's own buffers: its stack (2 MiB) and an
/// allocator arena (glibc reserves 64 MiB of address space for each).
pub const THREAD_ADDRESS_RESERVE: u64 = 66 << 20;

/// Threads [`MemoryLimit::system`] reserves address space for under an address-space limit.
pub const RESERVED_THREADS: u64 = 16;

/// What a cgroup v2 may still use: `memory.max` (a number, or `max`: no limit) less
/// `memory.current`.
fn cgroup_free(max: Option<&str>, current: Option<&str>) -> Option<u64> {
    let max: u64 = max?.trim().parse().ok()?;
    let current: u64 = current.and_then(|c| c.trim().parse().ok()).unwrap_or(0);
    Some(max.saturating_sub(current))
}

/// Under an address-space limit: the address space left for a render (the soft limit of `Max
/// address space` in a `/proc/self/limits` text, less `VmSize` of a `/proc/self/status` text and
/// the threads' reserve) and the limit; `None` without a limit.
fn address_space_free(limits: Option<&str>, status: Option<&str>) -> Option<(u64, u64)> {
    let line = limits?.lines().find(|l| l.starts_with("Max address space"))?;
    let soft = line.trim_start_matches("Max address space").split_whitespace().next()?;
    let limit: u64 = soft.parse().ok()?; // "unlimited" does not parse: no limit
    let in_use = status
        .and_then(|s| s.lines().find(|l| l.starts_with("VmSize:")))
        .and_then(|l| l.split_whitespace().nth(1)?.parse::<u64>().ok())
        .map_or(0, |kib| kib.saturating_mul(1024));
    let free =
        limit.saturating_sub(in_use).saturating_sub(THREAD_ADDRESS_RESERVE * RESERVED_THREADS);
    Some((free, limit))
}

/// `MemAvailable` of a `/proc/meminfo` text, in bytes.
fn mem_available(meminfo: &str) -> Option<u64> {
    let line = meminfo.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let mut words = line.split_whitespace().skip(1);
    let value: u64 = words.next()?.parse().ok()?;
    match words.next() {
        Some("kB") => value.checked_mul(1024),
        None => Some(value),
        Some(_) => None,
    }
}

impl RenderPlan {
    /// Number of chunks in the whole image.
    pub fn chunks(&self) -> u64 {
        self.beams.div_ceil(self.chunk_beams.max(1))
    }

    /// Whether the last chunk is shorter than the others: for a camera estimator, a pass the
    /// budget of samples ends inside.
    pub fn ends_inside_a_chunk(&self) -> bool {
        !self.beams.is_multiple_of(self.chunk_beams.max(1))
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

    /// Threads that actually work: `threads` (at least 1), but no more than this shard's chunks.
    pub fn worker_threads(&self) -> usize {
        (self.threads.max(1) as u64).min(self.shard_chunk_count().max(1)) as usize
    }

    /// Bytes [`render`] needs for a `width x height` image: one shared film plus one
    /// [`FilmWriter`] buffer per working thread. It does not grow with the thread count beyond
    /// the small buffers. With a time budget it counts the film's pass layer, which camera
    /// estimators may need ([`RenderPlan::memory_bytes_with`]).
    pub fn memory_bytes(&self, width: u32, height: u32) -> u64 {
        self.memory_bytes_with(width, height, self.time_budget.is_some())
    }

    /// Bytes [`render`] needs for a `width x height` image with (`pass_layer`) or without a
    /// film pass layer ([`Film::with_pass_layer`]: a camera estimator's render with a time
    /// budget).
    pub fn memory_bytes_with(&self, width: u32, height: u32, pass_layer: bool) -> u64 {
        let threads = self.worker_threads() as u64;
        let estimate = if self.keeps_estimate() {
            let pixels = u64::from(width) * u64::from(height);
            Moments::bytes_for(width, height).saturating_add(
                threads.saturating_mul(pixels.saturating_mul(ChunkTally::BYTES_PER_PIXEL)),
            )
        } else {
            0
        };
        let film = if pass_layer {
            Film::bytes_with_pass_layer(width, height)
        } else {
            Film::bytes_for(width, height)
        };
        film.saturating_add(threads.saturating_mul(FilmWriter::BYTES)).saturating_add(estimate)
    }

    /// The target error this shard stops at: the image's target times `sqrt(N)` for one of `N`
    /// shards (N shards of equal work, each with error `e`, merge into an image with error
    /// `e / sqrt(N)`).
    pub fn shard_target_error(&self) -> Option<f64> {
        let n = self.shard.map_or(1, |(_, n)| n.max(1));
        self.target_error.map(|t| t * (n as f64).sqrt())
    }

    /// `true` if the render keeps the error estimate's moments (asked for, or needed by a
    /// target).
    pub fn keeps_estimate(&self) -> bool {
        self.error_estimate || self.target_error.is_some()
    }

    /// Checks that a `width x height` render fits in `limit`; returns the bytes it needs
    /// ([`RenderPlan::memory_bytes`]).
    ///
    /// # Errors
    /// [`FilmError::TooLarge`] saying how much is needed and how much may be used.
    pub fn check_memory(
        &self,
        width: u32,
        height: u32,
        limit: &MemoryLimit,
    ) -> Result<u64, FilmError> {
        self.check_memory_with(width, height, self.time_budget.is_some(), limit)
    }

    /// This plan with the most threads, at most its own, whose render of a `width x height`
    /// image fits in `limit` (each thread keeps a chunk tally for the error estimate); `None`
    /// when not even one thread fits.
    pub fn with_threads_fitting(
        &self,
        width: u32,
        height: u32,
        limit: &MemoryLimit,
    ) -> Option<Self> {
        (1..=self.worker_threads())
            .rev()
            .map(|threads| RenderPlan { threads, ..*self })
            .find(|p| p.check_memory(width, height, limit).is_ok())
    }

    /// [`RenderPlan::check_memory`] with or without a film pass layer.
    ///
    /// # Errors
    /// As [`RenderPlan::check_memory`].
    pub fn check_memory_with(
        &self,
        width: u32,
        height: u32,
        pass_layer: bool,
        limit: &MemoryLimit,
    ) -> Result<u64, FilmError> {
        let needed = self.memory_bytes_with(width, height, pass_layer);
        if needed <= limit.bytes {
            return Ok(needed);
        }
        let threads = self.worker_threads();
        Err(FilmError::TooLarge {
            width,
            height,
            needed,
            breakdown: format!(
                "a film of {} at {} bytes per pixel{} and {threads} thread buffer{} of {}",
                spectrace_geometry::human_bytes(if pass_layer {
                    Film::bytes_with_pass_layer(width, height)
                } else {
                    Film::bytes_for(width, height)
                }),
                if pass_layer { "96 (with a pass layer)" } else { "48" },
                if self.keeps_estimate() {
                    ", the error estimate's moments at 120 bytes per pixel and 29 per pixel and thread"
                } else {
                    ""
                },
                if threads == 1 { "" } else { "s" },
                spectrace_geometry::human_bytes(FilmWriter::BYTES)
            ),
            limit: limit.bytes,
            limit_source: limit.source.clone(),
        })
    }
}

/// The result of a render (or of one shard).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RenderOutput {
    /// The film: exact sums, not yet scaled by [`Integrator::image_scale`] (for the light
    /// tracer, the light's power over the beams).
    pub film: Film,
    /// Counters.
    pub stats: TraceStats,
    /// The chunks that were rendered, sorted. With a time budget, the chunks being traced when
    /// it ran out are listed too, though they were cut short.
    pub chunks: Vec<u64>,
    /// Work items done (beams, for the light tracer; exactly: the image is normalised by it);
    /// equals `stats.beams`.
    pub beams: u64,
    /// Wall time (s).
    pub seconds: f64,
    /// The per-chunk moments of the error estimate, if the plan kept them (chunks cut short by
    /// a time budget are left out: see [`FilmWriter::discard_chunk`]).
    #[serde(default)]
    pub moments: Option<Moments>,
    /// The chunks a time budget cut short, and a camera estimator's pass that its budget of
    /// samples ends inside (the plan's last chunk, shorter than a pass), sorted, each with the
    /// items it did (also listed in `chunks`): a camera estimator's image normalises each
    /// pixel by its own sample count from them ([`crate::camera_image`]).
    #[serde(default)]
    pub cut: Vec<(u64, u64)>,
}

impl RenderOutput {
    /// The estimated accuracy of the image with `measure` as the headline (`None` if the plan
    /// kept no moments).
    pub fn estimate(&self, measure: ErrorMeasure) -> Option<ErrorEstimate> {
        self.moments.as_ref().map(|m| m.estimate(measure))
    }

    /// Adds another shard's output (same film size); chunks must not overlap.
    ///
    /// # Errors
    /// [`FilmError::SizeMismatch`] when the films differ in size.
    pub fn merge(&mut self, other: &RenderOutput) -> Result<(), FilmError> {
        self.film.merge(&other.film)?;
        self.moments = match (self.moments.take(), &other.moments) {
            (Some(mut a), Some(b)) => {
                a.merge(b)?;
                Some(a)
            }
            // One side without moments: the merged image has no estimate.
            _ => None,
        };
        self.stats.merge(&other.stats);
        self.chunks.extend(&other.chunks);
        self.chunks.sort_unstable();
        self.cut.extend(&other.cut);
        self.cut.sort_unstable();
        self.beams += other.beams;
        self.seconds = self.seconds.max(other.seconds);
        Ok(())
    }
}

/// Whether [`render_observed`] recomputes the error estimate as it goes. Either way the
/// render keeps its moments (with [`RenderPlan::error_estimate`]), from which the final
/// estimate is computed after it ([`RenderOutput::estimate`]); a live estimate is an O(pixels)
/// computation that only a reader needs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LiveEstimates {
    /// Recomputed every few chunks and handed to the progress callback (a progress display, a
    /// pilot's slope fit), and wherever a target error needs it.
    Reported,
    /// Only where the plan's target error needs one to decide when to stop; the progress
    /// callback otherwise gets none. For renders nobody watches: on the race's 64-sample
    /// spot-over-a-plane path render the live estimates were about 7% of the wall time.
    ForTarget,
}

/// What a render reports as it goes ([`render_observed`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Progress {
    /// Work items done (beams, for the light tracer).
    pub items: u64,
    /// Wall time since the render started (s).
    pub seconds: f64,
    /// The error estimate after this chunk in the plan's measure (for `energy` from the
    /// running totals; for the others recomputed every few chunks), if the render keeps one
    /// and reports it ([`LiveEstimates`]).
    pub estimate: Option<ErrorEstimate>,
}

/// Renders the plan's chunks with `integrator` on `plan.threads` threads into one shared film;
/// `progress(items)` is called after every chunk (from worker threads) with the work items
/// (beams, for the light tracer) done so far. See [`render_observed`].
///
/// # Errors
/// As [`render_observed`].
pub fn render(
    integrator: &dyn Integrator,
    plan: &RenderPlan,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<RenderOutput, FilmError> {
    render_observed(integrator, plan, &|p: &Progress| progress(p.items), LiveEstimates::ForTarget)
}

/// Renders the plan's chunks with `integrator` on `plan.threads` threads into one shared film;
/// `progress` is called after every chunk (from worker threads) with the work items done so far
/// and, if the plan keeps the error estimate and `reported` is [`LiveEstimates::Reported`], the
/// estimate so far.
///
/// The loop does not know which estimator runs: it claims chunks, hands each to
/// [`Integrator::render_chunk`] with the thread's [`FilmWriter`], and counts the items done. The
/// output's film holds the exact, unscaled sums; [`Integrator::image_scale`] of
/// [`RenderOutput::beams`] normalises them.
///
/// Memory: one film for the whole render plus a small [`FilmWriter`] buffer per thread, and with
/// the error estimate the [`Moments`] and a chunk tally per thread ([`RenderPlan::memory_bytes`]),
/// checked against [`MemoryLimit::system`] before anything is allocated. The film is exact, so
/// the image is bit-identical for any thread count (the estimate, a floating-point sum, to
/// rounding).
///
/// With a time budget, threads stop claiming chunks once it has passed (the first chunk is
/// always claimed) and the chunks in progress stop between items within a few microseconds of
/// work; the output counts exactly the items done. With a target error, threads stop claiming
/// chunks once an estimate from at least [`crate::MIN_BATCHES`] chunks reaches it; the chunks in
/// progress finish, and each is judged again with it folded in: if that estimate is above the
/// target (one more batch can raise it), the threads go on, so a render stops only on an
/// estimate over all the chunks it keeps.
///
/// # Errors
/// [`FilmError::InvalidSize`] for a camera whose resolution is not a valid film;
/// [`FilmError::TooLarge`] when the render would need more memory than it may use;
/// [`FilmError::OutOfMemory`] naming what could not be had (the film, the moments, a thread's
/// tally) when the system refuses memory the plan expected, before any work starts.
pub fn render_observed(
    integrator: &dyn Integrator,
    plan: &RenderPlan,
    progress: &(dyn Fn(&Progress) + Sync),
    reported: LiveEstimates,
) -> Result<RenderOutput, FilmError> {
    let started = Instant::now();
    let (w, h) = integrator.resolution();
    // A pass cut short needs its per-pass splats apart from the per-sample ones: with a time
    // budget, or when the budget of samples ends inside a pass.
    let passes = integrator.chunks_are_passes();
    let partial = passes && plan.ends_inside_a_chunk();
    let pass_layer = (plan.time_budget.is_some() || partial) && integrator.pass_splats();
    plan.check_memory_with(w, h, pass_layer, &MemoryLimit::system())?;
    let cells = integrator.sensor_cells();
    let film = Mutex::new(if pass_layer {
        Film::with_pass_layer(w, h, cells)?
    } else {
        Film::with_sensor_cells(w, h, cells)?
    });
    let moments = if plan.keeps_estimate() { Some(Mutex::new(Moments::new(w, h)?)) } else { None };
    let next = AtomicU64::new(0);
    let done = AtomicU64::new(0);
    let target_reached = AtomicBool::new(false);
    // A budget too large to represent is no budget at all.
    let deadline = plan
        .time_budget
        .and_then(|s| Duration::try_from_secs_f64(s.max(0.0)).ok())
        .and_then(|d| started.checked_add(d));
    // The live estimate after every chunk; its full O(pixels) form is redone ever more rarely,
    // at a cost of at most an eighth of a pixel per item (see `LiveEstimate`).
    let live = Mutex::new(LiveEstimate::new(
        plan.error_measure,
        u64::from(w) * u64::from(h),
        plan.chunk_beams,
    ));
    // After each chunk: the live estimate, and whether the target is reached, judged under the
    // moments' lock so that no chunk folded in can escape the judgement. A fresh estimate at or
    // below the target stops the threads from claiming chunks; a chunk that ends after that
    // (it was in progress) is folded in and the target judged again, fresh, with it: adding a
    // batch can raise the estimate, and then the threads go on. So a render stops only on an
    // estimate over every chunk it keeps.
    let live_estimate = || -> Option<ErrorEstimate> {
        let target = plan.shard_target_error();
        if reported == LiveEstimates::ForTarget && target.is_none() {
            return None;
        }
        let m = moments.as_ref()?.lock().unwrap_or_else(PoisonError::into_inner);
        let mut live = live.lock().unwrap_or_else(PoisonError::into_inner);
        let recheck = target.is_some() && target_reached.load(Ordering::Relaxed);
        let (e, fresh) = if recheck { (live.fresh(&m), true) } else { live.update(&m, target) };
        if let Some(target) = target
            && fresh
        {
            let reached = e.is_trusted() && e.relative_error.is_some_and(|r| r <= target);
            if reached || recheck {
                target_reached.store(reached, Ordering::Relaxed);
            }
        }
        Some(e)
    };
    let results: Mutex<Vec<ThreadResult>> = Mutex::new(Vec::new());
    // Each thread's writer, its memory had (or refused) before any work starts.
    let writers = (0..plan.worker_threads())
        .map(|_| match &moments {
            Some(m) => FilmWriter::with_moments(&film, m),
            None => Ok(FilmWriter::new(&film)),
        })
        .collect::<Result<Vec<_>, FilmError>>()?;
    let writers = Mutex::new(writers);
    std::thread::scope(|scope| {
        for _ in 0..plan.worker_threads() {
            scope.spawn(|| {
                let writer = writers.lock().unwrap_or_else(PoisonError::into_inner).pop();
                let Some(mut writer) = writer else { return };
                let mut stats = TraceStats::default();
                let mut mine = Vec::new();
                let mut cut = Vec::new();
                loop {
                    // The time budget stops new claims, but the first chunk always runs.
                    if deadline.is_some_and(|d| Instant::now() >= d)
                        && next.load(Ordering::Relaxed) > 0
                    {
                        break;
                    }
                    if target_reached.load(Ordering::Relaxed) {
                        break;
                    }
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    let Some(c) = plan.shard_chunk(i) else { break };
                    let n = plan.beams_in_chunk(c);
                    let work = ChunkWork {
                        seed: plan.seed,
                        chunk: c,
                        items: n,
                        deadline,
                        ends_pass: true,
                    };
                    let s = integrator.render_chunk(work, &mut writer);
                    if s.beams < n || (passes && s.beams < plan.chunk_beams) {
                        // Cut by the deadline, or a pass the budget ends inside: normalised
                        // pixel by pixel, kept out of the moments (a batch is a whole pass).
                        writer.discard_chunk();
                        cut.push((c, s.beams));
                    } else {
                        writer.end_chunk(c, s.beams);
                    }
                    stats.merge(&s);
                    mine.push(c);
                    let items = done.fetch_add(s.beams, Ordering::Relaxed) + s.beams;
                    let estimate = live_estimate();
                    progress(&Progress {
                        items,
                        seconds: started.elapsed().as_secs_f64(),
                        estimate,
                    });
                    if s.beams < n {
                        // Cut short by the deadline.
                        break;
                    }
                }
                writer.flush();
                if let Ok(mut r) = results.lock() {
                    r.push(ThreadResult { stats, chunks: mine, cut });
                }
            });
        }
    });
    drop(writers);
    let film = film.into_inner().unwrap_or_else(PoisonError::into_inner);
    let moments = moments.map(|m| m.into_inner().unwrap_or_else(PoisonError::into_inner));
    let mut stats = TraceStats::default();
    let mut rendered = Vec::new();
    let mut cut = Vec::new();
    for r in results.into_inner().unwrap_or_default() {
        stats.merge(&r.stats);
        rendered.extend(r.chunks);
        cut.extend(r.cut);
    }
    rendered.sort_unstable();
    cut.sort_unstable();
    // Without a budget every chunk of the shard was traced whole; with one, the rendered set is
    // the chunks claimed, the last ones possibly cut short, and the beams are counted exactly.
    Ok(RenderOutput {
        film,
        beams: stats.beams,
        stats,
        chunks: rendered,
        seconds: started.elapsed().as_secs_f64(),
        moments,
        cut,
    })
}

/// What one worker thread of [`render_observed`] did.
struct ThreadResult {
    /// Its counters.
    stats: TraceStats,
    /// The chunks it rendered.
    chunks: Vec<u64>,
    /// Those a time budget cut short, with the items each did.
    cut: Vec<(u64, u64)>,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plan(beams: u64, chunk_beams: u64, shard: Option<(u64, u64)>) -> RenderPlan {
        RenderPlan {
            beams,
            chunk_beams,
            seed: 1,
            threads: 1,
            shard,
            time_budget: None,
            error_estimate: false,
            target_error: None,
            error_measure: ErrorMeasure::default(),
        }
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

    #[test]
    fn memory_needs_one_film_whatever_the_thread_count() {
        let (w, h) = (8192, 4096);
        let with = |threads: usize| RenderPlan { threads, ..plan(u64::MAX / 2, 1 << 14, None) };
        let film = Film::bytes_for(w, h);
        let one = with(1).memory_bytes(w, h);
        let four = with(4).memory_bytes(w, h);
        let many = with(256).memory_bytes(w, h);
        assert_eq!(one, film + FilmWriter::BYTES);
        assert_eq!(four - one, 3 * FilmWriter::BYTES);
        // 256 threads need less than 5% more than one (a film per thread was 256 films).
        assert!(many < film + film / 20, "{many} vs {film}");
        // Threads beyond the chunks do not work and need nothing.
        assert_eq!(RenderPlan { threads: 8, ..plan(1000, 1000, None) }.memory_bytes(w, h), one);
    }

    #[test]
    fn a_render_that_cannot_fit_is_refused_with_what_it_needs() {
        let p = RenderPlan { threads: 4, ..plan(1 << 20, 1 << 14, None) };
        let small = MemoryLimit { bytes: 1 << 30, source: "a test limit".to_owned() };
        let e = p.check_memory(8192, 4096, &small).unwrap_err().to_string();
        assert!(
            e.contains("8192x4096")
                && e.contains("camera.width")
                && e.contains("1.5 GiB")
                && e.contains("4 thread buffers")
                && e.contains("1 GiB")
                && e.contains("a test limit"),
            "{e}"
        );
        assert_eq!(p.check_memory(640, 480, &small).unwrap(), p.memory_bytes(640, 480));
        assert_eq!(mem_available("MemTotal: 8 kB\nMemAvailable:   3 kB\n"), Some(3072));
        assert_eq!(mem_available("MemTotal: 8 kB\n"), None);
        assert!(MemoryLimit::system().bytes > 0);
        // With the estimate, each thread's tally takes 29 bytes per pixel: a limit that holds
        // the film, the moments and three tallies gives three threads.
        let eight = RenderPlan { threads: 8, error_estimate: true, ..p };
        let one = RenderPlan { threads: 1, ..eight }.memory_bytes(1000, 1000);
        let three = RenderPlan { threads: 3, ..eight }.memory_bytes(1000, 1000);
        let room = MemoryLimit { bytes: three + 1000, source: "test".to_owned() };
        assert_eq!(eight.with_threads_fitting(1000, 1000, &room).map(|p| p.threads), Some(3));
        let tight = MemoryLimit { bytes: one - 1, source: "test".to_owned() };
        assert_eq!(eight.with_threads_fitting(1000, 1000, &tight), None);
        // The limits Linux reports, as its files write them.
        let limits = "Limit                     Soft Limit           Hard Limit           Units\n\
                      Max address space         4096000000           unlimited            bytes\n";
        let status = "Name:\tspectrace\nVmSize:\t  100000 kB\n";
        let reserve = THREAD_ADDRESS_RESERVE * RESERVED_THREADS;
        assert_eq!(
            address_space_free(Some(limits), Some(status)),
            Some((4_096_000_000 - 102_400_000 - reserve, 4_096_000_000))
        );
        let unlimited = limits.replace("4096000000", "unlimited");
        assert_eq!(address_space_free(Some(&unlimited), Some(status)), None);
        assert_eq!(cgroup_free(Some("max\n"), Some("5\n")), None);
        assert_eq!(cgroup_free(Some("1000\n"), Some("300\n")), Some(700));
    }
}

#[cfg(test)]
mod loop_tests {
    //! The render loop with a trivial estimator: bit-identical for any thread count and shard
    //! split.
    #![allow(clippy::unwrap_used)]

    use std::sync::atomic::{AtomicU64, Ordering};

    use spectrace_spectrum::Xyz;

    use super::*;
    use crate::{ExactSum, Film, Integrator, Splat, TraceStats};

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

        fn render_chunk(&self, work: ChunkWork, film: &mut dyn Splat) -> TraceStats {
            let mut stats = TraceStats::default();
            let chunk = work.chunk;
            for i in 0..work.items {
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
            error_measure: ErrorMeasure::default(),
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

    /// A noisy estimator: item `i` of chunk `c` splats X = Y = 1 + a hash of `(c, i)` in
    /// `[0, 1)` into pixel `(i % width, 0)`, so that chunks scatter and the error falls with
    /// the items.
    struct Noisy {
        width: u32,
    }

    impl Integrator for Noisy {
        fn name(&self) -> &'static str {
            "noisy"
        }

        fn resolution(&self) -> (u32, u32) {
            (self.width, 1)
        }

        fn render_chunk(&self, work: ChunkWork, film: &mut dyn Splat) -> TraceStats {
            let mut stats = TraceStats::default();
            for i in 0..work.items {
                stats.beams += 1;
                let u = spectrace_sampling::mix64(work.chunk << 32 | i) as f64 / 2f64.powi(64);
                let x = (i % u64::from(self.width)) as u32;
                if film.splat(x, 0, Xyz::new(1.0 + u, 1.0 + u, 0.0)) {
                    stats.splats += 1;
                }
            }
            stats
        }

        fn image_scale(&self, samples_done: u64) -> f64 {
            if samples_done == 0 { 0.0 } else { 4.0 / samples_done as f64 }
        }
    }

    /// Renders `plan` with [`Noisy`], returning the output and the live estimates reported.
    fn observed(plan: &RenderPlan, live: LiveEstimates) -> (RenderOutput, Vec<ErrorEstimate>) {
        let seen = std::sync::Mutex::new(Vec::new());
        let record = |p: &Progress| seen.lock().unwrap().extend(p.estimate);
        let out = render_observed(&Noisy { width: 4 }, plan, &record, live).unwrap();
        (out, seen.into_inner().unwrap())
    }

    #[test]
    fn live_estimates_are_made_only_for_a_reader_or_a_target() {
        // 64 chunks of 100 items on one thread, keeping the error estimate.
        let base =
            RenderPlan { beams: 6400, chunk_beams: 100, error_estimate: true, ..plan(1, None) };
        let (reported, estimates) = observed(&base, LiveEstimates::Reported);
        assert!(estimates.iter().any(|e| e.relative_error.is_some()), "{estimates:?}");
        // Nobody reads them and no target needs them: none is made, and the final estimate
        // (from the same moments) is the same.
        let (unread, none) = observed(&base, LiveEstimates::ForTarget);
        assert!(none.is_empty(), "{none:?}");
        assert_eq!(unread.film, reported.film);
        let measure = base.error_measure;
        let final_error = reported.estimate(measure).unwrap().relative_error.unwrap();
        assert_eq!(unread.estimate(measure).unwrap().relative_error, Some(final_error));
        // A target still stops the render, unread or not, at an estimate that reaches it.
        let target = RenderPlan { target_error: Some(2.0 * final_error), ..base };
        for live in [LiveEstimates::ForTarget, LiveEstimates::Reported] {
            let (out, _) = observed(&target, live);
            let reached = out.estimate(measure).unwrap().relative_error.unwrap();
            assert!(out.beams < base.beams && reached <= 2.0 * final_error, "{live:?}");
        }
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
        integrator.render_chunk(
            ChunkWork { seed: 7, chunk: 3, items: 2, deadline: None, ends_pass: false },
            &mut film,
        );
        assert_eq!(film.to_xyz(1.0)[3], Constant::value(3, 0) + Constant::value(3, 1));
        assert!(render(&Constant { width: 0 }, &plan(1, None), &|_| {}).is_err());
    }
}
