//! Exact inverse-CDF generators: the weighted random generators of the Spectrace seed (section 2.2),
//! made numerically exact.
//!
//! This crate is the bottom layer of Spectrace and depends on nothing else of ours. Spectra
//! (`spectrace-spectrum`) use it to draw wavelengths in proportion to a spectral power distribution,
//! lights (`spectrace-lights`) to draw emission directions from angular profiles, and the renderer
//! to pick lights by power. It offers four generators, each built once from a table by a
//! constructor that validates the table and returns a [`Result`], then immutable and shared:
//!
//! | type | what it samples | cost per sample |
//! |---|---|---|
//! | [`Discrete`] | an index, by cumulative sums and bisection (the seed's first method) | `O(log n)` |
//! | [`AliasTable`] | an index, by Walker/Vose alias tables | `O(1)` |
//! | [`PiecewiseConstant`] | a real in bins of constant density (the seed's "choppy" generator) | `O(log n)` |
//! | [`PiecewiseLinear`] | a real under a piecewise-linear density (seed 2.2.1) | `O(log n)` |
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
//! The [`stats`] module holds the chi-square and Kolmogorov-Smirnov harness that every Spectrace
//! crate uses in its statistical tests.

mod alias;
mod discrete;
mod error;
mod piecewise_constant;
mod piecewise_linear;
pub mod stats;
mod table;

pub use alias::AliasTable;
pub use discrete::Discrete;
pub use error::SamplingError;
pub use piecewise_constant::PiecewiseConstant;
pub use piecewise_linear::{PiecewiseLinear, linear_segment_inverse};
pub use table::ONE_MINUS_EPSILON;
