//! [`Film`]: the image (and sensor cells) as exact per-pixel XYZ sums.

use serde::{Deserialize, Serialize};
use spectrace_spectrum::Xyz;

use super::exact::*;
use super::raster::{FilmError, film_pixels, pixel_index, raster_bytes, same_size, try_filled};
use super::{ExactSum, SENSOR_SLOTS, Splat, sensor_to_fixed};

/// A film of `width x height` pixels, each accumulating X, Y, Z exactly, followed by the cells
/// of the scene's sensors (if any), each taking [`SENSOR_SLOTS`] sums the same way (see
/// [`crate::SensorSums`]); optionally a second layer of pixel sums, the *pass layer*,
/// for contributions normalised per pass rather than per pixel sample (see
/// [`Film::with_pass_layer`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Film {
    pub(super) width: u32,
    pub(super) height: u32,
    /// `[X, Y, Z]` per pixel, row-major from the top-left pixel, then the sensor cells
    /// (two each: `[radiant, luminous, luminous^2]`, `[melanopic, 0, 0]`).
    pub(super) sums: Vec<[ExactSum; 3]>,
    /// The pass layer: `[X, Y, Z]` per pixel of contributions normalised per pass (empty when
    /// the film has none).
    #[serde(default)]
    pub(super) pass_sums: Vec<[ExactSum; 3]>,
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
            sums: try_filled(
                n + SENSOR_SLOTS * cells as usize,
                [ExactSum::default(); 3],
                "the film's pixel sums",
            )?,
            pass_sums: Vec::new(),
            rejected: 0,
            accepted: 0,
        })
    }

    /// An empty film with a pass layer: a second sum per pixel for the contributions a camera
    /// estimator normalises per pass (BDPT's light paths splatted to the camera, the path
    /// tracer's point lights seen directly), added by [`Film::add_pass`]. A pass cut short
    /// by a time budget samples some pixels one more time than others; the pixel layer is then
    /// normalised per pixel and the pass layer by the passes' share of work (see
    /// [`crate::camera_image`]). Without the layer, [`Film::add_pass`] adds to the pixel, which
    /// is the same image when every pass is whole.
    ///
    /// `cells` sensor cells follow the pixels, as for [`Film::with_sensor_cells`].
    ///
    /// # Errors
    /// As [`Film::new`].
    pub fn with_pass_layer(width: u32, height: u32, cells: u32) -> Result<Self, FilmError> {
        let mut film = Self::with_sensor_cells(width, height, cells)?;
        film.pass_sums =
            try_filled(film.pixels(), [ExactSum::default(); 3], "the film's pass layer")?;
        Ok(film)
    }

    /// `true` if the film has a pass layer ([`Film::with_pass_layer`]).
    pub fn has_pass_layer(&self) -> bool {
        !self.pass_sums.is_empty()
    }

    /// Adds an XYZ contribution normalised per pass to pixel `(x, y)`: to the pass layer if the
    /// film has one, else to the pixel. Rejections as [`Film::add`].
    #[inline]
    pub fn add_pass(&mut self, x: u32, y: u32, xyz: Xyz) -> bool {
        match (pixel_index(x, y, self.width, self.height), xyz_to_fixed(xyz)) {
            (Some(index), Some(fixed)) => self.add_fixed(self.pass_index(index), fixed),
            _ => {
                self.rejected += 1;
                false
            }
        }
    }

    /// The index [`Film::add_fixed`] takes for pixel `index`'s pass-layer sum: after the pixels
    /// and the sensor cells, or the pixel itself without a pass layer.
    #[inline]
    pub(super) fn pass_index(&self, index: usize) -> usize {
        if self.has_pass_layer() { self.sums.len() + index } else { index }
    }

    /// The number of sensor cells after the pixels.
    pub fn sensor_cells(&self) -> u32 {
        // A film read from a forged part file may hold fewer sums than its size says.
        (self.sums.len().saturating_sub(self.pixels()) / SENSOR_SLOTS) as u32
    }

    /// Sums after the pixels: [`SENSOR_SLOTS`] per sensor cell in a film a render made (a
    /// film read from a file may hold any number; [`Film::sensor_cells`] rounds down).
    pub fn sums_after_pixels(&self) -> usize {
        self.sums.len().saturating_sub(self.pixels())
    }

    fn pixels(&self) -> usize {
        self.width as usize * self.height as usize
    }

    /// The sensor cells' sums, `[radiant, luminous, luminous^2, melanopic]` each, multiplied by
    /// `scale` (the square by `scale^2`).
    pub fn sensor_sums(&self, scale: f64) -> Vec<crate::SensorSums> {
        self.sums
            .get(self.pixels()..)
            .unwrap_or_default()
            .chunks_exact(SENSOR_SLOTS)
            .map(|c| {
                let [a, b] = [c[0], c[1]].map(|s| s.map(ExactSum::value));
                [a[0] * scale, a[1] * scale, a[2] * scale * scale, b[0] * scale]
            })
            .collect()
    }

    /// Adds `[radiant, luminous, luminous^2, melanopic]` to sensor cell `cell`, all or nothing:
    /// `false` (and a rejection) for a cell beyond the film's or values out of range.
    pub fn add_sensor(&mut self, cell: u32, sums: crate::SensorSums) -> bool {
        let index = self.pixels() + SENSOR_SLOTS * cell as usize;
        match (index + 1 < self.sums.len(), sensor_to_fixed(sums)) {
            (true, Some([a, b])) => {
                let fits = |i: usize, f: [i128; 3]| {
                    (0..3).all(|c| self.sums[i][c].0.checked_add(f[c]).is_some())
                };
                if fits(index, a) && fits(index + 1, b) {
                    // Both fit: each slot counts as an accepted sum, as through a FilmWriter.
                    self.add_fixed(index, a) && self.add_fixed(index + 1, b)
                } else {
                    self.rejected += 1;
                    false
                }
            }
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

    /// Bytes a `width x height` film with a pass layer occupies: 96 per pixel plus the struct.
    pub fn bytes_with_pass_layer(width: u32, height: u32) -> u64 {
        raster_bytes(width, height, 2 * PIXEL_BYTES, std::mem::size_of::<Film>())
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

    /// Adds a contribution already in fixed point to sum `index` (the pixels, then the sensor
    /// cells, then the pass layer: see [`Film::pass_index`]): all three components or none (a
    /// rejection is counted when the index is outside or a sum would overflow).
    #[inline]
    pub(super) fn add_fixed(&mut self, index: usize, fixed: [i128; 3]) -> bool {
        let n = self.sums.len();
        let slot =
            if index < n { self.sums.get_mut(index) } else { self.pass_sums.get_mut(index - n) };
        let Some(pixel) = slot else {
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
        if self.sums.len() != other.sums.len() || self.pass_sums.len() != other.pass_sums.len() {
            // Same raster, different sensor cells or pass layers.
            let total = |f: &Film| (f.sums.len() + f.pass_sums.len()) as u64;
            return Err(FilmError::LayerMismatch(total(self), total(other)));
        }
        let layers = self.sums.iter_mut().chain(self.pass_sums.iter_mut());
        for (a, b) in layers.zip(other.sums.iter().chain(&other.pass_sums)) {
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
    /// normalisation, e.g. `1 / beams`); a pixel's pass-layer sum is added to it exactly first
    /// (the image when every pass is whole).
    pub fn to_xyz(&self, scale: f64) -> Vec<Xyz> {
        let value = |p: &[ExactSum; 3], c: usize, q: Option<&[ExactSum; 3]>| {
            let sum = q.map_or(p[c].0, |q| p[c].0.saturating_add(q[c].0));
            ExactSum(sum).value() * scale
        };
        self.sums
            .iter()
            .take(self.pixels())
            .enumerate()
            .map(|(i, p)| {
                let q = self.pass_sums.get(i);
                Xyz::new(value(p, 0, q), value(p, 1, q), value(p, 2, q))
            })
            .collect()
    }

    /// The XYZ of every pixel, row-major, with each layer normalised on its own: pixel `i`'s
    /// sum times `pixel_scale(i)` plus its pass-layer sum times `pass_scale` (a film without
    /// a pass layer has only the first).
    pub fn to_xyz_layers(&self, pixel_scale: impl Fn(usize) -> f64, pass_scale: f64) -> Vec<Xyz> {
        let xyz = |p: &[ExactSum; 3], s: f64| {
            Xyz::new(p[0].value() * s, p[1].value() * s, p[2].value() * s)
        };
        let none = [ExactSum::default(); 3];
        (0..self.pixels())
            .map(|i| {
                let pixel = self.sums.get(i).map_or(Xyz::default(), |p| xyz(p, pixel_scale(i)));
                pixel + xyz(self.pass_sums.get(i).unwrap_or(&none), pass_scale)
            })
            .collect()
    }

    /// Checks what a render always leaves: at least the pixels' sums, a pass layer of exactly
    /// the pixels' size or none, and no negative sum (light adds, it never subtracts); for a
    /// film read from a file.
    ///
    /// # Errors
    /// What is wrong, in words.
    pub fn check_sums(&self) -> Result<(), String> {
        let pixels = self.pixels();
        if self.sums.len() < pixels {
            return Err(format!("holds {} sums for {pixels} pixels", self.sums.len()));
        }
        if !self.pass_sums.is_empty() && self.pass_sums.len() != pixels {
            return Err(format!(
                "its pass layer holds {} sums for {pixels} pixels",
                self.pass_sums.len()
            ));
        }
        let negative = |sums: &[[ExactSum; 3]]| sums.iter().position(|p| p.iter().any(|c| c.0 < 0));
        if let Some(i) = negative(&self.sums) {
            return Err(format!(
                "sum {i} is negative ({:?}): light adds, it never subtracts",
                self.sums[i].map(ExactSum::value)
            ));
        }
        if let Some(i) = negative(&self.pass_sums) {
            return Err(format!(
                "pass-layer sum {i} is negative ({:?}): light adds, it never subtracts",
                self.pass_sums[i].map(ExactSum::value)
            ));
        }
        Ok(())
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

    #[inline]
    fn splat_pass(&mut self, x: u32, y: u32, xyz: Xyz) -> bool {
        self.add_pass(x, y, xyz)
    }

    fn splat_sensor(&mut self, cell: u32, sums: crate::SensorSums) -> bool {
        self.add_sensor(cell, sums)
    }
}
