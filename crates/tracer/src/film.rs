//! [`Film`]: per-pixel CIE XYZ accumulated in exact fixed-point sums.
//!
//! Floating-point addition is not associative, so a film summed in a different order (more
//! threads, another chunk order, several machines) would differ in the last bits. Spectrace
//! instead rounds every contribution once to a fixed-point integer with 64 fractional bits and
//! adds integers, which is exact and associative: any split of the work gives a bit-identical
//! image. The cost is a resolution of 2^-64 (5.4e-20) per contribution and a range of 2^62
//! (4.6e18) per pixel sum, both in the film's unscaled units (before the factor `power / beams`);
//! contributions outside the range, NaN and infinities are rejected and counted, never added.

use std::sync::{LazyLock, Mutex, PoisonError};

use serde::{Deserialize, Serialize};
use spectrace_spectrum::{CIE_Y_INTEGRAL, Xyz, cmf};

use crate::estimate::{ChunkTally, Moments};
use crate::raster::{FilmError, film_pixels, pixel_index, raster_bytes, same_size};

/// Fractional bits of the fixed-point sums.
const FRAC_BITS: i32 = 64;
/// `2^FRAC_BITS`.
const SCALE: f64 = (1u128 << FRAC_BITS) as f64;
/// Largest magnitude of one contribution: `2^62`; sums beyond `2^63` are refused as overflow.
const MAX_CONTRIBUTION: f64 = 4_611_686_018_427_387_904.0; // 2^62

/// Bytes of one pixel: three `i128` sums.
const PIXEL_BYTES: u64 = std::mem::size_of::<[ExactSum; 3]>() as u64;

/// `x` rounded once to fixed point, or `None` if it is NaN, infinite or larger in magnitude than
/// 2^62.
#[inline]
fn to_fixed(x: f64) -> Option<i128> {
    (x.abs() <= MAX_CONTRIBUTION).then(|| (x * SCALE).round() as i128)
}

/// A fixed-point value as `f64`, to within a few units in the last place (for the error
/// estimate, which needs no exactness): two 64-bit conversions instead of the slow 128-bit one.
#[inline]
fn fixed_to_f64(v: i128) -> f64 {
    let hi = (v >> 64) as i64 as f64;
    let lo = v as u64 as f64;
    hi + lo * (1.0 / SCALE)
}

/// The three components of `xyz` in fixed point, or `None` if any of them is out of range.
#[inline]
fn xyz_to_fixed(xyz: Xyz) -> Option<[i128; 3]> {
    Some([to_fixed(xyz.x)?, to_fixed(xyz.y)?, to_fixed(xyz.z)?])
}

/// An exact, order-independent sum of `f64` contributions (fixed point, 64 fractional bits).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct ExactSum(i128);

impl ExactSum {
    /// Adds `x`; returns `false` (and adds nothing) if `x` is NaN, infinite or larger in magnitude
    /// than 2^62, or if the sum would overflow.
    #[inline]
    pub fn add(&mut self, x: f64) -> bool {
        let Some(fixed) = to_fixed(x) else { return false };
        match self.0.checked_add(fixed) {
            Some(s) => {
                self.0 = s;
                true
            }
            None => false,
        }
    }

    /// Adds another exact sum; returns `false` on overflow (and leaves `self` unchanged).
    #[inline]
    pub fn merge(&mut self, other: ExactSum) -> bool {
        match self.0.checked_add(other.0) {
            Some(s) => {
                self.0 = s;
                true
            }
            None => false,
        }
    }

    /// The sum as the nearest `f64`.
    pub fn value(self) -> f64 {
        // i128 -> f64 rounds once; the division by a power of two is exact.
        self.0 as f64 / SCALE
    }

    /// The raw fixed-point integer (sum times 2^64).
    pub fn raw(self) -> i128 {
        self.0
    }
}

/// Where contributions go: a [`Film`] directly, or a [`FilmWriter`] that buffers them for a
/// film shared between threads. The light tracer ([`crate::trace_chunk`]) writes through it.
pub trait Splat {
    /// Adds an XYZ contribution to pixel `(x, y)` (0-based, from the top-left); returns `false`
    /// if the pixel is outside the film or a component is NaN, infinite or larger than 2^62
    /// (films and writers then count a rejection and add nothing).
    fn splat(&mut self, x: u32, y: u32, xyz: Xyz) -> bool;

    /// Adds `[radiant, luminous, luminous^2]` to sensor cell `cell` (numbered over all the
    /// scene's sensors, see [`crate::SensorSet`]); same rejections as `splat`. The default, for
    /// targets without sensors, rejects.
    fn splat_sensor(&mut self, cell: u32, sums: crate::SensorSums) -> bool {
        let _ = (cell, sums);
        false
    }

    /// Adds spectral samples to pixel `(x, y)`: `values[j]` at wavelength `lambdas[j]` (nm),
    /// turned into the film's XYZ by [`spectral_xyz`]. Nothing is added (and `false` returned)
    /// when every value is zero; otherwise as [`splat`](Self::splat).
    #[inline]
    fn splat_spectral(&mut self, x: u32, y: u32, lambdas: &[f64], values: &[f64]) -> bool {
        let xyz = spectral_xyz(lambdas, values);
        if xyz.x == 0.0 && xyz.y == 0.0 && xyz.z == 0.0 {
            return false;
        }
        self.splat(x, y, xyz)
    }
}

/// The film's XYZ of spectral samples, the one place colour is made: `sum_j cmf(lambda_j)
/// values[j]` over the integral of `ybar`, so that a spectral radiance of 1 W m^-2 sr^-1 nm^-1
/// at every wavelength gives `Y = 1`. Zero values are skipped (a wavelength outside the
/// matching functions' table contributes nothing).
#[inline]
pub fn spectral_xyz(lambdas: &[f64], values: &[f64]) -> Xyz {
    let inv_y = *INV_Y_INTEGRAL;
    let mut xyz = Xyz::default();
    for (&lambda, &v) in lambdas.iter().zip(values) {
        if v != 0.0 {
            xyz += cmf(lambda) * (v * inv_y);
        }
    }
    xyz
}

/// One over the integral of `ybar` (nm^-1), computed once.
static INV_Y_INTEGRAL: LazyLock<f64> = LazyLock::new(|| 1.0 / *CIE_Y_INTEGRAL);

/// A film of `width x height` pixels, each accumulating X, Y, Z exactly, followed by the cells
/// of the scene's sensors (if any), each accumulating `[radiant, luminous, luminous^2]` the same
/// way (see [`crate::SensorSums`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Film {
    width: u32,
    height: u32,
    /// `[X, Y, Z]` per pixel, row-major from the top-left pixel, then the sensor cells.
    sums: Vec<[ExactSum; 3]>,
    /// Contributions that were not finite or out of range (never added).
    rejected: u64,
    /// Contributions added.
    accepted: u64,
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
    fn add_fixed(&mut self, index: usize, fixed: [i128; 3]) -> bool {
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
    /// Sensor cells after the pixels.
    sensor_cells: u32,
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
        let (width, height, sensor_cells) = {
            let f = film.lock().unwrap_or_else(PoisonError::into_inner);
            (f.width, f.height, f.sensor_cells())
        };
        Self {
            film,
            width,
            height,
            sensor_cells,
            entries: Vec::with_capacity(Self::CAPACITY),
            rejected: 0,
            tally: None,
        }
    }

    /// A writer into `film` that also keeps each chunk's sums and folds them into `moments`
    /// at [`FilmWriter::end_chunk`], for the error estimate ([`Moments`]).
    pub fn with_moments(film: &'a Mutex<Film>, moments: &'a Mutex<Moments>) -> Self {
        let mut writer = Self::new(film);
        writer.tally = Some(ChunkTally::new(moments));
        writer
    }

    /// Ends a chunk of `items` work items: flushes, and folds the chunk's sums into the
    /// moments (if the writer keeps them). Every contribution since the previous call belongs
    /// to this chunk.
    pub fn end_chunk(&mut self, items: u64) {
        self.flush();
        if let Some(t) = &mut self.tally {
            t.end_chunk(items);
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
        self.entries.sort_unstable_by_key(|e| e.0);
        let mut film = self.film.lock().unwrap_or_else(PoisonError::into_inner);
        for &(index, fixed) in &self.entries {
            // Only what the film accepts counts for the estimate.
            if film.add_fixed(index as usize, fixed)
                && let Some(t) = &mut self.tally
            {
                t.add(index as usize, fixed.map(fixed_to_f64));
            }
        }
        film.rejected += self.rejected;
        drop(film);
        self.entries.clear();
        self.rejected = 0;
    }
}

impl Splat for FilmWriter<'_> {
    #[inline]
    fn splat(&mut self, x: u32, y: u32, xyz: Xyz) -> bool {
        match (pixel_index(x, y, self.width, self.height), xyz_to_fixed(xyz)) {
            (Some(index), Some(fixed)) => {
                if self.entries.len() >= Self::CAPACITY {
                    self.flush();
                }
                self.entries.push((index as u32, fixed));
                true
            }
            _ => {
                self.rejected += 1;
                false
            }
        }
    }

    fn splat_sensor(&mut self, cell: u32, sums: crate::SensorSums) -> bool {
        match (cell < self.sensor_cells, xyz_to_fixed(Xyz::new(sums[0], sums[1], sums[2]))) {
            (true, Some(fixed)) => {
                if self.entries.len() >= Self::CAPACITY {
                    self.flush();
                }
                // Sensor cells follow the pixels (at most 2^25 + 2^22 entries: fits u32).
                self.entries.push((self.width * self.height + cell, fixed));
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sums_are_order_independent() {
        let values: Vec<f64> =
            (0..10_000).map(|i| ((i as f64) * 0.7).sin() * 10f64.powi(i % 13 - 6)).collect();
        let mut forward = ExactSum::default();
        let mut backward = ExactSum::default();
        for &v in &values {
            assert!(forward.add(v));
        }
        for &v in values.iter().rev() {
            assert!(backward.add(v));
        }
        assert_eq!(forward, backward);
        // Plain f64 sums in the two orders differ; the exact sum is within 1e-12 of both.
        let f: f64 = values.iter().sum();
        assert!((forward.value() - f).abs() < 1e-9 * f.abs().max(1.0));
    }

    #[test]
    fn non_finite_and_huge_contributions_are_rejected() {
        let mut s = ExactSum::default();
        assert!(!s.add(f64::NAN));
        assert!(!s.add(f64::INFINITY));
        assert!(!s.add(1e19));
        assert!(s.add(4e18));
        assert_eq!(s.value(), 4e18);
        assert!(!s.add(4e18) || !s.add(4e18), "2^63 overflows");
        let mut film = Film::new(2, 2).unwrap();
        assert!(!film.add(0, 0, Xyz::new(1.0, f64::NAN, 0.0)));
        assert!(!film.add(2, 0, Xyz::new(1.0, 1.0, 1.0)));
        assert!(film.add(1, 1, Xyz::new(1.0, 2.0, 3.0)));
        assert_eq!(film.rejected(), 2);
        assert_eq!(film.to_xyz(0.5)[3], Xyz::new(0.5, 1.0, 1.5));
        assert_eq!(film.to_xyz(1.0)[0], Xyz::default());
    }

    #[test]
    fn merged_films_equal_one_film_bit_for_bit() {
        let contributions: Vec<(u32, u32, f64, f64)> = (0..5000)
            .map(|i| ((i * 7) % 8, (i * 3) % 5, 380.0 + (i % 400) as f64, 1.0 / (1.0 + i as f64)))
            .collect();
        let mut one = Film::new(8, 5).unwrap();
        for &(x, y, l, w) in &contributions {
            one.splat_spectral(x, y, &[l], &[w]);
        }
        let mut parts =
            [Film::new(8, 5).unwrap(), Film::new(8, 5).unwrap(), Film::new(8, 5).unwrap()];
        for (k, &(x, y, l, w)) in contributions.iter().enumerate() {
            parts[k % 3].splat_spectral(x, y, &[l], &[w]);
        }
        let mut merged = Film::new(8, 5).unwrap();
        for p in parts.iter().rev() {
            merged.merge(p).unwrap();
        }
        assert_eq!(merged, one);
        assert!(Film::new(8, 5).unwrap().merge(&Film::new(5, 8).unwrap()).is_err());
        assert!(Film::new(0, 5).is_err());
    }

    #[test]
    fn buffered_writers_into_a_shared_film_equal_direct_adds_bit_for_bit() {
        // More contributions than a buffer holds, some of them invalid (NaN, infinite, beyond
        // 2^62, outside the film), written by three interleaved writers.
        let contributions: Vec<(u32, u32, Xyz)> = (0..3 * FilmWriter::CAPACITY as u32 + 77)
            .map(|i| {
                let v = 1.0 / (1.0 + f64::from(i)) * 10f64.powi((i % 9) as i32 - 4);
                let xyz = match i % 101 {
                    0 => Xyz::new(f64::NAN, v, v),
                    1 => Xyz::new(v, f64::INFINITY, v),
                    2 => Xyz::new(v, v, 1e19),
                    _ => Xyz::new(v, 0.5 * v, -0.25 * v),
                };
                ((i * 7) % 13, (i * 3) % 6, xyz)
            })
            .collect();
        let mut direct = Film::new(12, 5).unwrap();
        let mut direct_answers = Vec::new();
        for &(x, y, xyz) in &contributions {
            direct_answers.push(direct.splat(x, y, xyz));
        }
        let shared = Mutex::new(Film::new(12, 5).unwrap());
        let mut buffered_answers = Vec::new();
        {
            let mut writers =
                [FilmWriter::new(&shared), FilmWriter::new(&shared), FilmWriter::new(&shared)];
            for (k, &(x, y, xyz)) in contributions.iter().enumerate().rev() {
                buffered_answers.push(writers[k % 3].splat(x, y, xyz));
            }
            writers[1].flush();
            // The others flush when dropped.
        }
        buffered_answers.reverse();
        assert_eq!(buffered_answers, direct_answers);
        let shared = shared.into_inner().unwrap();
        assert!(direct.rejected() > 0 && direct.accepted() > 3 * FilmWriter::CAPACITY as u64 / 2);
        assert_eq!(shared, direct);
    }

    #[test]
    fn the_quick_fixed_point_conversion_is_within_rounding_of_the_exact_one() {
        for x in [0.0, 1e-19, 0.25, -0.25, 1.0, -3.5, 123_456.789, -9.87e17, 4.6e18, 5e-20] {
            let fixed = to_fixed(x).unwrap();
            let exact = fixed as f64 / SCALE;
            let quick = fixed_to_f64(fixed);
            assert!((quick - exact).abs() <= 4.0 * f64::EPSILON * exact.abs() + 1e-300, "{x}");
        }
    }

    #[test]
    fn sensor_cells_sum_apart_from_the_pixels_and_merge_exactly() {
        let mut direct = Film::with_sensor_cells(3, 2, 4).unwrap();
        assert_eq!(direct.sensor_cells(), 4);
        assert!(direct.add_sensor(3, [1.5, 2.0, 4.0]));
        assert!(!direct.add_sensor(4, [1.0, 1.0, 1.0]), "beyond the cells");
        assert!(!direct.add_sensor(0, [f64::NAN, 0.0, 0.0]));
        assert_eq!(direct.rejected(), 2);
        assert!(direct.add(2, 1, Xyz::new(1.0, 1.0, 1.0)));
        // The image holds only the pixels; the cells come back scaled (squares by scale^2).
        assert_eq!(direct.to_xyz(1.0).len(), 6);
        assert_eq!(direct.sensor_sums(2.0)[3], [3.0, 4.0, 16.0]);
        // Through a buffered writer: bit for bit the same.
        let shared = Mutex::new(Film::with_sensor_cells(3, 2, 4).unwrap());
        {
            let mut w = FilmWriter::new(&shared);
            assert!(w.splat_sensor(3, [1.5, 2.0, 4.0]));
            assert!(!w.splat_sensor(4, [1.0, 1.0, 1.0]));
            assert!(w.splat(2, 1, Xyz::new(1.0, 1.0, 1.0)));
        }
        let shared = shared.into_inner().unwrap();
        assert_eq!(shared.sensor_sums(1.0), direct.sensor_sums(1.0));
        assert_eq!(shared.to_xyz(1.0), direct.to_xyz(1.0));
        // Films with different sensor cells do not merge.
        let mut other = Film::new(3, 2).unwrap();
        assert!(other.merge(&direct).is_err());
        let mut twice = direct.clone();
        twice.merge(&direct).unwrap();
        assert_eq!(twice.sensor_sums(1.0)[3], [3.0, 4.0, 8.0]);
    }

    #[test]
    fn film_bytes_are_48_per_pixel() {
        let b = Film::bytes_for(8192, 4096);
        assert!((48 << 25..(48 << 25) + 1024).contains(&b), "{b}");
        assert_eq!(Film::bytes_for(u32::MAX, u32::MAX), u64::MAX);
    }
}
