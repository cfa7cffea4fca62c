//! Which lights next-event estimation samples at a vertex: [`NextEventLights`], built from the
//! scene's `settings.light_sampler` ([`LightSamplerKind`]).
//!
//! | kind | lights sampled at a vertex | cost per vertex | choice depends on the vertex |
//! |---|---|---|---|
//! | `each` | every point, spot, luminaire and sampled parallel light once, plus one area light by power | `O(delta lights)` | no |
//! | `power` | one light of all, by power | `O(log n)` | no |
//! | `tree` | one light of all, by a [`LightTree`] | `O(log n)` | yes |
//! | `auto` | `each` up to [`AUTO_TREE_ABOVE`] lights, `tree` beyond | | |
//!
//! `each` has no variance from the choice of a delta light, and costs a shadow ray per light
//! per vertex: the best for a few lights, and what hangs a scene of thousands. The probability
//! of choosing an area light is exposed by [`NextEventLights::pmf`], which the path tracer's
//! multiple importance sampling asks when a path hits an emitter: the tree's answer depends on
//! the point the path left, like its choice.

use glam::DVec3;
use serde::{Deserialize, Serialize};
use spectrace_lights::{LightId, LightSet};

use crate::light_sampler::{LightSampler, PowerLightSampler};
use crate::light_tree::LightTree;

/// Above this many lights that next-event estimation can sample, `auto` chooses the tree.
pub const AUTO_TREE_ABOVE: usize = 16;

/// How next-event estimation chooses lights (`settings.light_sampler`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LightSamplerKind {
    /// `each` for up to [`AUTO_TREE_ABOVE`] lights, `tree` beyond.
    #[default]
    Auto,
    /// Every delta light once and one area light by power.
    Each,
    /// One light of all by power.
    Power,
    /// One light of all by a light tree.
    Tree,
}

impl LightSamplerKind {
    /// The kind used for `count` lights that next-event estimation can sample: `auto` resolved.
    pub fn resolve(self, count: usize) -> Self {
        match self {
            Self::Auto if count > AUTO_TREE_ABOVE => Self::Tree,
            Self::Auto => Self::Each,
            k => k,
        }
    }

    /// The scene-file name.
    pub fn name(self) -> &'static str {
        match self {
            Self::Auto => "auto",
            Self::Each => "each",
            Self::Power => "power",
            Self::Tree => "tree",
        }
    }
}

/// One light next-event estimation samples: which, with what probability, from what uniforms.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightChoice {
    /// The light.
    pub id: LightId,
    /// The probability it was chosen with (1 for a delta light that `each` samples).
    pub pmf: f64,
    /// The uniforms of the point on it.
    pub u: [f64; 2],
}

/// Next-event estimation's lights (see the module documentation).
#[derive(Debug, Clone)]
pub enum NextEventLights {
    /// Every delta light once, and one area light by power.
    Each {
        /// The delta lights, each sampled at every vertex.
        delta: Vec<LightId>,
        /// The area lights, one chosen per vertex.
        area: PowerLightSampler,
    },
    /// One light of all by power.
    Power(PowerLightSampler),
    /// One light of all by a light tree.
    Tree(LightTree),
}

impl Default for NextEventLights {
    fn default() -> Self {
        Self::Each { delta: Vec::new(), area: PowerLightSampler::default() }
    }
}

impl NextEventLights {
    /// The lights of `kind` over `lights`: `delta` are the delta lights a point can sample,
    /// `is_area` says which lights are sampled by area.
    pub fn new(
        kind: LightSamplerKind,
        lights: &LightSet,
        delta: &[LightId],
        is_area: impl Fn(&dyn spectrace_lights::LightSource) -> bool,
    ) -> Self {
        let mut is_delta = vec![false; lights.lights().len()];
        for id in delta {
            if let Some(f) = is_delta.get_mut(id.0 as usize) {
                *f = true;
            }
        }
        let sampled = |id: LightId, l: &dyn spectrace_lights::LightSource| {
            is_delta.get(id.0 as usize).copied().unwrap_or(false) || is_area(l)
        };
        let count = lights
            .lights()
            .iter()
            .enumerate()
            .filter(|(i, l)| sampled(LightId(*i as u32), l.as_ref()))
            .count();
        match kind.resolve(count) {
            LightSamplerKind::Power => Self::Power(PowerLightSampler::new(lights, sampled)),
            LightSamplerKind::Tree => Self::Tree(LightTree::new(lights, sampled)),
            _ => Self::Each {
                delta: delta.to_vec(),
                area: PowerLightSampler::new(lights, |_, l| is_area(l)),
            },
        }
    }

    /// The kind in use (never `auto`).
    pub fn kind(&self) -> LightSamplerKind {
        match self {
            Self::Each { .. } => LightSamplerKind::Each,
            Self::Power(_) => LightSamplerKind::Power,
            Self::Tree(_) => LightSamplerKind::Tree,
        }
    }

    /// Calls `f` with every light next-event estimation samples at a vertex at `point` with
    /// unit shading normal `normal` (`DVec3::ZERO`: not on a surface) whose light uniforms
    /// are `u`.
    #[inline]
    pub fn for_each(
        &self,
        (point, normal): (DVec3, DVec3),
        u: [f64; 2],
        mut f: impl FnMut(LightChoice),
    ) {
        let chosen = match self {
            Self::Each { delta, area } => {
                for &id in delta {
                    f(LightChoice { id, pmf: 1.0, u: [0.5, 0.5] });
                }
                area.sample(u[0])
            }
            Self::Power(sampler) => sampler.sample(u[0]),
            Self::Tree(tree) => tree.sample((point, normal), u[0]),
        };
        if let Some(c) = chosen {
            f(LightChoice { id: c.id, pmf: c.pmf, u: [c.u, u[1]] });
        }
    }

    /// The probability that next-event estimation at `point` with `normal` chooses light
    /// `id`, a light sampled by area (for the weight of the same light found by a BSDF-sampled
    /// ray).
    #[inline]
    pub fn pmf(&self, (point, normal): (DVec3, DVec3), id: LightId) -> f64 {
        match self {
            Self::Each { area, .. } => area.pmf(id),
            Self::Power(sampler) => sampler.pmf(id),
            Self::Tree(tree) => tree.pmf((point, normal), id),
        }
    }

    /// Whether a vertex makes a choice (and so draws the uniforms for it): some light can be
    /// chosen.
    pub fn chooses(&self) -> bool {
        match self {
            Self::Each { area, .. } => !area.is_empty(),
            Self::Power(sampler) => !sampler.is_empty(),
            Self::Tree(tree) => !tree.is_empty(),
        }
    }
}
