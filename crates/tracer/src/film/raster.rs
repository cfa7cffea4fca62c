//! The film's raster rules, which the film and the error estimate share: how many pixels a film
//! may have, the pixel index of a coordinate, and [`FilmError`]. Depends on nothing else of the
//! crate, so that [`crate::Film`] and [`crate::Moments`] need not depend on each other for it.

use spectrace_geometry::human_bytes;

/// Most pixels a film may have: 2^25 (33.5 million, e.g. 8192 x 4096), 1.6 GB of sums.
pub const MAX_PIXELS: u64 = 1 << 25;

/// Why a film operation failed.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum FilmError {
    /// Two films of different sizes cannot be merged.
    #[error("film sizes differ: {0}x{1} vs {2}x{3}")]
    SizeMismatch(u32, u32, u32, u32),
    /// Two films of one size with different sensor cells or pass layers cannot be merged.
    #[error(
        "films of one size differ in their sensor cells or pass layer ({0} and {1} sums): not parts of one render"
    )]
    LayerMismatch(u64, u64),
    /// A width or height of zero, or a pixel count that does not fit in memory.
    #[error(
        "film size {0}x{1} is invalid: both must be at least 1 and their product at most 2^25 (33.5 million pixels)"
    )]
    InvalidSize(u32, u32),
    /// The render needs more memory than it may use; nothing was allocated.
    #[error(
        "a {width}x{height} film (camera.width x camera.height) needs {} ({}), more than the {} a render may use ({limit_source}); lower the camera's resolution",
        human_bytes(*needed),
        breakdown,
        human_bytes(*limit)
    )]
    TooLarge {
        /// Film width.
        width: u32,
        /// Film height.
        height: u32,
        /// Bytes the render needs.
        needed: u64,
        /// What those bytes are.
        breakdown: String,
        /// Bytes it may use.
        limit: u64,
        /// Where the limit comes from.
        limit_source: String,
    },
    /// The system refused memory the plan had counted on (another process took it, or a limit
    /// the plan could not see); nothing was rendered.
    #[error(
        "could not allocate {} for {what}: the system refused it; lower the camera's resolution or --threads, or free memory",
        human_bytes(*bytes)
    )]
    OutOfMemory {
        /// What the memory was for.
        what: &'static str,
        /// Bytes asked for.
        bytes: u64,
    },
}

/// `n` copies of `value` in a vector whose memory is reserved fallibly, so that a refusal is an
/// error naming `what` instead of an abort.
///
/// # Errors
/// [`FilmError::OutOfMemory`].
pub(crate) fn try_filled<T: Clone>(
    n: usize,
    value: T,
    what: &'static str,
) -> Result<Vec<T>, FilmError> {
    let mut v = Vec::new();
    v.try_reserve_exact(n).map_err(|_| FilmError::OutOfMemory {
        what,
        bytes: (n as u64).saturating_mul(std::mem::size_of::<T>() as u64),
    })?;
    v.resize(n, value);
    Ok(v)
}

/// The pixel count of a `width x height` film (or of its error-estimate moments).
///
/// # Errors
/// [`FilmError::InvalidSize`] for a zero dimension or more than [`MAX_PIXELS`] pixels.
pub(crate) fn film_pixels(width: u32, height: u32) -> Result<usize, FilmError> {
    let n = u64::from(width) * u64::from(height);
    if width == 0 || height == 0 || n > MAX_PIXELS {
        return Err(FilmError::InvalidSize(width, height));
    }
    // At most 2^25: fits in usize.
    Ok(n as usize)
}

/// The row-major index of pixel `(x, y)`, if it lies on a `width x height` film.
#[inline]
pub(crate) fn pixel_index(x: u32, y: u32, width: u32, height: u32) -> Option<usize> {
    // Films have at most 2^25 pixels, so the index fits in u32 and usize.
    (x < width && y < height).then(|| (y * width + x) as usize)
}

/// Bytes of a `width x height` raster of `per_pixel` bytes a pixel plus `fixed` bytes: saturates
/// instead of overflowing, so that a memory check refuses absurd sizes rather than wrapping.
pub(crate) fn raster_bytes(width: u32, height: u32, per_pixel: u64, fixed: usize) -> u64 {
    (u64::from(width) * u64::from(height)).saturating_mul(per_pixel).saturating_add(fixed as u64)
}

/// `Ok` when a `width x height` raster and an `other_width x other_height` one have the same
/// size, else [`FilmError::SizeMismatch`] naming both.
pub(crate) fn same_size(width: u32, height: u32, other: (u32, u32)) -> Result<(), FilmError> {
    if (width, height) == other {
        Ok(())
    } else {
        Err(FilmError::SizeMismatch(width, height, other.0, other.1))
    }
}
