//! [`GridLocator`]: the segment of a sorted grid that holds a point, in `O(1)` for the evenly
//! spaced tables spectra usually are, and exactly the index a binary search gives for any grid.

/// Finds `i` with `xs[i] <= x < xs[i + 1]` from a guess by even spacing, corrected by at most
/// [`GridLocator::STEPS`] steps each way and falling back to a binary search beyond them, so the
/// answer is always the binary search's (the last index with `xs[i] <= x`), and tables that are
/// (nearly) evenly spaced, as measured spectra are, cost a multiply and one or two comparisons.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct GridLocator {
    /// `xs[0]`.
    origin: f64,
    /// `(n - 1) / (xs[n - 1] - xs[0])`, or 0 when that is not finite and positive.
    inv_step: f64,
}

impl GridLocator {
    /// Steps the guess may be corrected by before the binary search takes over.
    pub const STEPS: usize = 2;

    /// The locator of the sorted grid `xs` (any length; an empty or one-point grid, or one whose
    /// span is not finite and positive, always guesses 0).
    pub fn new(xs: &[f64]) -> Self {
        let (Some(&first), Some(&last)) = (xs.first(), xs.last()) else {
            return Self::default();
        };
        let inv_step = (xs.len() - 1) as f64 / (last - first);
        let inv_step = if inv_step.is_finite() && inv_step > 0.0 { inv_step } else { 0.0 };
        Self { origin: first, inv_step }
    }

    /// The last index `i` with `xs[i] <= x` (as `xs.partition_point(|&v| v <= x) - 1`), for a
    /// non-empty `xs` sorted ascending (the grid this locator was made for) and `x >= xs[0]`;
    /// 0 when `x < xs[0]` or `x` is NaN.
    #[inline]
    pub fn last_at_or_below(&self, xs: &[f64], x: f64) -> usize {
        let n = xs.len();
        if n == 0 || !(x >= xs[0]) {
            return 0;
        }
        let guess = cell_index((x - self.origin) * self.inv_step, n - 1);
        settle(xs, x, guess, Self::STEPS)
    }
}

/// [`GridLocator`]'s companion for grids far from evenly spaced (the cosines of evenly spaced
/// angles, whose steps shrink twentyfold towards the poles): per cell of an even subdivision of
/// the grid's span, the index at the cell's start. A lookup is a multiply, a load and a step or
/// two whatever the spacing, and always the binary search's answer (it corrects the guess both
/// ways, and falls back to the search if the guess is more than [`GuideTable::STEPS`] off).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct GuideTable {
    /// `xs[0]`.
    origin: f64,
    /// Cells per unit of `x`, or 0 when the span is not finite and positive.
    inv_width: f64,
    /// `starts[c]`: the last index at or below the start of cell `c`.
    starts: Vec<u32>,
}

impl GuideTable {
    /// Cells per grid segment (before the cap): steps shrinking up to this factor below the
    /// mean still leave about one node per cell.
    pub const CELLS_PER_SEGMENT: usize = 8;
    /// Most cells of one table (256 KiB).
    pub const MAX_CELLS: usize = 1 << 16;
    /// Steps the guess may be corrected by before the binary search takes over.
    pub const STEPS: usize = 4;

    /// The guide of the sorted grid `xs` (any length; an empty or one-point grid, or one whose
    /// span is not finite and positive, always guesses 0).
    pub fn new(xs: &[f64]) -> Self {
        let (Some(&first), Some(&last)) = (xs.first(), xs.last()) else {
            return Self::default();
        };
        let cells =
            (xs.len() - 1).saturating_mul(Self::CELLS_PER_SEGMENT).clamp(1, Self::MAX_CELLS);
        let span = last - first;
        if !(span.is_finite() && span > 0.0) || xs.len() > u32::MAX as usize {
            return Self { origin: first, inv_width: 0.0, starts: vec![0] };
        }
        let width = span / cells as f64;
        let mut i = 0usize;
        let starts = (0..cells)
            .map(|c| {
                let start = first + c as f64 * width;
                while i + 1 < xs.len() && xs[i + 1] <= start {
                    i += 1;
                }
                i as u32
            })
            .collect();
        Self { origin: first, inv_width: cells as f64 / span, starts }
    }

    /// The last index `i` with `xs[i] <= x` (as `xs.partition_point(|&v| v <= x) - 1`), for a
    /// non-empty `xs` sorted ascending (the grid this guide was made for) and `x >= xs[0]`; 0
    /// when `x < xs[0]` or `x` is NaN.
    #[inline]
    pub fn last_at_or_below(&self, xs: &[f64], x: f64) -> usize {
        let n = xs.len();
        if n == 0 || !(x >= xs[0]) {
            return 0;
        }
        let cell = cell_index((x - self.origin) * self.inv_width, self.starts.len() - 1);
        settle(xs, x, (self.starts[cell] as usize).min(n - 1), Self::STEPS)
    }
}

/// The last index `i` with `xs[i] <= x`, from the index `guess` (`< xs.len()`), for a sorted
/// non-empty `xs` and `x >= xs[0]`: the guess moved by up to `steps` single steps either way,
/// then, if it is still not the answer, a binary search.
#[inline]
fn settle(xs: &[f64], x: f64, guess: usize, steps: usize) -> usize {
    let n = xs.len();
    let mut i = guess;
    for _ in 0..steps {
        if xs[i] > x {
            i -= 1; // xs[0] <= x, so i > 0 here
        } else if i + 1 < n && xs[i + 1] <= x {
            i += 1;
        } else {
            return i;
        }
    }
    if xs[i] <= x && (i + 1 == n || xs[i + 1] > x) {
        i
    } else {
        xs.partition_point(|&v| v <= x) - 1
    }
}

/// `floor(x)` as an index in `0..=last`: `x` below 0 and NaN give 0, `x` at or above `last`
/// gives `last`. Equal to `(x as usize).min(last)`, in about a third of its instructions: a
/// saturating `as usize` must handle values from `2^63` on, a conversion through `u32` only a
/// clamp (taken for every `last` below `2^32`, the plain conversion beyond).
#[inline]
pub fn cell_index(x: f64, last: usize) -> usize {
    if last > u32::MAX as usize {
        (x as usize).min(last)
    } else if x < last as f64 {
        x as u32 as usize
    } else if x >= 0.0 {
        last
    } else {
        0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn reference(xs: &[f64], x: f64) -> usize {
        if !(x >= xs[0]) { 0 } else { xs.partition_point(|&v| v <= x) - 1 }
    }

    #[test]
    fn evenly_spaced_grids_and_their_ends() {
        let xs: Vec<f64> = (0..=95).map(|i| 360.0 + 5.0 * f64::from(i)).collect();
        let g = GridLocator::new(&xs);
        for x in [360.0, 362.5, 365.0, 829.999, 835.0, 1e9, 359.0, f64::NAN, f64::INFINITY] {
            assert_eq!(g.last_at_or_below(&xs, x), reference(&xs, x), "{x}");
        }
        let one = [3.0];
        assert_eq!(GridLocator::new(&one).last_at_or_below(&one, 5.0), 0);
    }

    #[test]
    fn a_guide_over_cosines_of_even_angles_needs_no_search_and_answers_as_one() {
        // -cos(gamma) for gamma every 5 degrees, 0 to 180: steps from 0.004 to 0.087.
        let ys: Vec<f64> = (0..=36).map(|k| -(f64::from(k) * 5f64.to_radians()).cos()).collect();
        let g = GuideTable::new(&ys);
        for k in 0..=20_000 {
            let y = -1.0 + 2.0 * f64::from(k) / 20_000.0;
            assert_eq!(g.last_at_or_below(&ys, y), reference(&ys, y), "{y}");
        }
        for y in [-1.0, 1.0, -1.5, 2.0, f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            assert_eq!(g.last_at_or_below(&ys, y), reference(&ys, y), "{y}");
        }
        assert_eq!(GuideTable::new(&[3.0]).last_at_or_below(&[3.0], 5.0), 0);
    }

    #[test]
    fn cell_index_is_the_saturating_conversion_clamped() {
        let xs = [-1e300, -2.0, -0.5, -0.0, 0.0, 0.3, 1.0, 6.999, 7.0, 7.5, 1e10, 4.3e9, 1e300];
        let specials = [f64::NAN, f64::INFINITY, f64::NEG_INFINITY];
        for last in [0usize, 1, 7, u32::MAX as usize - 1, u32::MAX as usize, 1 << 40] {
            for &x in xs.iter().chain(&specials) {
                assert_eq!(cell_index(x, last), (x as usize).min(last), "{x} {last}");
            }
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 2000, ..ProptestConfig::default() })]

        #[test]
        fn the_guide_agrees_with_binary_search_on_grids_of_wildly_uneven_steps(
            logs in prop::collection::vec(-30.0f64..5.0, 1..60),
            probes in prop::collection::vec(0.0f64..1.0, 1..30),
        ) {
            // Steps from e^-30 to e^5: many nodes share a cell, so the fallback search is used.
            let mut xs = vec![0.0];
            for l in &logs {
                xs.push(xs[xs.len() - 1] + l.exp());
            }
            let span = xs[xs.len() - 1];
            let guide = GuideTable::new(&xs);
            for x in probes.iter().map(|p| p * span).chain(xs.iter().copied()) {
                prop_assert_eq!(guide.last_at_or_below(&xs, x), reference(&xs, x), "{:?} at {}", xs, x);
            }
        }

        #[test]
        fn agrees_with_binary_search_on_any_sorted_grid(
            mut xs in prop::collection::vec(-1e3f64..1e3, 1..40),
            repeat in 0usize..3,
            probes in prop::collection::vec(-1.2e3f64..1.2e3, 1..20),
        ) {
            xs.sort_by(f64::total_cmp);
            // Repeated points (step tables) too.
            let copy = xs.clone();
            for &x in copy.iter().take(repeat) {
                let at = xs.partition_point(|&v| v <= x);
                xs.insert(at, x);
            }
            let g = GridLocator::new(&xs);
            let guide = GuideTable::new(&xs);
            for &x in probes.iter().chain(&xs) {
                prop_assert_eq!(g.last_at_or_below(&xs, x), reference(&xs, x), "{:?} at {}", xs, x);
                prop_assert_eq!(guide.last_at_or_below(&xs, x), reference(&xs, x), "{:?} at {}", xs, x);
            }
        }
    }
}
