//! Exact inverse-CDF generators: the weighted random generators of the Spectrace seed (section 2.2),
//! made numerically exact.
//!
//! This crate is the bottom layer of Spectrace and depends on nothing else of ours. Spectra
//! (`spectrace-spectrum`) use it to draw wavelengths in proportion to a spectral power distribution,
//! lights (`spectrace-lights`) to draw emission directions from angular profiles, and the renderer
//! to pick lights by power. It offers five generators, each built once from a table by a
//! constructor that validates the table and returns a [`Result`], then immutable and shared:
//!
//! | type | what it samples | cost per sample |
//! |---|---|---|
//! | [`Discrete`] | an index, by cumulative sums and bisection (the seed's first method) | `O(log n)` |
//! | [`AliasTable`] | an index, by Walker/Vose alias tables | `O(1)` |
//! | [`PiecewiseConstant`] | a real in bins of constant density (the seed's "choppy" generator) | `O(log n)` |
//! | [`PiecewiseLinear`] | a real under a piecewise-linear density (seed 2.2.1) | `O(log n)` |
//! | [`PiecewiseBilinear`] | a point under a density bilinear in each cell of a 2-D grid | `O(log n + log m)` |
//!
//! Samplers take an explicit uniform `u` in `[0, 1)` (`sample(&self, u)`), so stratified and
//! low-discrepancy sequences can drive them and results are reproducible; each also implements
//! [`rand::distr::Distribution`] so `rng.sample(&d)` works. The inverse-CDF samplers are monotone in
//! `u`. A `u` outside `[0, 1)` or NaN is a caller bug: debug builds assert, release builds clamp.
//!
//! The key design decision is numerical: the piecewise-linear in-segment quadratic is solved in a
//! form with no division by the slope and no cancellation (see [`PiecewiseLinear`]), tables are
//! rescaled by exact powers of two (so subnormal and 1e300-sized weights keep full precision) and
//! summed with compensation, and zero-mass entries and segments can never be returned. Bad tables
//! produce a [`SamplingError`] naming the array and index at fault.
//!
//! Below the generators sit the geometric helpers that lights and materials share, so each exists
//! once: [`Frame`], an orthonormal basis around a unit normal (Duff et al. 2017) with `to_world`
//! and `to_local`; the [`warp`] module, pbrt-style triples of `sample_*` (unit square to disk,
//! cosine-weighted or uniform hemisphere, sphere, cone; directions in a local space about `+z`),
//! `pdf_*` and, where natural, `invert_*`; and the uniform helpers [`uniform`] (53 random bits from
//! any generator) and [`clamp_uniform`] (a tolerant clamp into `[0, 1)`). Warps clamp their
//! uniforms instead of asserting, and narrow cones are described by `1 - cos` (computed without
//! cancellation by [`one_minus_cos`]) rather than by `cos`.
//!
//! [`SobolSampler`] serves Owen-scrambled Sobol points (through the `sobol_burley` crate) as a
//! [`rand::Rng`], one dimension per draw of a path, for renderers that want low-discrepancy
//! sampling without changing the code that draws the uniforms.
//!
//! Tables find the cell holding a point with [`GridLocator`] (a guess by even spacing, for the
//! evenly spaced tables spectra usually are) or [`GuideTable`] (a guess per cell of an even
//! subdivision, for grids like the cosines of candela tables' angles); both always answer as a
//! binary search would.
//!
//! The [`files`] module holds the bounded reading of input files that every crate reading one
//! shares (it is here because this is the lowest crate).
//!
//! The [`stats`] module holds the chi-square and Kolmogorov-Smirnov harness that every Spectrace
//! crate uses in its statistical tests.

mod alias;
mod discrete;
mod error;
pub mod files;
mod frame;
mod grid;
mod piecewise_bilinear;
mod piecewise_constant;
mod piecewise_linear;
mod sobol;
pub mod stats;
mod table;
mod trig;
mod uniform;
pub mod warp;

pub use alias::AliasTable;
pub use discrete::Discrete;
pub use error::SamplingError;
pub use frame::Frame;
pub use grid::{GridLocator, GuideTable, cell_index};
pub use piecewise_bilinear::PiecewiseBilinear;
pub use piecewise_constant::PiecewiseConstant;
pub use piecewise_linear::{PiecewiseLinear, linear_segment_inverse};
pub use sobol::{SOBOL_BLOCK, SOBOL_DIMENSIONS, SobolSampler};
pub use table::ONE_MINUS_EPSILON;
pub use trig::sin_cos_turn;
pub use uniform::{GOLDEN_GAMMA, clamp_uniform, mix64, shifted_uniform, split_mix64, uniform};
pub use warp::{
    invert_cosine_hemisphere, invert_cosine_hemisphere_concentric, invert_uniform_cone,
    invert_uniform_disk_concentric, invert_uniform_hemisphere, invert_uniform_sphere,
    one_minus_cos, pdf_cosine_hemisphere, pdf_uniform_cone, pdf_uniform_disk_concentric,
    pdf_uniform_hemisphere, pdf_uniform_sphere, sample_cosine_hemisphere,
    sample_cosine_hemisphere_concentric, sample_uniform_cone, sample_uniform_disk_concentric,
    sample_uniform_hemisphere, sample_uniform_sphere, sin_from_cos, spherical_direction,
    spherical_direction_turn,
};
