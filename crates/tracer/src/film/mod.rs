//! [`Film`]: per-pixel CIE XYZ accumulated in exact fixed-point sums.
//!
//! Floating-point addition is not associative, so a film summed in a different order (more
//! threads, another chunk order, several machines) would differ in the last bits. Spectrace
//! instead rounds every contribution once to a fixed-point integer with 64 fractional bits and
//! adds integers, which is exact and associative: any split of the work gives a bit-identical
//! image. The cost is a resolution of 2^-64 (5.4e-20) per contribution and a range of 2^62
//! (4.6e18) per pixel sum, both in the film's unscaled units (before the factor `power / beams`);
//! contributions outside the range, NaN and infinities are rejected and counted, never added.
//!
//! The module's parts: [`ExactSum`] (`exact.rs`), the [`Splat`] trait and [`spectral_xyz`]
//! (`splat.rs`), the [`Film`] itself (`buffer.rs`), a thread's buffered [`FilmWriter`]
//! (`writer.rs`), the chunk [`Moments`] behind the live error estimate (`moments/`, its tests in `moments/tests.rs`), the [`ErrorMeasure`]s it reports in (`measure.rs`) and the
//! pixel-count and size checks every buffer shares (`raster.rs`).

mod buffer;
mod exact;
mod measure;
pub(crate) mod moments;
pub(crate) mod raster;
mod splat;
mod writer;

pub use buffer::Film;

/// Bytes per pixel of the chunk tally each rendering thread keeps for the error estimate (its
/// sums and the list of pixels touched), counted by [`crate::RenderPlan::memory_bytes`].
pub const CHUNK_TALLY_BYTES_PER_PIXEL: u64 = moments::ChunkTally::BYTES_PER_PIXEL;

/// Sums a sensor cell takes in the film: `[radiant, luminous, luminous^2]` and
/// `[melanopic, 0, 0]` (see [`crate::SensorSums`]).
pub const SENSOR_SLOTS: usize = 2;

/// A sensor cell's sums in fixed point, one triple per slot; `None` if any is out of range.
#[inline]
pub(crate) fn sensor_to_fixed(s: crate::SensorSums) -> Option<[[i128; 3]; SENSOR_SLOTS]> {
    use spectrace_spectrum::Xyz;
    let a = exact::xyz_to_fixed(Xyz::new(s[0], s[1], s[2]))?;
    let b = exact::xyz_to_fixed(Xyz::new(s[3], 0.0, 0.0))?;
    Some([a, b])
}
pub use exact::ExactSum;
pub use measure::{ByMeasure, ErrorMeasure, RELMSE_EPSILON, relative_error};
pub use moments::{ErrorEstimate, MAX_TRUSTED_UNCERTAINTY, MIN_BATCHES, Moments};
pub use raster::{FilmError, MAX_PIXELS};
pub use splat::{Splat, spectral_xyz};
pub use writer::FilmWriter;

#[cfg(test)]
mod tests;
