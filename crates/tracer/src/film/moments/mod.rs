//! How accurate an image is, measured while it renders: the spread between independent chunks.
//!
//! Every chunk of a render ([`crate::RenderPlan`]) draws its random numbers from its own stream,
//! so the chunk images `I_c = k S_c / n_c` (`S_c` the chunk's film sums, `n_c` its work items,
//! `k` the estimator's normalisation) are independent, unbiased estimates of the same image, and
//! the image itself is their item-weighted mean `I = k S / N`. [`Moments`] keeps, per pixel, the
//! sums `S = Σ S_c` and the second moments `Q = Σ S_c S_cᵀ / n_c` (X, Y, Z and their cross terms)
//! of the chunks finished so far; from them the variance of every pixel of `I` is
//!
//! ```text
//! Var(I) = k² (Q - S Sᵀ / N) / ((C - 1) N) = s² (N Q - S Sᵀ) / (C - 1),   s = k / N,
//! ```
//!
//! (`C` chunks; exact for equal chunk sizes, the usual weighted estimate otherwise). The chunks
//! are the batches of a batch-means estimate: [`MIN_BATCHES`] of them are needed before a
//! render may stop on a target. The image's relative RMSE, the measure of the accuracy report
//! (`sqrt(Σ|I - T|² / Σ|T|²)` over all pixels and X, Y, Z against the converged image `T`), is
//! estimated by `sqrt(Σ Var / (Σ I² - Σ Var))`: `Σ I² - Σ Var` is an unbiased estimate of
//! `Σ T²`. The normalisation `k` cancels, so the estimate needs no knowledge of the estimator.
//!
//! The per-pixel relative measure (`relmse`) divides each pixel's variance by its square, and
//! a firefly raises both together: from the same chunks, their ratio hardly sees it. So the
//! moments also keep the sums of a pseudo-random half of the chunks, and each half's variance is
//! divided by the other half's square, where that square is known well enough
//! (`SPLIT_TRUST`) and not far below the image's own (`SPLIT_FLOOR`). The two halves also
//! give the relmse its uncertainty without assuming normal chunk values: how much they
//! disagree (`split_degrees_of_freedom`).
//!
//! What no estimate from the chunks can see: a pixel that a rare kind of path lights now and
//! then (the edge of a hard-edged spot, where a pixel is lit by a few percent of its area) and
//! that no chunk has reached yet. Its value is 0 in every chunk, so is its estimated error, and
//! its true relative error is about 1. Where such pixels and the pixels with one or two such
//! hits hold much of the image's error, the true relmse of one render scatters widely about
//! the estimate (the fading spot at 480x300, 16 passes: estimated 5.3%, true 4.0% to 6.5% over
//! three seeds; at 4 passes 14% against 9% to 24%).
//!
//! What it cannot see: bias. Light an estimator cannot reach (a path tracer and a laser) is
//! missing from every chunk alike. With the Sobol sampler and a camera integrator, the passes of
//! a pixel are points of one sequence, not independent, and the estimate is the independent
//! sampler's error: an upper bound on the true one.

use std::sync::{Mutex, PoisonError};

use serde::{Deserialize, Serialize};
use spectrace_spectrum::Xyz;

use super::measure::{ByMeasure, ErrorMeasure, RELMSE_EPSILON};
use super::raster::{FilmError, film_pixels, raster_bytes, same_size, try_filled};

/// Chunks (batches) a render needs before its error estimate is trusted to stop it.
pub const MIN_BATCHES: u64 = 16;

/// Bytes [`Moments`] keeps per pixel: nine `f64` of all chunks and six of the first half.
const MOMENT_BYTES: u64 = (9 + 6) * 8;

/// Per-pixel first and second moments of the chunk sums of a render (see the module essay).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Moments {
    width: u32,
    height: u32,
    /// Per pixel: `[Sx, Sy, Sz, Qxx, Qyy, Qzz, Qxy, Qxz, Qyz]`.
    sums: Vec<[f64; 9]>,
    /// Per pixel, of the chunks of the first half only ([`Moments::in_first_half`]) of the split-half relmse
    /// estimate; the odd half is `sums` less these): `[Sx, Sy, Sz, Qr, Qg, Qb]`, `Q` the
    /// linear-sRGB channels' second moments.
    first: Vec<[f64; 6]>,
    /// Chunks folded in.
    chunks: u64,
    /// Work items of those chunks.
    items: u64,
    /// Chunks and work items of the first half folded in.
    first_chunks: [u64; 2],
    /// Running totals over the pixels, kept as chunks are folded in, for an estimate in O(1)
    /// ([`Moments::quick_estimate`]): `Σ (Qxx + Qyy + Qzz)` and `Σ (Sx² + Sy² + Sz²)`.
    /// Derived data: not stored in part files, recomputed after a merge.
    #[serde(skip)]
    totals: [f64; 2],
}

/// The estimated accuracy of an image.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ErrorEstimate {
    /// The measure of the headline figure, [`ErrorEstimate::relative_error`].
    pub measure: ErrorMeasure,
    /// Estimated relative error against the converged image in `measure`; `None` with fewer
    /// than two chunks or when the noise is as large as the signal.
    pub relative_error: Option<f64>,
    /// The estimate in every measure.
    pub by_measure: ByMeasure,
    /// Chunks (independent batches) the estimate comes from.
    pub batches: u64,
    /// Work items (beams or camera samples) of those chunks.
    pub items: u64,
    /// Effective degrees of freedom of the headline: for `energy` and `mean` of the variance
    /// estimate (Welch-Satterthwaite over the pixels and channels); for `relmse` from the two
    /// halves' disagreement (see `split_degrees_of_freedom`). The relative uncertainty is
    /// `1 / sqrt(2 dof)`.
    pub degrees_of_freedom: f64,
}

/// Largest relative uncertainty (one sigma) of a trusted estimate.
pub const MAX_TRUSTED_UNCERTAINTY: f64 = 0.1;

impl ErrorEstimate {
    /// The relative standard deviation of [`ErrorEstimate::relative_error`] itself (one
    /// sigma): `1 / sqrt(2 dof)`; infinite without degrees of freedom.
    pub fn relative_uncertainty(&self) -> f64 {
        if self.degrees_of_freedom > 0.0 {
            (2.0 * self.degrees_of_freedom).sqrt().recip()
        } else {
            f64::INFINITY
        }
    }

    /// The estimate's one-sigma interval, `relative_error x (1 -/+ relative_uncertainty)`
    /// (the lower end at least 0).
    pub fn interval(&self) -> Option<(f64, f64)> {
        let e = self.relative_error?;
        let u = self.relative_uncertainty();
        u.is_finite().then(|| ((e * (1.0 - u)).max(0.0), e * (1.0 + u)))
    }

    /// `true` once the estimate comes from at least [`MIN_BATCHES`] chunks and its own
    /// relative uncertainty is below [`MAX_TRUSTED_UNCERTAINTY`].
    pub fn is_trusted(&self) -> bool {
        self.batches >= MIN_BATCHES
            && self.relative_error.is_some()
            && self.relative_uncertainty() < MAX_TRUSTED_UNCERTAINTY
    }
}

impl Moments {
    /// Empty moments for a `width x height` film.
    ///
    /// # Errors
    /// [`FilmError::InvalidSize`] as for [`crate::Film::new`].
    pub fn new(width: u32, height: u32) -> Result<Self, FilmError> {
        let n = film_pixels(width, height)?;
        Ok(Self {
            width,
            height,
            sums: try_filled(n, [0.0; 9], "the error estimate's moments")?,
            first: try_filled(n, [0.0; 6], "the error estimate's moments")?,
            chunks: 0,
            items: 0,
            first_chunks: [0; 2],
            totals: [0.0; 2],
        })
    }

    /// Bytes the moments of a `width x height` film occupy (120 per pixel).
    pub fn bytes_for(width: u32, height: u32) -> u64 {
        raster_bytes(width, height, MOMENT_BYTES, std::mem::size_of::<Moments>())
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Chunks folded in.
    pub fn chunks(&self) -> u64 {
        self.chunks
    }

    /// Work items of the chunks folded in.
    pub fn items(&self) -> u64 {
        self.items
    }

    /// Chunks and work items of the first half folded in (see [`Moments::in_first_half`]).
    pub fn first_half_chunks(&self) -> [u64; 2] {
        self.first_chunks
    }

    /// Whether chunk number `chunk` belongs to the first half of the split-half estimate: the
    /// top bit of the chunk number times the golden ratio's 64-bit fraction, so that the chunks
    /// of every shard (every `n`-th chunk) fall into both halves alike.
    pub fn in_first_half(chunk: u64) -> bool {
        chunk.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 63 == 0
    }

    /// Folds in finished chunk number `chunk` (its index in the render plan, which decides its
    /// half of the split-half estimate) of `items` work items whose film sums are `pixels`
    /// (`(index, [X, Y, Z])`, every pixel at most once; pixels not listed received nothing).
    pub fn add_chunk(
        &mut self,
        chunk: u64,
        pixels: impl IntoIterator<Item = (usize, [f64; 3])>,
        items: u64,
    ) {
        let first = Self::in_first_half(chunk);
        self.chunks += 1;
        self.items = self.items.saturating_add(items);
        if first {
            self.first_chunks[0] += 1;
            self.first_chunks[1] = self.first_chunks[1].saturating_add(items);
        }
        if items == 0 {
            return;
        }
        let inv = 1.0 / items as f64;
        let rows = srgb_rows();
        let [mut q, mut s2] = self.totals;
        for (index, [x, y, z]) in pixels {
            let (Some(m), Some(h)) = (self.sums.get_mut(index), self.first.get_mut(index)) else {
                continue;
            };
            if first {
                let rgb = rows.map(|r| dot(&r, &[x, y, z]));
                for (k, v) in [x, y, z].into_iter().chain(rgb.map(|c| c * c * inv)).enumerate() {
                    h[k] += v;
                }
            }
            // (S + s)^2 - S^2 = s (2 S + s), per channel.
            s2 += x * (2.0 * m[0] + x) + y * (2.0 * m[1] + y) + z * (2.0 * m[2] + z);
            q += (x * x + y * y + z * z) * inv;
            m[0] += x;
            m[1] += y;
            m[2] += z;
            m[3] += x * x * inv;
            m[4] += y * y * inv;
            m[5] += z * z * inv;
            m[6] += x * y * inv;
            m[7] += x * z * inv;
            m[8] += y * z * inv;
        }
        self.totals = [q, s2];
    }

    /// The chunk and item counts, with no error estimated yet.
    fn no_estimate(&self, measure: ErrorMeasure) -> ErrorEstimate {
        ErrorEstimate {
            measure,
            relative_error: None,
            by_measure: ByMeasure::default(),
            batches: self.chunks,
            items: self.items,
            degrees_of_freedom: 0.0,
        }
    }

    /// The estimated [`ErrorMeasure::Energy`] error from the running totals, in O(1) (the
    /// live estimate while rendering in that measure; [`Moments::estimate`] is the exact sum
    /// over the pixels, with the degrees of freedom and every measure). Equal to it up to
    /// rounding, except that it does not clamp a pixel's variance at zero;
    /// `degrees_of_freedom` is left at 0 and the other measures at `None`.
    pub fn quick_estimate(&self) -> ErrorEstimate {
        let mut estimate = self.no_estimate(ErrorMeasure::Energy);
        if self.chunks < 2 || self.items == 0 {
            return estimate;
        }
        let [q, s2] = self.totals;
        let variance = ((self.items as f64 * q - s2) / (self.chunks - 1) as f64).max(0.0);
        let truth = s2 - variance;
        if truth > 0.0 && variance.is_finite() {
            estimate.relative_error = Some((variance / truth).sqrt());
            estimate.by_measure.energy = estimate.relative_error;
        }
        estimate
    }

    /// Recomputes the running totals from the per-pixel moments.
    fn recompute_totals(&mut self) {
        let (mut q, mut s2) = (0.0, 0.0);
        for m in &self.sums {
            q += m[3] + m[4] + m[5];
            s2 += m[0] * m[0] + m[1] * m[1] + m[2] * m[2];
        }
        self.totals = [q, s2];
    }

    /// Adds another render's moments (same size; their chunks must be other chunks of the
    /// same image, e.g. another shard).
    ///
    /// # Errors
    /// [`FilmError::SizeMismatch`] when the sizes differ.
    pub fn merge(&mut self, other: &Moments) -> Result<(), FilmError> {
        same_size(self.width, self.height, (other.width, other.height))?;
        for (a, b) in self.sums.iter_mut().zip(&other.sums) {
            for (x, y) in a.iter_mut().zip(b) {
                *x += y;
            }
        }
        for (a, b) in self.first.iter_mut().zip(&other.first) {
            for (x, y) in a.iter_mut().zip(b) {
                *x += y;
            }
        }
        self.first_chunks[0] += other.first_chunks[0];
        self.first_chunks[1] = self.first_chunks[1].saturating_add(other.first_chunks[1]);
        self.chunks += other.chunks;
        self.items = self.items.saturating_add(other.items);
        self.recompute_totals();
        Ok(())
    }

    /// Checks moments read from a file: one entry per pixel, every value finite, sums of
    /// light never negative.
    ///
    /// # Errors
    /// What is wrong, in words.
    pub fn validate(&self) -> Result<(), String> {
        let pixels = u64::from(self.width) * u64::from(self.height);
        if self.sums.len() as u64 != pixels || self.first.len() as u64 != pixels {
            return Err(format!(
                "holds {} and {} pixels, but a {}x{} image has {pixels}",
                self.sums.len(),
                self.first.len(),
                self.width,
                self.height
            ));
        }
        let [first, first_items] = self.first_chunks;
        if first > self.chunks || first_items > self.items {
            return Err(format!(
                "{first} chunks of {first_items} items in the first half, more than all {} chunks of {} items",
                self.chunks, self.items
            ));
        }
        let valid = |m: &[f64]| m.iter().all(|v| v.is_finite()) && m[..3].iter().all(|&v| v >= 0.0);
        if let Some(i) =
            self.sums.iter().zip(&self.first).position(|(m, h)| !(valid(m) && valid(h)))
        {
            return Err(format!("pixel {i}: a value is not finite, or a sum of light is negative"));
        }
        Ok(())
    }

    /// The covariance of X, Y, Z of pixel `m` times `(C - 1) / s²`: `N Q - S Sᵀ` as
    /// `[xx, yy, zz, xy, xz, yz]`, the diagonal clamped at 0 (rounding can make a noiseless
    /// pixel's slightly negative).
    fn scaled_covariance(&self, m: &[f64; 9]) -> [f64; 6] {
        let n = self.items as f64;
        let [sx, sy, sz] = [m[0], m[1], m[2]];
        [
            (n * m[3] - sx * sx).max(0.0),
            (n * m[4] - sy * sy).max(0.0),
            (n * m[5] - sz * sz).max(0.0),
            n * m[6] - sx * sy,
            n * m[7] - sx * sz,
            n * m[8] - sy * sz,
        ]
    }

    /// The estimated relative error of the image these chunks make in every measure, with
    /// `measure` as the headline (see the module essay).
    pub fn estimate(&self, measure: ErrorMeasure) -> ErrorEstimate {
        let mut estimate = self.no_estimate(measure);
        if self.chunks < 2 || self.items == 0 {
            return estimate;
        }
        // Everything in units of s (the image) and s² (variances, s = k / N): the measures
        // are ratios that do not depend on it.
        let dof = (self.chunks - 1) as f64;
        let rows = srgb_rows();
        let values = 3.0 * self.sums.len() as f64;
        let total = self.sums.iter().fold([0.0; 3], |t, m| [t[0] + m[0], t[1] + m[1], t[2] + m[2]]);
        let level = rows.iter().map(|r| dot(r, &total)).sum::<f64>() / values;
        let eps2 = (RELMSE_EPSILON * level).powi(2);
        let (mut energy, mut mean, mut relmse) =
            (Spread::default(), Spread::default(), Spread::default());
        let mut signal = 0.0;
        // Each pixel's linear-sRGB value and variance, for the relmse denominators below.
        let mut rgb = Vec::with_capacity(self.sums.len());
        for m in &self.sums {
            let c = self.scaled_covariance(m);
            for v in &c[..3] {
                energy.add(v / dof);
            }
            signal += m[0] * m[0] + m[1] * m[1] + m[2] * m[2];
            let s = [m[0], m[1], m[2]];
            let pixel = rows.map(|r| (dot(&r, &s), (quadratic(&r, &c) / dof).max(0.0)));
            for &(_, v) in &pixel {
                mean.add(v);
            }
            rgb.push(pixel);
        }
        let relmse_dof = match self.split_relmse(&rows, &rgb, eps2) {
            Some((spread, dof)) => {
                relmse = spread;
                dof
            }
            None => {
                for &(i, v) in rgb.iter().flatten() {
                    relmse.add(v / (denominator(i, v) + eps2));
                }
                relmse.dof(dof)
            }
        };
        let truth = signal - energy.sum;
        let by = &mut estimate.by_measure;
        if truth > 0.0 && energy.sum.is_finite() {
            by.energy = Some((energy.sum / truth).sqrt());
        }
        if level > 0.0 && mean.sum.is_finite() {
            by.mean = Some((mean.sum / values).sqrt() / level);
            by.relmse = Some((relmse.sum / values).sqrt()).filter(|e| e.is_finite());
        }
        estimate.relative_error = by.get(measure);
        estimate.degrees_of_freedom = match measure {
            ErrorMeasure::RelMse => relmse_dof,
            ErrorMeasure::Energy => energy.dof(dof),
            ErrorMeasure::Mean => mean.dof(dof),
        };
        estimate
    }

    /// The split-half terms of the relmse estimate (see `RELMSE_DENOMINATOR`) in units of `s²`
    /// and the degrees of freedom of their sum ([`split_degrees_of_freedom`]), with `eps2` the
    /// `eps²` of the measure in units of `s²`; `None` unless each half has at least two chunks
    /// with work.
    ///
    /// A pixel's variance and the square of its value both grow with a firefly, so their
    /// ratio from the same chunks hardly sees it (a pixel whose value is one firefly gets a
    /// ratio near 2, where the truth's is `(firefly / value)²`). So each half's estimate of the
    /// image's variance is divided by the other half's estimate of the square: independent
    /// of each other, their ratio is unbiased but for the denominator's own noise. Where that
    /// noise is large (the other half's variance at least [`SPLIT_TRUST`] of its square: a
    /// pixel lit by rare paths, whose other half may be 0) the image's own square is used.
    fn split_relmse(
        &self,
        rows: &[[f64; 3]; 3],
        rgb: &[[(f64, f64); 3]],
        eps2: f64,
    ) -> Option<(Spread, f64)> {
        let [ca, na] = self.first_chunks;
        let (cb, nb) = (self.chunks - ca, self.items - na);
        if ca < 2 || cb < 2 || na == 0 || nb == 0 {
            return None;
        }
        let halves = [(ca, na as f64), (cb, nb as f64)];
        let n = self.items as f64;
        let mut spread = Spread::default();
        let mut disagreement = 0.0;
        for ((m, h), pixel) in self.sums.iter().zip(&self.first).zip(rgb) {
            let q_all = [m[3], m[4], m[5], m[6], m[7], m[8]];
            let sa = [h[0], h[1], h[2]];
            let sb = [m[0] - h[0], m[1] - h[1], m[2] - h[2]];
            // Per pixel, summed over its channels before squaring: a pixel's channels are
            // mostly noisy together (one path lights all three), so they count as one.
            let mut difference = 0.0;
            for (c, r) in rows.iter().enumerate() {
                let qa = h[3 + c];
                let sums = [(dot(r, &sa), qa), (dot(r, &sb), quadratic(r, &q_all) - qa)];
                let [ta, tb] = split_terms(halves, n, sums, pixel[c], eps2);
                spread.add(0.5 * (ta + tb));
                difference += ta - tb;
            }
            disagreement += difference * difference;
        }
        Some((spread, split_degrees_of_freedom(spread.sum, disagreement)))
    }

    /// The standard error of every pixel of the image `s S` (`s` = the image's scale per film
    /// unit), in linear sRGB like the image: `sqrt(mᵀ Cov m)` for each row `m` of the XYZ to
    /// linear sRGB matrix. All zero with fewer than two chunks.
    pub fn standard_error_rgb(&self, scale: f64) -> Vec<[f64; 3]> {
        if self.chunks < 2 {
            return vec![[0.0; 3]; self.sums.len()];
        }
        let rows = srgb_rows();
        let factor = scale * scale / (self.chunks - 1) as f64;
        self.sums
            .iter()
            .map(|m| {
                let c = self.scaled_covariance(m);
                rows.map(|r| (quadratic(&r, &c).max(0.0) * factor).sqrt())
            })
            .collect()
    }
}

/// One pixel channel's split-half terms `[t_a, t_b]` (see `split_relmse`), from its halves'
/// chunk counts and items `halves`, all items `n`, each half's channel sum and second moment
/// `sums`, the image's value and variance `(i, v)` (units s, s²) and `eps2`.
fn split_terms(
    halves: [(u64, f64); 2],
    n: f64,
    sums: [(f64, f64); 2],
    (i, v): (f64, f64),
    eps2: f64,
) -> [f64; 2] {
    // Each half's estimate of the image's variance and of its value (units s², s).
    let [(va, ia), (vb, ib)] = [0, 1].map(|k| {
        let ((chunks, items), (s, q)) = (halves[k], sums[k]);
        let v = (n * (q - s * s / items) / (chunks - 1) as f64).max(0.0);
        (v, s * n / items)
    });
    let (ra, rb) = (n / halves[0].1, n / halves[1].1);
    // The other half's square where it is known well enough, else the image's. The other
    // half's noise makes `1 / D` too large on average, by `1 + 4 r` to first order (`r` its
    // relative variance: Var(I²) ≈ 4 I² Var): taken off. Never below `SPLIT_FLOOR` of the
    // image's own: see there.
    let own = denominator(i, v);
    let square = |hi: f64, hv: f64| {
        let r = hv / (hi * hi);
        if r < SPLIT_TRUST {
            ((hi * hi - hv) * (1.0 + 4.0 * r)).max(own * SPLIT_FLOOR)
        } else {
            own
        }
    };
    let (da, db) = (square(ia, va * ra), square(ib, vb * rb));
    [va / (db + eps2), vb / (da + eps2)]
}

/// The live estimate is redone once the chunks have grown by at least `1 / LIVE_GROWTH` of
/// those of the last one (see [`LiveEstimate`]).
const LIVE_GROWTH: u64 = 4;

/// The live estimate of a render in a measure: the full [`Moments::estimate`] (O(pixels),
/// with the degrees of freedom that decide whether it is trusted), redone once the chunks have
/// grown by `every` (eight times the pixels over the items per chunk, at least 1) and by a
/// quarter ([`LIVE_GROWTH`]) since the last one; and also whenever a cheap prediction says a
/// target may be reached (`LiveEstimate::predicted`), so that a render to a target stops as
/// soon as it is.
///
/// Why both: `every` keeps the estimates' cost at most an eighth of a pixel's worth per work
/// item (an estimate costs about 540 instructions per pixel, a camera sample on the race's
/// spot over a plane about 2,200), and the growth makes their number grow with the logarithm of
/// the render's length, not with the length: a render of `n` chunks does about
/// `log(n / every) / log(1.25)` of them. A full estimate blocks the other threads' chunks from
/// the moments while it runs, so on short renders it cost more than its instructions: with one
/// every four items per pixel, the race's 64-sample spot-over-a-plane render took 9% (fastest of
/// 15) to 18% (median) longer than with none.
#[derive(Debug, Clone)]
pub(crate) struct LiveEstimate {
    measure: ErrorMeasure,
    every: u64,
    last: Option<ErrorEstimate>,
}

impl LiveEstimate {
    /// The error now, cheaply: the O(1) [`Moments::quick_estimate`] for
    /// [`ErrorMeasure::Energy`]; for the other measures the last full estimate scaled by
    /// `1 / sqrt(items)` (the error of an unbiased estimate falls so).
    fn predicted(&self, moments: &Moments) -> Option<f64> {
        if self.measure == ErrorMeasure::Energy {
            return moments.quick_estimate().relative_error;
        }
        let last = self.last?;
        let grown = moments.items() as f64 / last.items.max(1) as f64;
        last.relative_error.map(|e| e / grown.sqrt())
    }

    /// The live estimate in `measure` of a `pixels`-pixel film rendered in chunks of
    /// `chunk_items` items.
    pub(crate) fn new(measure: ErrorMeasure, pixels: u64, chunk_items: u64) -> Self {
        let every = pixels.saturating_mul(8).div_ceil(chunk_items.max(1)).max(1);
        Self { measure, every, last: None }
    }

    /// The estimate after the chunks folded into `moments` so far, computed now.
    pub(crate) fn fresh(&mut self, moments: &Moments) -> ErrorEstimate {
        let e = moments.estimate(self.measure);
        self.last = Some(e);
        e
    }

    /// The estimate after the chunks folded into `moments` so far, with `target` the error a
    /// render stops at (if any); `fresh` says whether it was computed now (a target may stop
    /// the render only on a fresh one).
    pub(crate) fn update(
        &mut self,
        moments: &Moments,
        target: Option<f64>,
    ) -> (ErrorEstimate, bool) {
        let due = self.last.is_none_or(|e| {
            moments.chunks() >= e.batches + self.every.max(e.batches / LIVE_GROWTH)
        });
        let may_stop = target.is_some_and(|t| self.predicted(moments).is_some_and(|p| p <= t));
        match self.last {
            Some(e) if !due && !may_stop => (e, false),
            _ => (self.fresh(moments), true),
        }
    }
}

/// The least share of the noisy image's square `I^2` that [`Moments::estimate`] keeps as the
/// relmse denominator's estimate of the truth's square where it cannot use the other half's
/// (see `split_relmse`): `max(I^2 - Var, I^2 / 2, Var / 2)`. Subtracting the variance makes
/// `I^2 - Var` unbiased, but a pixel whose batches are mostly zero (a caustic at low counts) can
/// make it 0 and its ratio `Var / eps^2` explode; keeping half of `I^2` bounds that. Simulated
/// (20,000 pixels, 16 and 64 batches): for gamma-distributed batch values up to 100% relative
/// error per pixel the estimate is 0.89-1.08 of the truth, for batches that are zero with
/// probability 0.5-0.95 it is 1.07-2.3 (the unclamped `I^2 - Var` gave up to 4,900, `I^2` alone
/// 0.38-1.38).
const RELMSE_DENOMINATOR: f64 = 0.5;

/// The least share of a pixel channel's variance `Var` the same denominator keeps (see
/// [`RELMSE_DENOMINATOR`]). Where a value is within its noise of 0, `I^2` itself may be near 0
/// and `1 / D` has no finite mean: a linear-sRGB channel of a saturated colour, which
/// single-wavelength paths scatter on both sides of 0 (the prism's rainbow). Simulated (20,000
/// pixel channels of normal batch values, mean `k` standard errors from 0, 64 batches),
/// estimated over true: 280, 320, 270, 79 and 1.4 for `k` = 1, 1.5, 2, 3, 4 without this
/// floor, 1.3, 2.2, 2.5, 1.9 and 1.2 with it (skewed positive pixels are unchanged). On the
/// final moments of the 13 shipped scenes' renders to 10% (the accuracy report's estimate
/// check), estimated over true: 0.88 to 1.03 with it; without it the same but the prism at
/// 1.44 (and 1.21 against a 2^28-path reference in another render); with `Var` (1) or
/// `0.25 Var`: 0.85 to 1.03 and 0.88 to 1.05. Adding `1.5 Var` to `max(I^2 - Var, 0)` instead
/// (within 15% on the simulated normal channels) moved the caustic ring and the plastic
/// spheres to 0.79 and 0.82.
const VARIANCE_FLOOR: f64 = 0.5;

/// The largest relative variance (variance over square) of one half's value for
/// [`Moments::estimate`] to divide the other half's variance by its square (see `split_relmse`):
/// its standard deviation below half its value. Measured against converged references (16
/// times the samples) on five shipped scenes at fixed efforts giving 7% to 10% relmse (24x16
/// pixels, 4 renders each), estimated over true: 0.89 (fading spot, path), 0.95 (Cornell box,
/// path), 1.11 (prism, BDPT), 1.00 (spot and torus, light), 1.00 (sky, BDPT). Without the
/// `1 + 4 r` correction: 0.93, 0.98, 1.16, 1.07, 1.08; with 0.1 instead of 0.25: 0.90, 0.96,
/// 1.12, 1.02, 0.96; with 1: 0.91, 0.97, 1.10, 1.00, 1.29. Without the split (the image's own
/// square, the estimate before) near 20% relmse: 0.64 on the fading spot; splitting every pixel
/// whatever its noise: up to 2.8.
const SPLIT_TRUST: f64 = 0.25;

/// The least share of the image's own square estimate that [`Moments::estimate`] takes as the
/// other half's (see `split_relmse`): the other half's value may stand for the truth down to a
/// quarter of the image's. A pixel of skewed paths (a dispersive caustic far from converged)
/// with few chunks per half often has one half far below its truth with a small spread too,
/// so the spread test (`SPLIT_TRUST`) passes and `1 / square` has no finite mean. Simulated
/// (20,000 pixels, chunk values gamma-distributed with relative deviation 2 and 4, 8 and 16
/// chunks): estimated over true 66, 61, 4.4 and 54 without this floor, 2.3, 0.72, 2.2 and 1.2
/// with it; a firefly 20 times the pixel's value in 1% or 5% of the chunks keeps 1.4 and 3.2
/// (was 1.4 and 3.3), one 100 times it in 1% of 16 chunks 2.1 (was 3.5); at 64 chunks
/// everything is within 1.1 of the estimate without the floor but the relative deviation 4
/// (4.6, now 2.0).
const SPLIT_FLOOR: f64 = 1.0 / 16.0;

/// The estimate of a pixel channel's true square from its noisy value `i` of variance `v`:
/// `max(i² - v, i² RELMSE_DENOMINATOR, v VARIANCE_FLOOR)`.
fn denominator(i: f64, v: f64) -> f64 {
    let i2 = i * i;
    (i2 - v).max(i2 * RELMSE_DENOMINATOR).max(v * VARIANCE_FLOOR)
}

/// A sum of variance terms and of their squares, for a Welch-Satterthwaite count of degrees of
/// freedom.
#[derive(Debug, Default, Clone, Copy)]
struct Spread {
    sum: f64,
    sum_sq: f64,
}

impl Spread {
    fn add(&mut self, v: f64) {
        self.sum += v;
        self.sum_sq += v * v;
    }

    /// The effective degrees of freedom of the sum when each term has `dof`; infinite when
    /// every term is 0 (no noise: an estimate of 0 is exact).
    fn dof(&self, dof: f64) -> f64 {
        if self.sum_sq > 0.0 { dof * self.sum * self.sum / self.sum_sq } else { f64::INFINITY }
    }
}

/// The degrees of freedom of the split-half relmse estimate `sum = Σ (t_a + t_b) / 2` (one
/// term per pixel channel, `t_a` and `t_b` the two halves' independent estimates of it), with
/// `disagreement = Σ (Σ_c (t_a - t_b))²` (per pixel, over its channels before squaring: a
/// pixel's channels are mostly noisy together, one path lighting all three):
/// `(t_a - t_b)² / 4` estimates the variance of a term whatever the distribution of the
/// pixel's paths, so the sum's relative variance is `disagreement / (4 sum²)` and the relmse's
/// (half the relative deviation) `u² = disagreement / (16 sum²)`, reported as `1 / (2 u²)`. The
/// Welch-Satterthwaite count of the other measures assumes normal chunk values and independent
/// channels; this one assumes neither. Measured on 40 synthetic renders of 200 skewed grey
/// pixels (relative deviation `sqrt(5)` per chunk, 64 chunks): the estimates scattered by
/// 5.2% where this `u` says 5.6% (the moments' test). Infinite when the halves agree exactly.
///
/// What it does not hold: how far one render's *true* error strays from its expectation,
/// which no estimate can follow (one draw per pixel: about `1 / sqrt(2 pixels)` for normal
/// pixels, far more where pixels lit by rare paths rule the error).
fn split_degrees_of_freedom(sum: f64, disagreement: f64) -> f64 {
    if disagreement > 0.0 { 8.0 * sum * sum / disagreement } else { f64::INFINITY }
}

/// `a . b`.
fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `rᵀ C r` for a symmetric `C` given as `[xx, yy, zz, xy, xz, yz]`.
fn quadratic(r: &[f64; 3], c: &[f64; 6]) -> f64 {
    let [a, b, d] = *r;
    let [xx, yy, zz, xy, xz, yz] = *c;
    a * a * xx + b * b * yy + d * d * zz + 2.0 * (a * b * xy + a * d * xz + b * d * yz)
}

/// The rows of the XYZ to linear sRGB matrix.
fn srgb_rows() -> [[f64; 3]; 3] {
    let cols = [Xyz::new(1.0, 0.0, 0.0), Xyz::new(0.0, 1.0, 0.0), Xyz::new(0.0, 0.0, 1.0)]
        .map(Xyz::to_linear_srgb);
    [0, 1, 2].map(|r| [cols[0][r], cols[1][r], cols[2][r]])
}

/// A thread's sums of the chunk it is rendering, folded into shared [`Moments`] when the chunk
/// ends ([`crate::FilmWriter::end_chunk`]). Dense (24 bytes per pixel, reserved fallibly when
/// the tally is made) with a list of the pixels touched, so a chunk that lights few pixels
/// costs little to fold.
#[derive(Debug)]
pub(crate) struct ChunkTally<'a> {
    moments: &'a Mutex<Moments>,
    sums: Vec<[f64; 3]>,
    /// Whether each pixel is in `touched`.
    listed: Vec<bool>,
    touched: Vec<u32>,
}

impl<'a> ChunkTally<'a> {
    /// Bytes a tally takes per pixel at most: the sums and the touched list.
    pub(crate) const BYTES_PER_PIXEL: u64 = 24 + 1 + 4;

    /// A tally folding into `moments`, its memory reserved at once ([`Self::BYTES_PER_PIXEL`]
    /// per pixel, which the render's memory plan counts per thread).
    ///
    /// # Errors
    /// [`FilmError::OutOfMemory`] when the memory cannot be had.
    pub(crate) fn new(moments: &'a Mutex<Moments>) -> Result<Self, FilmError> {
        let pixels = moments.lock().unwrap_or_else(PoisonError::into_inner).sums.len();
        let sums = try_filled(pixels, [0.0; 3], "a thread's error-estimate tally")?;
        let listed = try_filled(pixels, false, "a thread's error-estimate tally")?;
        let mut touched = Vec::new();
        touched.try_reserve_exact(pixels).map_err(|_| FilmError::OutOfMemory {
            what: "a thread's error-estimate tally",
            bytes: 4 * pixels as u64,
        })?;
        Ok(Self { moments, sums, listed, touched })
    }

    /// Adds a contribution to pixel `index` of the current chunk.
    #[inline]
    pub(crate) fn add(&mut self, index: usize, xyz: [f64; 3]) {
        let (Some(s), Some(listed)) = (self.sums.get_mut(index), self.listed.get_mut(index)) else {
            return;
        };
        if !*listed {
            *listed = true;
            self.touched.push(index as u32);
        }
        for (a, b) in s.iter_mut().zip(xyz) {
            *a += b;
        }
    }

    /// Folds the current chunk (number `chunk` of `items` work items) into the moments and
    /// starts a new one.
    pub(crate) fn end_chunk(&mut self, chunk: u64, items: u64) {
        let mut moments = self.moments.lock().unwrap_or_else(PoisonError::into_inner);
        let sums = &self.sums;
        let pixels = self.touched.iter().map(|&i| (i as usize, sums[i as usize]));
        moments.add_chunk(chunk, pixels, items);
        drop(moments);
        self.discard();
    }

    /// Forgets the current chunk and starts a new one.
    pub(crate) fn discard(&mut self) {
        for &i in &self.touched {
            self.sums[i as usize] = [0.0; 3];
            self.listed[i as usize] = false;
        }
        self.touched.clear();
    }
}

#[cfg(test)]
mod tests;
