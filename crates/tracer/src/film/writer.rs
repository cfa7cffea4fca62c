//! [`FilmWriter`]: a thread's buffered writes to a shared [`Film`], flushed under its lock.

use std::sync::{Mutex, PoisonError};

use spectrace_spectrum::Xyz;

use super::exact::*;
use super::moments::ChunkTally;
use super::moments::Moments;
use super::raster::FilmError;
use super::raster::pixel_index;
use super::{Film, Splat};

/// Films with more pixels than this (48 bytes of sums each: 3 MiB) have a flush's contributions
/// sorted by pixel before they are added.
const SORT_ABOVE_PIXELS: u64 = 1 << 16;

/// One buffered contribution: pixel index and fixed-point XYZ.
type Entry = (u32, [i128; 3]);

/// A thread's writer into a film shared between threads: contributions are checked and rounded
/// to fixed point at once (so `splat` answers exactly as [`Film::add`] would), kept in a buffer
/// of [`FilmWriter::CAPACITY`] entries, and added to the film under its lock when the buffer is
/// full, on [`FilmWriter::flush`] and when the writer is dropped; the buffer is sorted by pixel
/// first, for cache locality. Since the film's sums are exact integers, the result is bit for bit
/// the film that direct adds in any order give, whatever the number of writers.
///
/// One difference: a pixel sum overflowing 2^63 (reachable only with contributions near the
/// 2^62 limit) is found at the flush, so `splat` has already answered `true`; the film counts it
/// as rejected.
#[derive(Debug)]
pub struct FilmWriter<'a> {
    film: &'a Mutex<Film>,
    width: u32,
    height: u32,
    /// Sensor cells after the pixels ([`super::SENSOR_SLOTS`] sums each).
    sensor_cells: u32,
    /// The film has a pass layer (its sums follow the sensor cells).
    pass_layer: bool,
    entries: Vec<Entry>,
    rejected: u64,
    /// The current chunk's sums for the error estimate, if the render keeps one.
    tally: Option<ChunkTally<'a>>,
}

impl<'a> FilmWriter<'a> {
    /// Contributions buffered before a flush (256 KiB: large enough that the lock is rare,
    /// small enough to stay in a core's L2 cache).
    pub const CAPACITY: usize = 4096;

    /// Bytes one writer occupies (its buffer and the struct).
    pub const BYTES: u64 = (Self::CAPACITY * std::mem::size_of::<Entry>()
        + std::mem::size_of::<FilmWriter<'static>>()) as u64;

    /// A writer into `film`.
    pub fn new(film: &'a Mutex<Film>) -> Self {
        let (width, height, sensor_cells, pass_layer) = {
            let f = film.lock().unwrap_or_else(PoisonError::into_inner);
            (f.width, f.height, f.sensor_cells(), f.has_pass_layer())
        };
        Self {
            film,
            width,
            height,
            sensor_cells,
            pass_layer,
            entries: Vec::with_capacity(Self::CAPACITY),
            rejected: 0,
            tally: None,
        }
    }

    /// A writer into `film` that also keeps each chunk's sums and folds them into `moments`
    /// at [`FilmWriter::end_chunk`], for the error estimate ([`Moments`]).
    ///
    /// # Errors
    /// [`FilmError::OutOfMemory`] when the chunk sums' memory (29 bytes per pixel) cannot be
    /// had.
    pub fn with_moments(
        film: &'a Mutex<Film>,
        moments: &'a Mutex<Moments>,
    ) -> Result<Self, FilmError> {
        let mut writer = Self::new(film);
        writer.tally = Some(ChunkTally::new(moments)?);
        Ok(writer)
    }

    /// Ends chunk number `chunk` (its index in the render plan) of `items` work items:
    /// flushes, and folds the chunk's sums into the moments (if the writer keeps them). Every
    /// contribution since the previous call belongs to this chunk.
    pub fn end_chunk(&mut self, chunk: u64, items: u64) {
        self.flush();
        if let Some(t) = &mut self.tally {
            t.end_chunk(chunk, items);
        }
    }

    /// Ends a chunk that was cut short (by a time budget): flushes it into the film but leaves
    /// it out of the moments, since a camera pass cut short samples only part of the image
    /// and is no unbiased estimate of it.
    pub fn discard_chunk(&mut self) {
        self.flush();
        if let Some(t) = &mut self.tally {
            t.discard();
        }
    }

    /// Adds the buffered contributions (and rejections) to the film.
    pub fn flush(&mut self) {
        if self.entries.is_empty() && self.rejected == 0 {
            return;
        }
        // Sorting by pixel makes the adds below sweep a large film in order (its sums far
        // exceed the caches); a small film stays cached and sorting would cost more than it
        // saves. The film's sums are exact, so the order never changes the image.
        if u64::from(self.width) * u64::from(self.height) > SORT_ABOVE_PIXELS {
            self.entries.sort_unstable_by_key(|e| e.0);
        }
        let mut film = self.film.lock().unwrap_or_else(PoisonError::into_inner);
        // Pass-layer sums follow the pixels and the sensor cells; the estimate counts them at
        // their pixel.
        let layer_start = film.pass_index(0);
        let layered = film.has_pass_layer();
        for &(index, fixed) in &self.entries {
            // Only what the film accepts counts for the estimate.
            if film.add_fixed(index as usize, fixed)
                && let Some(t) = &mut self.tally
            {
                let index = index as usize;
                let pixel =
                    if layered && index >= layer_start { index - layer_start } else { index };
                t.add(pixel, fixed.map(fixed_to_f64));
            }
        }
        film.rejected += self.rejected;
        drop(film);
        self.entries.clear();
        self.rejected = 0;
    }
}

impl FilmWriter<'_> {
    /// Buffers a contribution to pixel `(x, y)`, at its pixel sum or (`pass`, with a pass layer)
    /// its pass-layer sum.
    #[inline]
    fn push_pixel(&mut self, x: u32, y: u32, xyz: Xyz, pass: bool) -> bool {
        match (pixel_index(x, y, self.width, self.height), xyz_to_fixed(xyz)) {
            (Some(index), Some(fixed)) => {
                if self.entries.len() >= Self::CAPACITY {
                    self.flush();
                }
                // The pass layer follows the pixels and the sensor cells (at most 2^26 + 2^22
                // entries in all: fits u32).
                let pixels = self.width * self.height;
                let sensor_sums = super::SENSOR_SLOTS as u32 * self.sensor_cells;
                let offset = if pass && self.pass_layer { pixels + sensor_sums } else { 0 };
                self.entries.push((index as u32 + offset, fixed));
                true
            }
            _ => {
                self.rejected += 1;
                false
            }
        }
    }
}

impl Splat for FilmWriter<'_> {
    #[inline]
    fn splat(&mut self, x: u32, y: u32, xyz: Xyz) -> bool {
        self.push_pixel(x, y, xyz, false)
    }

    #[inline]
    fn splat_pass(&mut self, x: u32, y: u32, xyz: Xyz) -> bool {
        self.push_pixel(x, y, xyz, true)
    }

    fn splat_sensor(&mut self, cell: u32, sums: crate::SensorSums) -> bool {
        match (cell < self.sensor_cells, super::sensor_to_fixed(sums)) {
            (true, Some([a, b])) => {
                if self.entries.len() + 1 >= Self::CAPACITY {
                    self.flush();
                }
                // Sensor cells follow the pixels (at most 2^25 + 2^23 entries: fits u32).
                let index = self.width * self.height + super::SENSOR_SLOTS as u32 * cell;
                self.entries.push((index, a));
                self.entries.push((index + 1, b));
                true
            }
            _ => {
                self.rejected += 1;
                false
            }
        }
    }
}

impl Drop for FilmWriter<'_> {
    fn drop(&mut self) {
        self.flush();
    }
}
