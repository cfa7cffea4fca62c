//! The one error type of this crate: what is wrong with a table, and where.

/// Why a table could not be turned into a sampler. Every variant that concerns one entry names the
/// array (`"weights"`, `"xs"`, `"ys"`, `"edges"`, `"values"`) and the index of the offending entry.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SamplingError {
    /// The table has no entries at all.
    #[error("{array} is empty")]
    Empty {
        /// Which input array is empty.
        array: &'static str,
    },
    /// A continuous table needs at least two grid points (one segment or bin).
    #[error("{array} has {len} point(s) but at least 2 are needed")]
    TooFewPoints {
        /// Which input array is too short.
        array: &'static str,
        /// How many points it has.
        len: usize,
    },
    /// Two arrays that must match in length do not.
    #[error("{first} has {first_len} entries but {second} has {second_len} (expected {expected})")]
    LengthMismatch {
        /// The first array.
        first: &'static str,
        /// Its length.
        first_len: usize,
        /// The second array.
        second: &'static str,
        /// Its length.
        second_len: usize,
        /// What the relation should be, e.g. `"equal lengths"`.
        expected: &'static str,
    },
    /// An entry is NaN.
    #[error("{array}[{index}] is NaN")]
    NaN {
        /// Which input array.
        array: &'static str,
        /// Index of the NaN entry.
        index: usize,
    },
    /// An entry is infinite.
    #[error("{array}[{index}] is infinite ({value})")]
    Infinite {
        /// Which input array.
        array: &'static str,
        /// Index of the infinite entry.
        index: usize,
        /// The value (positive or negative infinity).
        value: f64,
    },
    /// A weight or density value is negative.
    #[error("{array}[{index}] is negative ({value})")]
    Negative {
        /// Which input array.
        array: &'static str,
        /// Index of the negative entry.
        index: usize,
        /// The negative value.
        value: f64,
    },
    /// A grid coordinate is not strictly greater than its predecessor.
    #[error("{array}[{index}] = {value} is not greater than {array}[{}] = {previous}", index - 1)]
    NotIncreasing {
        /// Which input array.
        array: &'static str,
        /// Index of the entry that fails to increase (always at least 1).
        index: usize,
        /// Its value.
        value: f64,
        /// The value before it.
        previous: f64,
    },
    /// The distance between two neighbouring grid points is too large for an `f64`.
    #[error("{array}[{}] - {array}[{index}] overflows f64", index + 1)]
    SpanOverflow {
        /// Which input array.
        array: &'static str,
        /// Index of the left end of the segment whose width overflows.
        index: usize,
    },
    /// Every entry is zero, so there is nothing to sample.
    #[error("{array} has zero total mass (every entry is zero)")]
    ZeroTotal {
        /// Which input array.
        array: &'static str,
    },
    /// The total mass (sum of weights or integral) is too large for an `f64`.
    #[error("the total mass of {array} overflows f64")]
    TotalOverflow {
        /// Which input array.
        array: &'static str,
    },
    /// The total mass (an integral) is positive but smaller than the least positive `f64`, so it
    /// cannot be reported (it rounds to zero): tiny values on a narrow support.
    #[error("the total mass of {array} underflows f64 (positive, but below 5e-324)")]
    TotalUnderflow {
        /// Which input array.
        array: &'static str,
    },
    /// The normalised density is too large for an `f64` (a huge value on a tiny segment).
    #[error("the normalised density of {array} overflows f64 at index {index}")]
    DensityOverflow {
        /// Which input array.
        array: &'static str,
        /// Index of the entry whose normalised density overflows.
        index: usize,
    },
}

impl SamplingError {
    /// The index of the offending entry, when the error concerns one entry.
    pub fn index(&self) -> Option<usize> {
        match self {
            Self::NaN { index, .. }
            | Self::Infinite { index, .. }
            | Self::Negative { index, .. }
            | Self::NotIncreasing { index, .. }
            | Self::SpanOverflow { index, .. }
            | Self::DensityOverflow { index, .. } => Some(*index),
            Self::Empty { .. }
            | Self::TooFewPoints { .. }
            | Self::LengthMismatch { .. }
            | Self::ZeroTotal { .. }
            | Self::TotalOverflow { .. }
            | Self::TotalUnderflow { .. } => None,
        }
    }

    /// The same error with the array renamed, for callers that expose the table under their own
    /// field names (e.g. a spectrum's `nm` and `values` instead of `xs` and `ys`).
    pub fn with_array(mut self, from: &'static str, to: &'static str) -> Self {
        match &mut self {
            Self::Empty { array }
            | Self::TooFewPoints { array, .. }
            | Self::NaN { array, .. }
            | Self::Infinite { array, .. }
            | Self::Negative { array, .. }
            | Self::NotIncreasing { array, .. }
            | Self::SpanOverflow { array, .. }
            | Self::ZeroTotal { array }
            | Self::TotalOverflow { array }
            | Self::TotalUnderflow { array }
            | Self::DensityOverflow { array, .. } => {
                if *array == from {
                    *array = to;
                }
            }
            Self::LengthMismatch { first, second, .. } => {
                if *first == from {
                    *first = to;
                }
                if *second == from {
                    *second = to;
                }
            }
        }
        self
    }

    /// The name of the input array the error concerns.
    pub fn array(&self) -> &'static str {
        match self {
            Self::Empty { array }
            | Self::TooFewPoints { array, .. }
            | Self::NaN { array, .. }
            | Self::Infinite { array, .. }
            | Self::Negative { array, .. }
            | Self::NotIncreasing { array, .. }
            | Self::SpanOverflow { array, .. }
            | Self::ZeroTotal { array }
            | Self::TotalOverflow { array }
            | Self::TotalUnderflow { array }
            | Self::DensityOverflow { array, .. } => array,
            Self::LengthMismatch { second, .. } => second,
        }
    }
}
