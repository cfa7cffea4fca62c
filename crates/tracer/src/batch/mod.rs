//! The batched kernel: many camera paths traced together, stage by stage, instead of one path
//! from its first ray to its end (the scalar kernel, kept as the reference).
//!
//! A chunk's paths ride in a batch of [`LANES`] lanes. Each round of the loop moves every path
//! in the batch one vertex on, through stages that each run over all the lanes before the next
//! begins (pbrt-v4's wavefront queues, kept in a batch small enough to stay in cache):
//! 1. **generate**: free lanes take the chunk's next items (a camera ray, its wavelengths and
//!    the path's own sampler);
//! 2. **intersect**: the closest hit of every lane's ray (one ray at a time through the wide
//!    BVH, whose node and leaf tests are SIMD across a node's children);
//! 3. **shade, grouped by material**: lanes sorted by the primitive they hit, then emission,
//!    the vertex's uniforms and its lobe, and next-event estimation's light samples, which queue
//!    their shadow rays;
//! 4. **shadow rays**: the queue's visibility tests, all together;
//! 5. **connect**: the unoccluded samples' BSDF values, added to their paths;
//! 6. **go on**: each lane's BSDF sample and Russian roulette;
//! 7. **splat**: paths that ended add their sample to the film and free their lane.
//!
//! # Why it gives the scalar kernel's image
//! Each stage calls the scalar kernel's own steps (`PathTracer::arrive`, `connection`,
//! `connect`, `go_on`), and each path draws from its own sampler
//! ([`crate::ChunkSampler::for_path`]) in the order the scalar kernel draws: no path's numbers
//! depend on its lane or on its neighbours. A path's radiance is therefore the same, bit for
//! bit, in either kernel, and the exact film makes the order of splats irrelevant: the batched
//! image is bit-identical to the scalar one (a test asserts it on every shipped scene the path
//! tracer renders).

pub(crate) mod path;

use serde::{Deserialize, Serialize};

/// Which kernel traces camera paths (`settings.kernel` in scene files, `--kernel` on the command
/// line). Both give the same image, bit for bit. The scalar kernel is the default: with every
/// stage still running its steps lane by lane, the batch's bookkeeping costs more than its
/// grouping saves (measured in the README's "Measured figures").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Kernel {
    /// Paths in batches of [`LANES`], stage by stage.
    Batched,
    /// One path at a time from its first ray to its end: the reference, and the default.
    #[default]
    Scalar,
}

impl Kernel {
    /// The name used in scene files, on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            Self::Batched => "batched",
            Self::Scalar => "scalar",
        }
    }

    /// The kernel called `name`, if any.
    pub fn from_name(name: &str) -> Option<Self> {
        [Self::Batched, Self::Scalar].into_iter().find(|k| k.name() == name)
    }
}

/// Paths in one batch.
pub const LANES: usize = 16;
