//! [`Reflectance`]: spectral reflectance or transmittance, a fraction in `[0, 1]` per wavelength.
//!
//! Unlike an SPD it is not normalised and not sampled; materials multiply a beam's weight by it.
//!
//! | JSON | meaning |
//! |---|---|
//! | `0.8` | the same fraction at every wavelength |
//! | `{"nm": [400, 550, 700], "values": [0.1, 0.6, 0.9]}` | linear between the points, held constant beyond the first and last |

use serde::{Deserialize, Serialize};

use crate::error::SpectrumError;
use spectrace_sampling::SamplingError;

/// A spectral reflectance (or transmittance): a fraction in `[0, 1]` at each wavelength, linear
/// between tabulated points and constant beyond the ends.
#[derive(Debug, Clone, PartialEq)]
pub struct Reflectance {
    nm: Vec<f64>,
    values: Vec<f64>,
}

/// A transmittance spectrum has the same representation and rules as a reflectance.
pub type Transmittance = Reflectance;

/// Scene-file form of [`Reflectance`]: a number or a table (untagged, for JSON).
#[derive(Serialize, Deserialize)]
#[serde(untagged)]
enum ReflectanceRepr {
    Constant(f64),
    Table { nm: Vec<f64>, values: Vec<f64> },
}

/// Binary form of [`Reflectance`] (externally tagged: formats such as bincode are not
/// self-describing and cannot read an untagged enum).
#[derive(Serialize, Deserialize)]
enum ReflectanceBinary {
    Constant(f64),
    Table { nm: Vec<f64>, values: Vec<f64> },
}

impl Serialize for Reflectance {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let repr = ReflectanceRepr::from(self.clone());
        if serializer.is_human_readable() {
            repr.serialize(serializer)
        } else {
            match repr {
                ReflectanceRepr::Constant(v) => ReflectanceBinary::Constant(v),
                ReflectanceRepr::Table { nm, values } => ReflectanceBinary::Table { nm, values },
            }
            .serialize(serializer)
        }
    }
}

impl<'de> Deserialize<'de> for Reflectance {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let repr = if deserializer.is_human_readable() {
            ReflectanceRepr::deserialize(deserializer)?
        } else {
            match ReflectanceBinary::deserialize(deserializer)? {
                ReflectanceBinary::Constant(v) => ReflectanceRepr::Constant(v),
                ReflectanceBinary::Table { nm, values } => ReflectanceRepr::Table { nm, values },
            }
        };
        Self::try_from(repr).map_err(serde::de::Error::custom)
    }
}

impl TryFrom<ReflectanceRepr> for Reflectance {
    type Error = SpectrumError;
    fn try_from(r: ReflectanceRepr) -> Result<Self, SpectrumError> {
        match r {
            ReflectanceRepr::Constant(v) => Self::constant(v),
            ReflectanceRepr::Table { nm, values } => Self::from_table(&nm, &values),
        }
    }
}

impl From<Reflectance> for ReflectanceRepr {
    fn from(r: Reflectance) -> Self {
        if r.nm.is_empty() {
            ReflectanceRepr::Constant(r.values[0])
        } else {
            ReflectanceRepr::Table { nm: r.nm, values: r.values }
        }
    }
}

impl Reflectance {
    /// The same fraction `value` at every wavelength.
    ///
    /// # Errors
    /// [`SpectrumError::ReflectanceOutOfRange`] unless `0 <= value <= 1`.
    pub fn constant(value: f64) -> Result<Self, SpectrumError> {
        check_fraction("constant", 0, value)?;
        Ok(Self { nm: Vec::new(), values: vec![value] })
    }

    /// A table of fractions at strictly increasing wavelengths.
    ///
    /// # Errors
    /// [`SpectrumError::Table`] naming `nm[i]` (empty, lengths differ, not finite, not
    /// increasing) and [`SpectrumError::ReflectanceOutOfRange`] naming `values[i]`.
    pub fn from_table(nm: &[f64], values: &[f64]) -> Result<Self, SpectrumError> {
        let table_error =
            |e: SamplingError| SpectrumError::Table { spectrum: "Reflectance", source: e };
        if nm.is_empty() {
            return Err(table_error(SamplingError::Empty { array: "nm" }));
        }
        if nm.len() != values.len() {
            return Err(table_error(SamplingError::LengthMismatch {
                first: "nm",
                first_len: nm.len(),
                second: "values",
                second_len: values.len(),
                expected: "equal lengths",
            }));
        }
        for (index, &value) in nm.iter().enumerate() {
            if value.is_nan() {
                return Err(table_error(SamplingError::NaN { array: "nm", index }));
            }
            if value.is_infinite() {
                return Err(table_error(SamplingError::Infinite { array: "nm", index, value }));
            }
            if index > 0 && value <= nm[index - 1] {
                return Err(table_error(SamplingError::NotIncreasing {
                    array: "nm",
                    index,
                    value,
                    previous: nm[index - 1],
                }));
            }
        }
        for (index, &value) in values.iter().enumerate() {
            check_fraction("values", index, value)?;
        }
        Ok(Self { nm: nm.to_vec(), values: values.to_vec() })
    }

    /// The fraction at `lambda` (nm); in `[0, 1]` for every input (NaN gives the first value).
    #[inline]
    pub fn value(&self, lambda: f64) -> f64 {
        let n = self.nm.len();
        if n <= 1 {
            return self.values[0];
        }
        if !(lambda > self.nm[0]) {
            return self.values[0];
        }
        if lambda >= self.nm[n - 1] {
            return self.values[n - 1];
        }
        let i = self.nm.partition_point(|&x| x <= lambda) - 1;
        let t = (lambda - self.nm[i]) / (self.nm[i + 1] - self.nm[i]);
        self.values[i] * (1.0 - t) + self.values[i + 1] * t
    }

    /// `true` if the fraction is the same at every wavelength.
    pub fn is_constant(&self) -> bool {
        self.values.iter().all(|&v| v == self.values[0])
    }

    /// The largest fraction at any wavelength.
    pub fn max_value(&self) -> f64 {
        self.values.iter().copied().fold(0.0, f64::max)
    }
}

fn check_fraction(field: &'static str, index: usize, value: f64) -> Result<(), SpectrumError> {
    if (0.0..=1.0).contains(&value) {
        Ok(())
    } else {
        Err(SpectrumError::ReflectanceOutOfRange { field, index, value })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolates_and_holds_the_ends() {
        let r = Reflectance::from_table(&[400.0, 500.0, 700.0], &[0.0, 1.0, 0.5]).unwrap();
        assert_eq!(r.value(300.0), 0.0);
        assert_eq!(r.value(450.0), 0.5);
        assert_eq!(r.value(600.0), 0.75);
        assert_eq!(r.value(900.0), 0.5);
        assert!(!r.is_constant());
        let c = Reflectance::constant(0.3).unwrap();
        assert_eq!(c.value(123.0), 0.3);
        assert!(c.is_constant());
    }

    #[test]
    fn rejects_values_outside_the_unit_interval_by_index() {
        let e = Reflectance::from_table(&[400.0, 500.0], &[0.5, 1.2]).unwrap_err();
        assert_eq!(e.to_string(), "values[1] = 1.2: a reflectance must lie in [0, 1]");
        assert!(Reflectance::constant(f64::NAN).is_err());
        assert!(Reflectance::constant(-0.1).is_err());
        let e = Reflectance::from_table(&[400.0, 400.0], &[0.5, 0.2]).unwrap_err();
        assert!(e.to_string().contains("nm[1]"), "{e}");
    }

    #[test]
    fn json_forms() {
        let c: Reflectance = serde_json::from_str("0.25").unwrap();
        assert_eq!(c.value(500.0), 0.25);
        let t: Reflectance =
            serde_json::from_str(r#"{"nm": [400, 700], "values": [0, 1]}"#).unwrap();
        assert_eq!(t.value(550.0), 0.5);
        assert_eq!(serde_json::to_string(&c).unwrap(), "0.25");
        assert!(serde_json::from_str::<Reflectance>("1.5").is_err());
    }

    #[test]
    fn bincode_round_trip() {
        let config = bincode::config::standard();
        for r in [
            Reflectance::constant(0.25).unwrap(),
            Reflectance::from_table(&[400.0, 700.0], &[0.1, 0.9]).unwrap(),
        ] {
            let bytes = bincode::serde::encode_to_vec(&r, config).unwrap();
            let (back, _): (Reflectance, usize) =
                bincode::serde::decode_from_slice(&bytes, config).unwrap();
            assert_eq!(back, r);
        }
    }
}
