//! [`Reflectance`] and [`Transmittance`]: a fraction in `[0, 1]` per wavelength.
//!
//! Unlike an SPD it is not normalised and not sampled; materials multiply a beam's weight by it.
//!
//! | JSON | meaning |
//! |---|---|
//! | `0.8` | the same fraction at every wavelength |
//! | `{"nm": [400, 550, 700], "values": [0.1, 0.6, 0.9]}` | linear between the points, held constant beyond the first and last |
//!
//! Anything else is refused with a message that says what was expected and what was found, e.g.
//! `expected a reflectance: a number in [0, 1] or a table {"nm": [...], "values": [...]}, found a
//! string "0.5"`; an element of the table that is not a number is named (`values[2]: ...`), and
//! a transmittance's errors say "transmittance".

use std::fmt;

use serde::de::{self, DeserializeSeed, MapAccess, SeqAccess, Unexpected, Visitor};
use serde::{Deserialize, Serialize};

use crate::error::SpectrumError;
use crate::rgb::SigmoidSpectrum;
use spectrace_sampling::{GridLocator, SamplingError};

/// A spectral reflectance: a fraction in `[0, 1]` at each wavelength, linear between tabulated
/// points and constant beyond the ends.
#[derive(Debug, Clone, PartialEq)]
pub struct Reflectance {
    nm: Vec<f64>,
    values: Vec<f64>,
    /// Finds the segment of a wavelength (in `O(1)` on evenly spaced tables).
    locator: GridLocator,
    /// A smooth spectrum from a colour instead of the table (a texel: built without
    /// allocating, see [`Reflectance::from_sigmoid`]).
    sigmoid: Option<SigmoidSpectrum>,
}

/// A spectral transmittance: the same representation and rules as a [`Reflectance`], but its
/// errors say "transmittance".
#[derive(Debug, Clone, PartialEq)]
pub struct Transmittance(Reflectance);

/// Which quantity a fraction spectrum is, for messages.
#[derive(Debug, Clone, Copy)]
struct Kind {
    /// The type name, e.g. `"Reflectance"`.
    spectrum: &'static str,
    /// The quantity in prose, e.g. `"reflectance"`.
    quantity: &'static str,
}

const REFLECTANCE: Kind = Kind { spectrum: "Reflectance", quantity: "reflectance" };
const TRANSMITTANCE: Kind = Kind { spectrum: "Transmittance", quantity: "transmittance" };

/// Plain form of a fraction spectrum, for serialisation.
enum FractionRepr {
    Constant(f64),
    Table { nm: Vec<f64>, values: Vec<f64> },
}

/// Binary form (externally tagged: formats such as bincode are not self-describing).
#[derive(Serialize, Deserialize)]
enum ReflectanceBinary {
    Constant(f64),
    Table { nm: Vec<f64>, values: Vec<f64> },
}

impl From<&Reflectance> for FractionRepr {
    fn from(r: &Reflectance) -> Self {
        if let Some(s) = &r.sigmoid {
            let (nm, values) = s.table();
            FractionRepr::Table { nm, values }
        } else if r.nm.is_empty() {
            FractionRepr::Constant(r.values.first().copied().unwrap_or(0.0))
        } else {
            FractionRepr::Table { nm: r.nm.clone(), values: r.values.clone() }
        }
    }
}

/// Serialises a fraction spectrum: a number or `{"nm", "values"}` for human-readable formats,
/// an externally tagged enum otherwise.
fn serialize_fraction<S: serde::Serializer>(
    r: &Reflectance,
    serializer: S,
) -> Result<S::Ok, S::Error> {
    use serde::ser::SerializeStruct;
    let repr = FractionRepr::from(r);
    if serializer.is_human_readable() {
        match repr {
            FractionRepr::Constant(v) => serializer.serialize_f64(v),
            FractionRepr::Table { nm, values } => {
                let mut st = serializer.serialize_struct("Reflectance", 2)?;
                st.serialize_field("nm", &nm)?;
                st.serialize_field("values", &values)?;
                st.end()
            }
        }
    } else {
        match repr {
            FractionRepr::Constant(v) => ReflectanceBinary::Constant(v),
            FractionRepr::Table { nm, values } => ReflectanceBinary::Table { nm, values },
        }
        .serialize(serializer)
    }
}

/// Deserialises a fraction spectrum of the given kind, with messages that name the quantity,
/// what was expected and what was found.
fn deserialize_fraction<'de, D: serde::Deserializer<'de>>(
    deserializer: D,
    kind: Kind,
) -> Result<Reflectance, D::Error> {
    if deserializer.is_human_readable() {
        deserializer.deserialize_any(FractionVisitor { kind })
    } else {
        match ReflectanceBinary::deserialize(deserializer)? {
            ReflectanceBinary::Constant(v) => Reflectance::constant_of(kind, v),
            ReflectanceBinary::Table { nm, values } => Reflectance::table_of(kind, &nm, &values),
        }
        .map_err(de::Error::custom)
    }
}

/// `a string "0.5"`, `an array`, `null`: what the input held instead, for messages.
fn found(unexpected: Unexpected<'_>) -> String {
    match unexpected {
        Unexpected::Str(s) => format!("a string {s:?}"),
        Unexpected::Bool(b) => format!("a boolean {b}"),
        Unexpected::Unit | Unexpected::Option => "null".to_owned(),
        Unexpected::Seq => "an array".to_owned(),
        Unexpected::Map => "a table".to_owned(),
        Unexpected::Float(x) => format!("the number {x}"),
        Unexpected::Unsigned(x) => format!("the number {x}"),
        Unexpected::Signed(x) => format!("the number {x}"),
        other => other.to_string(),
    }
}

/// Visits a whole fraction spectrum: a number or a table.
struct FractionVisitor {
    kind: Kind,
}

impl FractionVisitor {
    fn wrong<E: de::Error>(&self, unexpected: Unexpected<'_>) -> E {
        E::custom(format_args!("expected {self}, found {}", found(unexpected)))
    }
}

impl fmt::Display for FractionVisitor {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "a {}: a number in [0, 1] or a table {{\"nm\": [...], \"values\": [...]}}",
            self.kind.quantity
        )
    }
}

impl<'de> Visitor<'de> for FractionVisitor {
    type Value = Reflectance;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Display::fmt(self, f)
    }

    fn visit_f64<E: de::Error>(self, v: f64) -> Result<Reflectance, E> {
        Reflectance::constant_of(self.kind, v).map_err(E::custom)
    }

    fn visit_u64<E: de::Error>(self, v: u64) -> Result<Reflectance, E> {
        self.visit_f64(v as f64)
    }

    fn visit_i64<E: de::Error>(self, v: i64) -> Result<Reflectance, E> {
        self.visit_f64(v as f64)
    }

    fn visit_str<E: de::Error>(self, v: &str) -> Result<Reflectance, E> {
        Err(self.wrong(Unexpected::Str(v)))
    }

    fn visit_bool<E: de::Error>(self, v: bool) -> Result<Reflectance, E> {
        Err(self.wrong(Unexpected::Bool(v)))
    }

    fn visit_unit<E: de::Error>(self) -> Result<Reflectance, E> {
        Err(self.wrong(Unexpected::Unit))
    }

    fn visit_none<E: de::Error>(self) -> Result<Reflectance, E> {
        Err(self.wrong(Unexpected::Unit))
    }

    fn visit_seq<A: SeqAccess<'de>>(self, _seq: A) -> Result<Reflectance, A::Error> {
        Err(self.wrong(Unexpected::Seq))
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Reflectance, A::Error> {
        const FIELDS: &[&str] = &["nm", "values"];
        let (mut nm, mut values) = (None, None);
        while let Some(key) = map.next_key::<String>()? {
            let slot = match key.as_str() {
                "nm" => &mut nm,
                "values" => &mut values,
                other => return Err(de::Error::unknown_field(other, FIELDS)),
            };
            if slot.is_some() {
                return Err(de::Error::custom(format_args!(
                    "duplicate field `{key}` in a {} table",
                    self.kind.quantity
                )));
            }
            let field = if key == "nm" { "nm" } else { "values" };
            *slot = Some(map.next_value_seed(NumbersSeed { field })?);
        }
        let nm = nm.ok_or_else(|| {
            de::Error::custom(format_args!(
                "a {} table needs `nm` (wavelengths) as well as `values`",
                self.kind.quantity
            ))
        })?;
        let values = values.ok_or_else(|| {
            de::Error::custom(format_args!(
                "a {} table needs `values` as well as `nm` (wavelengths)",
                self.kind.quantity
            ))
        })?;
        Reflectance::table_of(self.kind, &nm, &values).map_err(de::Error::custom)
    }
}

/// An array of numbers, each error naming `field[i]`.
struct NumbersSeed {
    field: &'static str,
}

impl<'de> DeserializeSeed<'de> for NumbersSeed {
    type Value = Vec<f64>;
    fn deserialize<D: serde::Deserializer<'de>>(self, d: D) -> Result<Vec<f64>, D::Error> {
        d.deserialize_any(self)
    }
}

impl NumbersSeed {
    fn wrong<E: de::Error>(&self, unexpected: Unexpected<'_>) -> E {
        E::custom(format_args!(
            "{}: expected an array of numbers, found {}",
            self.field,
            found(unexpected)
        ))
    }
}

impl<'de> Visitor<'de> for NumbersSeed {
    type Value = Vec<f64>;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "an array of numbers for `{}`", self.field)
    }

    fn visit_f64<E: de::Error>(self, v: f64) -> Result<Vec<f64>, E> {
        Err(self.wrong(Unexpected::Float(v)))
    }

    fn visit_u64<E: de::Error>(self, v: u64) -> Result<Vec<f64>, E> {
        Err(self.wrong(Unexpected::Unsigned(v)))
    }

    fn visit_i64<E: de::Error>(self, v: i64) -> Result<Vec<f64>, E> {
        Err(self.wrong(Unexpected::Signed(v)))
    }

    fn visit_str<E: de::Error>(self, v: &str) -> Result<Vec<f64>, E> {
        Err(self.wrong(Unexpected::Str(v)))
    }

    fn visit_bool<E: de::Error>(self, v: bool) -> Result<Vec<f64>, E> {
        Err(self.wrong(Unexpected::Bool(v)))
    }

    fn visit_unit<E: de::Error>(self) -> Result<Vec<f64>, E> {
        Err(self.wrong(Unexpected::Unit))
    }

    fn visit_none<E: de::Error>(self) -> Result<Vec<f64>, E> {
        Err(self.wrong(Unexpected::Unit))
    }

    fn visit_map<A: MapAccess<'de>>(self, _map: A) -> Result<Vec<f64>, A::Error> {
        Err(self.wrong(Unexpected::Map))
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Vec<f64>, A::Error> {
        // The size hint comes from the input; cap it so a hostile hint cannot allocate much.
        let mut out = Vec::with_capacity(seq.size_hint().unwrap_or(0).min(4096));
        while let Some(x) =
            seq.next_element_seed(NumberSeed { field: self.field, index: out.len() })?
        {
            out.push(x);
        }
        Ok(out)
    }
}

/// One number of a table, its error naming `field[index]`.
struct NumberSeed {
    field: &'static str,
    index: usize,
}

impl<'de> DeserializeSeed<'de> for NumberSeed {
    type Value = f64;
    fn deserialize<D: serde::Deserializer<'de>>(self, d: D) -> Result<f64, D::Error> {
        d.deserialize_any(self)
    }
}

impl NumberSeed {
    fn wrong<E: de::Error>(&self, unexpected: Unexpected<'_>) -> E {
        E::custom(format_args!(
            "{}[{}]: expected a number, found {}",
            self.field,
            self.index,
            found(unexpected)
        ))
    }
}

impl<'de> Visitor<'de> for NumberSeed {
    type Value = f64;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "a number for `{}[{}]`", self.field, self.index)
    }

    fn visit_f64<E: de::Error>(self, v: f64) -> Result<f64, E> {
        Ok(v)
    }

    fn visit_u64<E: de::Error>(self, v: u64) -> Result<f64, E> {
        Ok(v as f64)
    }

    fn visit_i64<E: de::Error>(self, v: i64) -> Result<f64, E> {
        Ok(v as f64)
    }

    fn visit_str<E: de::Error>(self, v: &str) -> Result<f64, E> {
        Err(self.wrong(Unexpected::Str(v)))
    }

    fn visit_bool<E: de::Error>(self, v: bool) -> Result<f64, E> {
        Err(self.wrong(Unexpected::Bool(v)))
    }

    fn visit_unit<E: de::Error>(self) -> Result<f64, E> {
        Err(self.wrong(Unexpected::Unit))
    }

    fn visit_none<E: de::Error>(self) -> Result<f64, E> {
        Err(self.wrong(Unexpected::Unit))
    }

    fn visit_seq<A: SeqAccess<'de>>(self, _seq: A) -> Result<f64, A::Error> {
        Err(self.wrong(Unexpected::Seq))
    }

    fn visit_map<A: MapAccess<'de>>(self, _map: A) -> Result<f64, A::Error> {
        Err(self.wrong(Unexpected::Map))
    }
}

impl Serialize for Reflectance {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serialize_fraction(self, serializer)
    }
}

impl<'de> Deserialize<'de> for Reflectance {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserialize_fraction(deserializer, REFLECTANCE)
    }
}

impl Serialize for Transmittance {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serialize_fraction(&self.0, serializer)
    }
}

impl<'de> Deserialize<'de> for Transmittance {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserialize_fraction(deserializer, TRANSMITTANCE).map(Self)
    }
}

impl From<Reflectance> for Transmittance {
    fn from(r: Reflectance) -> Self {
        Self(r)
    }
}

impl Transmittance {
    /// The same fraction `value` at every wavelength.
    ///
    /// # Errors
    /// [`SpectrumError::ReflectanceOutOfRange`] (saying "transmittance") unless `0 <= value <= 1`.
    pub fn constant(value: f64) -> Result<Self, SpectrumError> {
        Reflectance::constant_of(TRANSMITTANCE, value).map(Self)
    }

    /// A table of fractions at strictly increasing wavelengths.
    ///
    /// # Errors
    /// As [`Reflectance::from_table`], the messages saying "Transmittance".
    pub fn from_table(nm: &[f64], values: &[f64]) -> Result<Self, SpectrumError> {
        Reflectance::table_of(TRANSMITTANCE, nm, values).map(Self)
    }

    /// The fraction at `lambda` (nm); in `[0, 1]` for every input.
    #[inline]
    pub fn value(&self, lambda: f64) -> f64 {
        self.0.value(lambda)
    }

    /// `true` if the fraction is the same at every wavelength.
    pub fn is_constant(&self) -> bool {
        self.0.is_constant()
    }

    /// The largest fraction at any wavelength.
    pub fn max_value(&self) -> f64 {
        self.0.max_value()
    }

    /// The same fractions as a [`Reflectance`].
    pub fn as_reflectance(&self) -> &Reflectance {
        &self.0
    }
}

impl Reflectance {
    /// The same fraction `value` at every wavelength.
    ///
    /// # Errors
    /// [`SpectrumError::ReflectanceOutOfRange`] unless `0 <= value <= 1`.
    pub fn constant(value: f64) -> Result<Self, SpectrumError> {
        Self::constant_of(REFLECTANCE, value)
    }

    /// [`Reflectance::constant`] with messages for `kind`.
    /// The fraction 1 at every wavelength (a white, lossless surface).
    pub fn white() -> Self {
        Self { nm: Vec::new(), values: vec![1.0], locator: GridLocator::default(), sigmoid: None }
    }

    fn constant_of(kind: Kind, value: f64) -> Result<Self, SpectrumError> {
        check_fraction(kind, "constant", 0, value)?;
        Ok(Self {
            nm: Vec::new(),
            values: vec![value],
            locator: GridLocator::default(),
            sigmoid: None,
        })
    }

    /// The smooth reflectance `s` (a colour's spectrum, e.g. a texel's from
    /// [`crate::RgbTable`]); allocates nothing, so a renderer may build one per surface hit.
    pub fn from_sigmoid(s: SigmoidSpectrum) -> Self {
        Self {
            nm: Vec::new(),
            values: Vec::new(),
            locator: GridLocator::default(),
            sigmoid: Some(s),
        }
    }

    /// A table of fractions at strictly increasing wavelengths.
    ///
    /// # Errors
    /// [`SpectrumError::Table`] naming `nm[i]` (empty, lengths differ, not finite, not
    /// increasing) and [`SpectrumError::ReflectanceOutOfRange`] naming `values[i]`.
    pub fn from_table(nm: &[f64], values: &[f64]) -> Result<Self, SpectrumError> {
        Self::table_of(REFLECTANCE, nm, values)
    }

    /// [`Reflectance::from_table`] with messages for `kind`.
    fn table_of(kind: Kind, nm: &[f64], values: &[f64]) -> Result<Self, SpectrumError> {
        let table_error =
            |e: SamplingError| SpectrumError::Table { spectrum: kind.spectrum, source: e };
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
            check_fraction(kind, "values", index, value)?;
        }
        Ok(Self {
            nm: nm.to_vec(),
            values: values.to_vec(),
            locator: GridLocator::new(nm),
            sigmoid: None,
        })
    }

    /// The fraction at `lambda` (nm); in `[0, 1]` for every input (NaN gives the first value).
    #[inline]
    pub fn value(&self, lambda: f64) -> f64 {
        let n = self.nm.len();
        if n <= 1 {
            return match &self.sigmoid {
                Some(s) => s.value(lambda),
                None => self.values[0],
            };
        }
        if !(lambda > self.nm[0]) {
            return self.values[0];
        }
        if lambda >= self.nm[n - 1] {
            return self.values[n - 1];
        }
        let i = self.locator.last_at_or_below(&self.nm, lambda);
        let t = (lambda - self.nm[i]) / (self.nm[i + 1] - self.nm[i]);
        self.values[i] * (1.0 - t) + self.values[i + 1] * t
    }

    /// `true` if the fraction is the same at every wavelength.
    pub fn is_constant(&self) -> bool {
        match &self.sigmoid {
            Some(s) => s.value(400.0) == s.value(700.0) && s.value(400.0) == s.value(550.0),
            None => self.values.iter().all(|&v| v == self.values[0]),
        }
    }

    /// The largest fraction at any wavelength (for a smooth spectrum: over its 5 nm table).
    pub fn max_value(&self) -> f64 {
        match &self.sigmoid {
            Some(s) => s.table().1.into_iter().fold(0.0, f64::max),
            None => self.values.iter().copied().fold(0.0, f64::max),
        }
    }
}

fn check_fraction(
    kind: Kind,
    field: &'static str,
    index: usize,
    value: f64,
) -> Result<(), SpectrumError> {
    if (0.0..=1.0).contains(&value) {
        Ok(())
    } else {
        Err(SpectrumError::ReflectanceOutOfRange { quantity: kind.quantity, field, index, value })
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

    fn json_error(json: &str) -> String {
        serde_json::from_str::<Reflectance>(json).unwrap_err().to_string()
    }

    #[test]
    fn json_errors_say_what_was_expected_and_what_was_found() {
        let e = json_error(r#""0.5""#);
        assert!(
            e.starts_with(
                r#"expected a reflectance: a number in [0, 1] or a table {"nm": [...], "values": [...]}, found a string "0.5""#
            ),
            "{e}"
        );
        let e = json_error(r#"["NaN"]"#);
        assert!(e.contains("expected a reflectance") && e.contains("found an array"), "{e}");
        let e = json_error("null");
        assert!(e.contains("found null"), "{e}");
        let e = json_error(r#"{"nm": [400, 700], "values": [0.5, "NaN"]}"#);
        assert!(e.starts_with(r#"values[1]: expected a number, found a string "NaN""#), "{e}");
        let e = json_error(r#"{"nm": [400, true], "values": [0.5, 0.5]}"#);
        assert!(e.starts_with("nm[1]: expected a number, found a boolean true"), "{e}");
        let e = json_error(r#"{"nm": 400, "values": [0.5]}"#);
        assert!(e.starts_with("nm: expected an array of numbers, found the number 400"), "{e}");
        let e = json_error(r#"{"nm": [400], "values": [0.5], "colour": 1}"#);
        assert!(e.contains("unknown field `colour`"), "{e}");
        let e = json_error(r#"{"values": [0.5]}"#);
        assert!(e.contains("needs `nm`"), "{e}");
        let e = json_error(r#"{"nm": [400], "nm": [500], "values": [0.5]}"#);
        assert!(e.contains("duplicate field `nm`"), "{e}");
        let e = json_error(r#"{"nm": [400, 700], "values": [0.5, 2]}"#);
        assert!(e.starts_with("values[1] = 2: a reflectance must lie in [0, 1]"), "{e}");
    }

    #[test]
    fn transmittance_errors_say_transmittance() {
        let e = Transmittance::constant(1.5).unwrap_err().to_string();
        assert_eq!(e, "constant[0] = 1.5: a transmittance must lie in [0, 1]");
        let e = serde_json::from_str::<Transmittance>("1.5").unwrap_err().to_string();
        assert!(e.contains("a transmittance must lie in [0, 1]"), "{e}");
        let e = serde_json::from_str::<Transmittance>("true").unwrap_err().to_string();
        assert!(e.starts_with("expected a transmittance: "), "{e}");
        let t: Transmittance =
            serde_json::from_str(r#"{"nm": [400, 700], "values": [0, 1]}"#).unwrap();
        assert_eq!(t.value(550.0), 0.5);
        assert_eq!(
            serde_json::to_string(&t).unwrap(),
            r#"{"nm":[400.0,700.0],"values":[0.0,1.0]}"#
        );
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
        let t = Transmittance::from_table(&[400.0, 700.0], &[0.1, 0.9]).unwrap();
        let bytes = bincode::serde::encode_to_vec(&t, config).unwrap();
        let (back, _): (Transmittance, usize) =
            bincode::serde::decode_from_slice(&bytes, config).unwrap();
        assert_eq!(back, t);
    }
}
