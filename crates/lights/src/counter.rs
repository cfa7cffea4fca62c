//! [`BeamCounter`]: counting emitted beams from many threads without a contended atomic.

use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};

/// Number of independent counters; threads are spread over them.
const SLOTS: usize = 16;

/// One counter on its own pair of cache lines, so two threads never share a line.
#[derive(Debug, Default)]
#[repr(align(128))]
struct Slot(AtomicU64);

/// Counts beams across threads: each thread increments its own slot (relaxed, uncontended) and
/// the total is the sum of the slots. Exact once the emitting threads have finished (and at any
/// time from a single thread).
#[derive(Debug, Default)]
pub struct BeamCounter {
    slots: [Slot; SLOTS],
}

/// Hands out slot indices to threads round-robin.
static NEXT_SLOT: AtomicUsize = AtomicUsize::new(0);

thread_local! {
    /// This thread's slot index.
    static THREAD_SLOT: usize = NEXT_SLOT.fetch_add(1, Ordering::Relaxed) % SLOTS;
}

impl BeamCounter {
    /// A counter at zero.
    pub fn new() -> Self {
        Self::default()
    }

    /// Counts one beam.
    #[inline]
    pub fn increment(&self) {
        let slot = THREAD_SLOT.with(|s| *s);
        self.slots[slot].0.fetch_add(1, Ordering::Relaxed);
    }

    /// Counts `n` beams at once (for workers that count locally and report in batches).
    #[inline]
    pub fn add(&self, n: u64) {
        let slot = THREAD_SLOT.with(|s| *s);
        self.slots[slot].0.fetch_add(n, Ordering::Relaxed);
    }

    /// Beams counted so far.
    pub fn total(&self) -> u64 {
        self.slots.iter().map(|s| s.0.load(Ordering::Relaxed)).sum()
    }

    /// Sets the count back to zero (before a new render with the same light).
    pub fn reset(&self) {
        for s in &self.slots {
            s.0.store(0, Ordering::Relaxed);
        }
    }
}

impl Clone for BeamCounter {
    /// A clone is a new light: its count starts at zero.
    fn clone(&self) -> Self {
        Self::new()
    }
}
