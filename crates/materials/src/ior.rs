//! [`Ior`]: an index of refraction as a function of wavelength (dispersion).
//!
//! | JSON | law | units |
//! |---|---|---|
//! | `1.5` | constant `n` | |
//! | `{"sellmeier": {"b": [B1, B2, B3], "c": [C1, C2, C3]}}` | `n^2 = 1 + sum B_i l^2 / (l^2 - C_i)` | `l` in µm, `C_i` in µm², `B_i` dimensionless; any number of terms, `b` and `c` of equal length |
//! | `{"cauchy": {"a": A, "b": B, "c": C}}` | `n = A + B / l^2 + C / l^4` | `l` in **nm**, `B` in nm², `C` in nm⁴; `b` and `c` default to 0 |
//! | `{"table": {"nm": [...], "n": [...]}}` | linear between points, constant beyond the ends | nm |
//! | `{"glass": "BK7"}` | a named glass from the [catalog](crate::GLASSES) | |
//!
//! Every index is checked over [`VALID_MIN_NM`]-[`VALID_MAX_NM`] (360-830 nm): finite and
//! `>= 1` at every nanometre, and a Sellmeier pole (`l^2 = C_i`) inside the range is rejected.
//! Outside that range the law is evaluated as written; where it gives a non-finite value or
//! one below 1 (near a pole, or a Cauchy law at tiny wavelengths) the value at the nearest end of
//! the range is used instead, so [`Ior::n`] is finite and `>= 1` for every input.
//!
//! ```json
//! {"type": "Dielectric", "ior": {"sellmeier": {"b": [1.03961212, 0.231792344, 1.01046945],
//!                                              "c": [0.00600069867, 0.0200179144, 103.560653]}}}
//! ```

use serde::de::{self, MapAccess, Visitor};
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use crate::MaterialError;
use crate::glass::{Glass, find_glass, known_glasses};

/// Shortest wavelength (nm) at which every index is validated.
pub const VALID_MIN_NM: f64 = 360.0;
/// Longest wavelength (nm) at which every index is validated.
pub const VALID_MAX_NM: f64 = 830.0;
/// Helium d line (nm), where `n_d` is quoted.
pub const FRAUNHOFER_D_NM: f64 = 587.5618;
/// Hydrogen F line (nm).
pub const FRAUNHOFER_F_NM: f64 = 486.1327;
/// Hydrogen C line (nm).
pub const FRAUNHOFER_C_NM: f64 = 656.2725;

const IOR: &str = "Ior";

/// An index of refraction `n(lambda)`: constant, Sellmeier, Cauchy, tabulated or a named glass.
/// Validated when built (see the module documentation); immutable afterwards.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "IorRepr", into = "IorRepr")]
pub struct Ior {
    model: Model,
}

#[derive(Debug, Clone, PartialEq)]
enum Model {
    Constant(f64),
    Sellmeier { b: Vec<f64>, c: Vec<f64> },
    Cauchy { a: f64, b: f64, c: f64 },
    Table { nm: Vec<f64>, n: Vec<f64> },
    Glass(&'static Glass),
}

impl Ior {
    /// A constant index `n` (no dispersion).
    ///
    /// # Errors
    /// [`MaterialError::Parameter`] unless `n` is finite and `>= 1`.
    pub fn constant(n: f64) -> Result<Self, MaterialError> {
        if n.is_finite() && n >= 1.0 {
            Ok(Self { model: Model::Constant(n) })
        } else {
            Err(MaterialError::parameter(
                IOR,
                "",
                n,
                "an index of refraction must be finite and >= 1",
            ))
        }
    }

    /// A Sellmeier law `n^2 = 1 + sum B_i l^2 / (l^2 - C_i)`, `l` in µm, `C_i` in µm².
    ///
    /// # Errors
    /// [`MaterialError::Parameter`] naming `sellmeier.b[i]` / `sellmeier.c[i]` (non-finite, a pole
    /// inside 360-830 nm, lengths differ or empty) or `sellmeier` (the index is below 1 or not
    /// finite somewhere in 360-830 nm).
    pub fn sellmeier(b: &[f64], c: &[f64]) -> Result<Self, MaterialError> {
        if b.is_empty() {
            return Err(MaterialError::parameter(IOR, "sellmeier.b", b, "needs at least one term"));
        }
        if b.len() != c.len() {
            return Err(MaterialError::parameter(
                IOR,
                "sellmeier.c",
                c,
                format!("must have as many terms as b ({})", b.len()),
            ));
        }
        for (i, &bi) in b.iter().enumerate() {
            if !bi.is_finite() {
                return Err(MaterialError::parameter(
                    IOR,
                    format!("sellmeier.b[{i}]"),
                    bi,
                    "must be finite",
                ));
            }
        }
        let (lo, hi) = (VALID_MIN_NM * 1e-3, VALID_MAX_NM * 1e-3);
        for (i, &ci) in c.iter().enumerate() {
            if !ci.is_finite() {
                return Err(MaterialError::parameter(
                    IOR,
                    format!("sellmeier.c[{i}]"),
                    ci,
                    "must be finite (µm²)",
                ));
            }
            if ci >= lo * lo && ci <= hi * hi {
                return Err(MaterialError::parameter(
                    IOR,
                    format!("sellmeier.c[{i}]"),
                    ci,
                    format!(
                        "puts a pole at {:.1} nm, inside {VALID_MIN_NM}-{VALID_MAX_NM} nm (C is in µm²)",
                        ci.sqrt() * 1e3
                    ),
                ));
            }
        }
        Self::checked(Model::Sellmeier { b: b.to_vec(), c: c.to_vec() }, "sellmeier")
    }

    /// A Cauchy law `n = a + b / l^2 + c / l^4` with `l` in nm (`b` in nm², `c` in nm⁴).
    ///
    /// # Errors
    /// [`MaterialError::Parameter`] naming `cauchy.a`, `cauchy.b` or `cauchy.c` (not finite) or
    /// `cauchy` (the index is below 1 somewhere in 360-830 nm).
    pub fn cauchy(a: f64, b: f64, c: f64) -> Result<Self, MaterialError> {
        for (field, v) in [("cauchy.a", a), ("cauchy.b", b), ("cauchy.c", c)] {
            if !v.is_finite() {
                return Err(MaterialError::parameter(IOR, field, v, "must be finite"));
            }
        }
        Self::checked(Model::Cauchy { a, b, c }, "cauchy")
    }

    /// A table of indices `n` at strictly increasing wavelengths `nm`, linear in between and
    /// constant beyond the ends.
    ///
    /// # Errors
    /// [`MaterialError::Parameter`] naming `table.nm`, `table.nm[i]` (empty, not finite, not
    /// increasing), `table.n` (length differs) or `table.n[i]` (not finite or below 1).
    pub fn table(nm: &[f64], n: &[f64]) -> Result<Self, MaterialError> {
        if nm.is_empty() {
            return Err(MaterialError::parameter(IOR, "table.nm", nm, "needs at least one point"));
        }
        if nm.len() != n.len() {
            return Err(MaterialError::parameter(
                IOR,
                "table.n",
                n,
                format!("must have as many values as nm ({})", nm.len()),
            ));
        }
        for (i, &x) in nm.iter().enumerate() {
            if !x.is_finite() {
                return Err(MaterialError::parameter(
                    IOR,
                    format!("table.nm[{i}]"),
                    x,
                    "must be finite",
                ));
            }
            if i > 0 && !(x > nm[i - 1]) {
                return Err(MaterialError::parameter(
                    IOR,
                    format!("table.nm[{i}]"),
                    x,
                    format!("wavelengths must increase strictly (previous {})", nm[i - 1]),
                ));
            }
        }
        for (i, &v) in n.iter().enumerate() {
            if !(v.is_finite() && v >= 1.0) {
                return Err(MaterialError::parameter(
                    IOR,
                    format!("table.n[{i}]"),
                    v,
                    "an index of refraction must be finite and >= 1",
                ));
            }
        }
        Ok(Self { model: Model::Table { nm: nm.to_vec(), n: n.to_vec() } })
    }

    /// A named glass from the catalog ([`GLASSES`](crate::GLASSES)), by name or alias,
    /// case-insensitively: `"BK7"`, `"N-BK7"`, `"F2"`, `"SF11"`, `"FusedSilica"`, `"CaF2"`, ...
    ///
    /// # Errors
    /// [`MaterialError::UnknownGlass`] listing the known names.
    pub fn glass(name: &str) -> Result<Self, MaterialError> {
        match find_glass(name) {
            Some(g) => Ok(Self { model: Model::Glass(g) }),
            None => Err(MaterialError::UnknownGlass {
                material: IOR,
                field: "glass".to_owned(),
                name: name.to_owned(),
                known: known_glasses(),
            }),
        }
    }

    /// Checks a law over 360-830 nm at every nanometre.
    fn checked(model: Model, field: &'static str) -> Result<Self, MaterialError> {
        let ior = Self { model };
        let steps = (VALID_MAX_NM - VALID_MIN_NM) as usize;
        for k in 0..=steps {
            let lambda = VALID_MIN_NM + k as f64;
            let n = ior.raw(lambda);
            if !(n.is_finite() && n >= 1.0) {
                return Err(MaterialError::parameter(
                    IOR,
                    field,
                    format!("n({lambda} nm) = {n}"),
                    format!(
                        "the index must be finite and >= 1 over {VALID_MIN_NM}-{VALID_MAX_NM} nm"
                    ),
                ));
            }
        }
        Ok(ior)
    }

    /// The law as written, with no guard.
    #[inline]
    fn raw(&self, lambda: f64) -> f64 {
        match &self.model {
            Model::Constant(n) => *n,
            Model::Sellmeier { b, c } => sellmeier(b, c, lambda),
            Model::Cauchy { a, b, c } => {
                let l2 = lambda * lambda;
                a + b / l2 + c / (l2 * l2)
            }
            Model::Table { nm, n } => interpolate(nm, n, lambda),
            Model::Glass(g) => sellmeier(&g.b, &g.c, lambda),
        }
    }

    /// The index of refraction at `lambda` (nm): finite and `>= 1` for every input (see the
    /// module documentation for wavelengths outside 360-830 nm).
    #[inline]
    pub fn n(&self, lambda: f64) -> f64 {
        let n = self.raw(lambda);
        if n.is_finite() && n >= 1.0 {
            return n;
        }
        let nearest = if lambda >= VALID_MIN_NM { lambda.min(VALID_MAX_NM) } else { VALID_MIN_NM };
        let n = self.raw(nearest);
        if n.is_finite() && n >= 1.0 { n } else { 1.0 }
    }

    /// `true` if the index depends on the wavelength.
    pub fn is_dispersive(&self) -> bool {
        match &self.model {
            Model::Constant(_) => false,
            Model::Sellmeier { b, .. } => b.iter().any(|&x| x != 0.0),
            Model::Cauchy { b, c, .. } => *b != 0.0 || *c != 0.0,
            Model::Table { n, .. } => n.iter().any(|&x| x != n[0]),
            Model::Glass(_) => true,
        }
    }

    /// The Abbe number `V_d = (n_d - 1) / (n_F - n_C)` (d, F, C: the Fraunhofer lines at
    /// 587.56, 486.13 and 656.27 nm): large for weak dispersion (fused silica about 68), small
    /// for strong (dense flint about 25). `None` if the index does not vary between F and C.
    pub fn abbe_number(&self) -> Option<f64> {
        let spread = self.n(FRAUNHOFER_F_NM) - self.n(FRAUNHOFER_C_NM);
        let v = (self.n(FRAUNHOFER_D_NM) - 1.0) / spread;
        (spread != 0.0 && v.is_finite()).then_some(v)
    }

    /// The catalog entry, if this index is a named glass.
    pub fn catalog_glass(&self) -> Option<&'static Glass> {
        match self.model {
            Model::Glass(g) => Some(g),
            _ => None,
        }
    }
}

#[inline]
fn sellmeier(b: &[f64], c: &[f64], lambda_nm: f64) -> f64 {
    let l = lambda_nm * 1e-3;
    let l2 = l * l;
    let n2 = 1.0 + b.iter().zip(c).map(|(&bi, &ci)| bi * l2 / (l2 - ci)).sum::<f64>();
    n2.sqrt()
}

#[inline]
pub(crate) fn interpolate(xs: &[f64], ys: &[f64], x: f64) -> f64 {
    let last = xs.len() - 1;
    if last == 0 || !(x > xs[0]) {
        return ys[0];
    }
    if x >= xs[last] {
        return ys[last];
    }
    let i = xs.partition_point(|&v| v <= x) - 1;
    let t = (x - xs[i]) / (xs[i + 1] - xs[i]);
    ys[i] * (1.0 - t) + ys[i + 1] * t
}

// ---------------------------------------------------------------------------------------------
// Serialisation.

/// The laws with a name, as written in scene files (externally tagged: `{"sellmeier": ...}`).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub(crate) enum IorModelRepr {
    Sellmeier(SellmeierRepr),
    Cauchy(CauchyRepr),
    Table(TableRepr),
    Glass(String),
}

#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct SellmeierRepr {
    b: Vec<f64>,
    c: Vec<f64>,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct CauchyRepr {
    a: f64,
    #[serde(default)]
    b: f64,
    #[serde(default)]
    c: f64,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct TableRepr {
    nm: Vec<f64>,
    n: Vec<f64>,
}

/// Unvalidated scene-file form of [`Ior`]: a number or a named law. Human-readable formats see
/// the number bare; binary formats (bincode, not self-describing) get an externally tagged enum.
#[derive(Debug, Clone)]
pub(crate) enum IorRepr {
    Constant(f64),
    Model(IorModelRepr),
}

#[derive(Serialize)]
enum IorBinaryRef<'a> {
    Constant(f64),
    Model(&'a IorModelRepr),
}

#[derive(Deserialize)]
enum IorBinary {
    Constant(f64),
    Model(IorModelRepr),
}

impl Serialize for IorRepr {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        if serializer.is_human_readable() {
            match self {
                Self::Constant(n) => serializer.serialize_f64(*n),
                Self::Model(m) => m.serialize(serializer),
            }
        } else {
            match self {
                Self::Constant(n) => IorBinaryRef::Constant(*n),
                Self::Model(m) => IorBinaryRef::Model(m),
            }
            .serialize(serializer)
        }
    }
}

impl<'de> Deserialize<'de> for IorRepr {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        if deserializer.is_human_readable() {
            deserializer.deserialize_any(IorVisitor)
        } else {
            Ok(match IorBinary::deserialize(deserializer)? {
                IorBinary::Constant(n) => Self::Constant(n),
                IorBinary::Model(m) => Self::Model(m),
            })
        }
    }
}

/// Reads a number as a constant index and a map as a named law, so that a mistake inside a law
/// is reported as such (`unknown field`, `unknown variant`) rather than as "matched no form".
struct IorVisitor;

impl<'de> Visitor<'de> for IorVisitor {
    type Value = IorRepr;

    fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(
            "an index of refraction: a number, or {\"sellmeier\": ...}, {\"cauchy\": ...}, {\"table\": ...} or {\"glass\": name}",
        )
    }

    fn visit_f64<E: de::Error>(self, v: f64) -> Result<IorRepr, E> {
        Ok(IorRepr::Constant(v))
    }

    fn visit_i64<E: de::Error>(self, v: i64) -> Result<IorRepr, E> {
        Ok(IorRepr::Constant(v as f64))
    }

    fn visit_u64<E: de::Error>(self, v: u64) -> Result<IorRepr, E> {
        Ok(IorRepr::Constant(v as f64))
    }

    fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<IorRepr, A::Error> {
        IorModelRepr::deserialize(de::value::MapAccessDeserializer::new(map)).map(IorRepr::Model)
    }
}

impl TryFrom<IorRepr> for Ior {
    type Error = MaterialError;
    fn try_from(r: IorRepr) -> Result<Self, MaterialError> {
        match r {
            IorRepr::Constant(n) => Self::constant(n),
            IorRepr::Model(IorModelRepr::Sellmeier(s)) => Self::sellmeier(&s.b, &s.c),
            IorRepr::Model(IorModelRepr::Cauchy(c)) => Self::cauchy(c.a, c.b, c.c),
            IorRepr::Model(IorModelRepr::Table(t)) => Self::table(&t.nm, &t.n),
            IorRepr::Model(IorModelRepr::Glass(name)) => Self::glass(&name),
        }
    }
}

impl From<Ior> for IorRepr {
    fn from(ior: Ior) -> Self {
        match ior.model {
            Model::Constant(n) => Self::Constant(n),
            Model::Sellmeier { b, c } => {
                Self::Model(IorModelRepr::Sellmeier(SellmeierRepr { b, c }))
            }
            Model::Cauchy { a, b, c } => Self::Model(IorModelRepr::Cauchy(CauchyRepr { a, b, c })),
            Model::Table { nm, n } => Self::Model(IorModelRepr::Table(TableRepr { nm, n })),
            Model::Glass(g) => Self::Model(IorModelRepr::Glass(g.name.to_owned())),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constant_and_table() {
        assert_eq!(Ior::constant(1.5).unwrap().n(123.0), 1.5);
        assert!(!Ior::constant(1.5).unwrap().is_dispersive());
        assert!(Ior::constant(0.9).is_err());
        assert!(Ior::constant(f64::NAN).is_err());
        let t = Ior::table(&[400.0, 600.0], &[1.6, 1.5]).unwrap();
        assert_eq!(t.n(300.0), 1.6);
        assert!((t.n(500.0) - 1.55).abs() < 1e-15);
        assert_eq!(t.n(900.0), 1.5);
        assert!(t.is_dispersive());
    }

    #[test]
    fn guard_keeps_the_index_finite_outside_the_range() {
        let c = Ior::cauchy(1.5, 4200.0, 0.0).unwrap();
        assert_eq!(c.n(0.0), c.n(VALID_MIN_NM));
        assert_eq!(c.n(f64::NAN), c.n(VALID_MIN_NM));
        // N-BK7's IR pole is at about 10.2 µm: just below it n^2 < 0, and the guard uses 830 nm.
        let g = Ior::glass("BK7").unwrap();
        assert_eq!(g.n(10_000.0), g.n(VALID_MAX_NM));
        assert!(g.n(1064.0) > 1.5 && g.n(1064.0) < g.n(VALID_MAX_NM));
    }
}
