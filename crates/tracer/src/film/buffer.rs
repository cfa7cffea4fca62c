//! [`Film`]: the image (and sensor cells) as exact per-pixel XYZ sums.

use serde::{Deserialize, Serialize};
use spectrace_spectrum::Xyz;

use super::exact::*;
use super::raster::{FilmError, film_pixels, pixel_index, raster_bytes, same_size};
use super::{ExactSum, Splat};

/// A film of `width x height` pixels, each accumulating X, Y, Z exactly, followed by the cells
/// of the scene's sensors (if any), each accumulating `[radiant, luminous, luminous^2]` the same
/// way (see [`crate::SensorSums`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Film {
    pub(super) width: u32,
    pub(super) height: u32,
    /// `[X, Y, Z]` per pixel, row-major from the top-left pixel, then the sensor cells.
    pub(super) sums: Vec<[ExactSum; 3]>,
    /// Contributions that were not finite or out of range (never added).
    pub(super) rejected: u64,
    /// Contributions added.
    pub(super) accepted: u64,
}

impl Film {
    /// An empty film.
    ///
    /// # Errors
    /// [`FilmError::InvalidSize`] for a zero dimension or more than [`crate::MAX_PIXELS`] pixels (each
    /// pixel takes 48 bytes; see [`Film::bytes_for`]).
    pub fn new(width: u32, height: u32) -> Result<Self, FilmError> {
        Self::with_sensor_cells(width, height, 0)
    }

    /// An empty film with `cells` sensor cells after its pixels.
    ///
    /// # Errors
    /// As [`Film::new`].
    pub fn with_sensor_cells(width: u32, height: u32, cells: u32) -> Result<Self, FilmError> {
        let n = film_pixels(width, height)?;
        Ok(Self {
            width,
            height,
            sums: vec![[ExactSum::default(); 3]; n + cells as usize],
            rejected: 0,
            accepted: 0,
        })
    }

    /// The number of sensor cells after the pixels.
    pub fn sensor_cells(&self) -> u32 {
        // A film read from a forged part file may hold fewer sums than its size says.
        self.sums.len().saturating_sub(self.pixels()) as u32
    }

    fn pixels(&self) -> usize {
        self.width as usize * self.height as usize
    }

    /// The sensor cells' sums, `[radiant, luminous, luminous^2]` each, multiplied by `scale`
    /// (the first two) and `scale^2` (the squares).
    pub fn sensor_sums(&self, scale: f64) -> Vec<crate::SensorSums> {
        self.sums
            .get(self.pixels()..)
            .unwrap_or_default()
            .iter()
            .map(|c| [c[0].value() * scale, c[1].value() * scale, c[2].value() * scale * scale])
            .collect()
    }

    /// Adds `[radiant, luminous, luminous^2]` to sensor cell `cell`; `false` (and a rejection)
    /// for a cell beyond the film's or values out of range.
    pub fn add_sensor(&mut self, cell: u32, sums: crate::SensorSums) -> bool {
        let index = self.pixels() + cell as usize;
        match (index < self.sums.len(), xyz_to_fixed(Xyz::new(sums[0], sums[1], sums[2]))) {
            (true, Some(fixed)) => self.add_fixed(index, fixed),
            _ => {
                self.rejected += 1;
                false
            }
        }
    }

    /// Bytes a `width x height` film occupies: 48 per pixel (three `i128` sums) plus the struct.
    pub fn bytes_for(width: u32, height: u32) -> u64 {
        raster_bytes(width, height, PIXEL_BYTES, std::mem::size_of::<Film>())
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Adds an XYZ contribution to pixel `(x, y)` (0-based, from the top-left). Returns `false`
    /// and counts a rejection if the pixel is outside the film or any component is not finite or
    /// out of range; nothing is then added.
    #[inline]
    pub fn add(&mut self, x: u32, y: u32, xyz: Xyz) -> bool {
        match (pixel_index(x, y, self.width, self.height), xyz_to_fixed(xyz)) {
            (Some(index), Some(fixed)) => self.add_fixed(index, fixed),
            _ => {
                self.rejected += 1;
                false
            }
        }
    }

    /// Adds a contribution already in fixed point to pixel `index`: all three components or
    /// none (a rejection is counted when the index is outside or a sum would overflow).
    #[inline]
    pub(super) fn add_fixed(&mut self, index: usize, fixed: [i128; 3]) -> bool {
        let Some(pixel) = self.sums.get_mut(index) else {
            self.rejected += 1;
            return false;
        };
        let sum = |c: usize| pixel[c].0.checked_add(fixed[c]);
        if let (Some(x), Some(y), Some(z)) = (sum(0), sum(1), sum(2)) {
            *pixel = [ExactSum(x), ExactSum(y), ExactSum(z)];
            self.accepted += 1;
            true
        } else {
            self.rejected += 1;
            false
        }
    }

    /// Adds every pixel of `other` (same size) to this film, exactly.
    ///
    /// # Errors
    /// [`FilmError::SizeMismatch`] if the sizes differ.
    pub fn merge(&mut self, other: &Film) -> Result<(), FilmError> {
        same_size(self.width, self.height, (other.width, other.height))?;
        if self.sums.len() != other.sums.len() {
            // Same raster, different sensor cells.
            return Err(FilmError::SizeMismatch(
                self.width,
                self.height,
                other.width,
                other.height,
            ));
        }
        for (a, b) in self.sums.iter_mut().zip(&other.sums) {
            for c in 0..3 {
                if !a[c].merge(b[c]) {
                    self.rejected += 1;
                }
            }
        }
        self.rejected += other.rejected;
        self.accepted += other.accepted;
        Ok(())
    }

    /// The accumulated XYZ of every pixel, row-major, multiplied by `scale` (the estimator's
    /// normalisation, e.g. `1 / beams`).
    pub fn to_xyz(&self, scale: f64) -> Vec<Xyz> {
        self.sums
            .iter()
            .take(self.pixels())
            .map(|p| Xyz::new(p[0].value() * scale, p[1].value() * scale, p[2].value() * scale))
            .collect()
    }

    /// Contributions rejected (non-finite, out of range, or outside the film).
    pub fn rejected(&self) -> u64 {
        self.rejected
    }

    /// Contributions added.
    pub fn accepted(&self) -> u64 {
        self.accepted
    }
}

impl Splat for Film {
    #[inline]
    fn splat(&mut self, x: u32, y: u32, xyz: Xyz) -> bool {
        self.add(x, y, xyz)
    }

    fn splat_sensor(&mut self, cell: u32, sums: crate::SensorSums) -> bool {
        self.add_sensor(cell, sums)
    }
}
