//! [`TraceStats`]: what a chunk of work did (items, hits, splats, paths ended and why), summed
//! over a render and reported.

use serde::{Deserialize, Serialize};

/// Counters of one chunk (or a whole render, summed).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct TraceStats {
    /// Beams emitted.
    pub beams: u64,
    /// Surface hits.
    pub hits: u64,
    /// Connections to the camera that reached the film.
    pub splats: u64,
    /// Beams ended by Russian roulette.
    pub roulette_kills: u64,
    /// Beams that reached `max_depth`.
    pub depth_limited: u64,
    /// Fluorescent re-emissions (a path continuing at a new wavelength).
    #[serde(default)]
    pub reemissions: u64,
}

impl TraceStats {
    /// Adds another chunk's counters.
    pub fn merge(&mut self, o: &TraceStats) {
        self.beams += o.beams;
        self.hits += o.hits;
        self.splats += o.splats;
        self.roulette_kills += o.roulette_kills;
        self.depth_limited += o.depth_limited;
        self.reemissions += o.reemissions;
    }
}
