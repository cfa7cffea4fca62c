//! The catalog of measured metals and [`ComplexIor`], the complex index of refraction
//! `eta(lambda) + i k(lambda)` of a conductor.
//!
//! | symbol | metal | measurement (see `data/metals/README.md`) | range (nm) |
//! |---|---|---|---|
//! | `Ag` | silver | McPeak et al. 2015 | 350-850 |
//! | `Al` | aluminium | McPeak et al. 2015 | 350-850 |
//! | `Au` | gold | McPeak et al. 2015 | 350-850 |
//! | `Cr` | chromium | Palik 1985 | 341.5-861 |
//! | `Cu` | copper | McPeak et al. 2015 | 350-850 |
//! | `Ni` | nickel | Johnson & Christy 1974 | 342-892 |
//! | `Pt` | platinum | Tselin et al. 2024 | 349-850.7 |
//! | `Ti` | titanium | Johnson & Christy 1974 | 342-892 |
//! | `W` | tungsten | Palik 1985 | 349.2-855 |
//!
//! The tables are the published `nm, n, k` rows, embedded in the binary (`include_str!`) and
//! parsed once on first use. Symbols are matched as written (`"Au"`, not `"au"`).
//!
//! A scene file gives a conductor's index either as a catalog metal or as two tables:
//!
//! ```json
//! {"type": "Conductor", "metal": "Au"}
//! {"type": "Conductor", "eta": {"nm": [400, 700], "values": [1.5, 0.2]},
//!                       "k":   {"nm": [400, 700], "values": [1.9, 3.9]}}
//! ```
//!
//! Both `eta` and `k` are interpolated linearly in nm between their points and held at the end
//! values beyond the first and last point (the catalog covers about 350-850 nm, the whole
//! visible range; outside it the end values are used). A table needs at least one point, equal
//! lengths of `nm` and `values`, strictly increasing finite wavelengths, and finite values
//! `> 0` (a conductor's `k` is positive: `k = 0` would be a lossless dielectric whose
//! transmitted light this opaque material would silently discard).

use std::sync::LazyLock;

use crate::MaterialError;
use crate::ior::interpolate;
use crate::microfacet::fresnel_conductor;

/// One measured metal of the catalog: its symbol, name, source and `nm, n, k` table.
#[derive(Debug, Clone, PartialEq)]
pub struct Metal {
    /// Chemical symbol, as written in scene files: `"Au"`.
    pub symbol: &'static str,
    /// English name: `"Gold"`.
    pub name: String,
    /// The measurement the table comes from (the `# source:` line of its file).
    pub source: String,
    /// Wavelengths (nm), strictly increasing.
    pub nm: Vec<f64>,
    /// Real part `n` of the index at each wavelength.
    pub n: Vec<f64>,
    /// Extinction coefficient `k` at each wavelength.
    pub k: Vec<f64>,
}

impl Metal {
    /// The real part of the index at `lambda` (nm), linear in nm, end values held outside.
    pub fn eta(&self, lambda: f64) -> f64 {
        interpolate(&self.nm, &self.n, lambda)
    }

    /// The extinction coefficient at `lambda` (nm), linear in nm, end values held outside.
    pub fn k(&self, lambda: f64) -> f64 {
        interpolate(&self.nm, &self.k, lambda)
    }
}

/// The embedded files: symbol and contents.
const FILES: [(&str, &str); 9] = [
    ("Ag", include_str!("../data/metals/Ag.csv")),
    ("Al", include_str!("../data/metals/Al.csv")),
    ("Au", include_str!("../data/metals/Au.csv")),
    ("Cr", include_str!("../data/metals/Cr.csv")),
    ("Cu", include_str!("../data/metals/Cu.csv")),
    ("Ni", include_str!("../data/metals/Ni.csv")),
    ("Pt", include_str!("../data/metals/Pt.csv")),
    ("Ti", include_str!("../data/metals/Ti.csv")),
    ("W", include_str!("../data/metals/W.csv")),
];

/// The parsed catalog (every file parses: the tests check it and that none is missing).
static CATALOG: LazyLock<Vec<Metal>> = LazyLock::new(|| {
    FILES.iter().filter_map(|&(symbol, text)| parse_metal(symbol, text)).collect()
});

/// Parses one embedded file: `#` header lines (the first `# Name (Symbol): ...`, one
/// `# source: ...`), the column line `nm,n,k`, then rows. `None` if any row is malformed (a
/// table that does not parse is left out of the catalog rather than half-read).
fn parse_metal(symbol: &'static str, text: &str) -> Option<Metal> {
    let mut name = String::new();
    let mut source = String::new();
    let (mut nm, mut n, mut k) = (Vec::new(), Vec::new(), Vec::new());
    for line in text.lines().map(str::trim) {
        if let Some(comment) = line.strip_prefix('#') {
            let comment = comment.trim();
            if let Some(s) = comment.strip_prefix("source:") {
                source = s.trim().to_owned();
            } else if name.is_empty()
                && let Some((head, _)) = comment.split_once(" (")
            {
                name = head.to_owned();
            }
            continue;
        }
        if line.is_empty() || line == "nm,n,k" {
            continue;
        }
        let mut fields = line.split(',').map(|f| f.trim().parse::<f64>().ok());
        let (Some(Some(x)), Some(Some(re)), Some(Some(im)), None) =
            (fields.next(), fields.next(), fields.next(), fields.next())
        else {
            return None;
        };
        nm.push(x);
        n.push(re);
        k.push(im);
    }
    check_table(&nm, &n).ok()?;
    check_table(&nm, &k).ok()?;
    Some(Metal { symbol, name, source, nm, n, k })
}

/// Every metal of the catalog, in alphabetical order of symbol.
pub fn metals() -> &'static [Metal] {
    &CATALOG
}

/// The catalog metal with this symbol, matched exactly (`"Au"`).
pub fn find_metal(symbol: &str) -> Option<&'static Metal> {
    CATALOG.iter().find(|m| m.symbol == symbol)
}

/// Every catalog symbol, comma-separated, for error messages: `"Ag, Al, Au, ..."`.
pub fn known_metals() -> String {
    CATALOG.iter().map(|m| m.symbol).collect::<Vec<_>>().join(", ")
}

/// Where a table failed: `(field within the table, value, reason)`.
type TableFault = (String, String, String);

/// Checks a `nm` / `values` pair: non-empty, equal lengths, `nm` finite and strictly
/// increasing, values finite and `> 0`.
fn check_table(nm: &[f64], values: &[f64]) -> Result<(), TableFault> {
    if nm.is_empty() {
        return Err(("nm".into(), format!("{nm:?}"), "needs at least one point".into()));
    }
    if nm.len() != values.len() {
        return Err((
            "values".into(),
            format!("{values:?}"),
            format!(
                "has {} values but nm has {} wavelengths; they must be equally long",
                values.len(),
                nm.len()
            ),
        ));
    }
    for (i, &x) in nm.iter().enumerate() {
        if !x.is_finite() {
            return Err((format!("nm[{i}]"), format!("{x:?}"), "must be finite (nm)".into()));
        }
        if i > 0 && !(x > nm[i - 1]) {
            return Err((
                format!("nm[{i}]"),
                format!("{x:?}"),
                format!("wavelengths must increase strictly (previous {})", nm[i - 1]),
            ));
        }
    }
    for (i, &v) in values.iter().enumerate() {
        if !(v.is_finite() && v > 0.0) {
            return Err((
                format!("values[{i}]"),
                format!("{v:?}"),
                "must be finite and > 0 (non-positive values are rejected)".into(),
            ));
        }
    }
    Ok(())
}

/// A tabulated spectrum of `eta` or `k` given by the user.
#[derive(Debug, Clone, PartialEq)]
struct Table {
    nm: Vec<f64>,
    values: Vec<f64>,
}

#[derive(Debug, Clone, PartialEq)]
enum Source {
    Metal(&'static Metal),
    Tables { eta: Table, k: Table },
}

/// The complex index of refraction `eta(lambda) + i k(lambda)` of a conductor, relative to the
/// vacuum around it: a catalog metal or user tables. Validated when built.
#[derive(Debug, Clone, PartialEq)]
pub struct ComplexIor {
    source: Source,
}

const COMPLEX_IOR: &str = "ComplexIor";

impl ComplexIor {
    /// The measured metal with this symbol from the catalog ([`metals`]), e.g. `"Au"`.
    ///
    /// # Errors
    /// [`MaterialError::UnknownMetal`] (field `metal`) listing the known symbols.
    pub fn metal(symbol: &str) -> Result<Self, MaterialError> {
        match find_metal(symbol) {
            Some(m) => Ok(Self { source: Source::Metal(m) }),
            None => Err(MaterialError::UnknownMetal {
                material: COMPLEX_IOR,
                field: "metal".to_owned(),
                name: symbol.to_owned(),
                known: known_metals(),
            }),
        }
    }

    /// An index from two tables, `eta` at wavelengths `eta_nm` and `k` at `k_nm` (the two
    /// tables may use different wavelengths).
    ///
    /// # Errors
    /// [`MaterialError::Parameter`] naming e.g. `eta.values[3]` (not finite or `<= 0`),
    /// `k.nm[2]` (not finite or not increasing), `eta.values` (length differs from `eta.nm`) or
    /// `k.nm` (empty).
    pub fn tables(
        eta_nm: &[f64],
        eta: &[f64],
        k_nm: &[f64],
        k: &[f64],
    ) -> Result<Self, MaterialError> {
        for (name, nm, values) in [("eta", eta_nm, eta), ("k", k_nm, k)] {
            check_table(nm, values).map_err(|(field, value, reason)| MaterialError::Parameter {
                material: COMPLEX_IOR,
                field: format!("{name}.{field}"),
                value,
                reason,
            })?;
        }
        Ok(Self {
            source: Source::Tables {
                eta: Table { nm: eta_nm.to_vec(), values: eta.to_vec() },
                k: Table { nm: k_nm.to_vec(), values: k.to_vec() },
            },
        })
    }

    /// The real part of the index at `lambda` (nm): finite and `> 0` for every input.
    #[inline]
    pub fn eta(&self, lambda: f64) -> f64 {
        match &self.source {
            Source::Metal(m) => m.eta(lambda),
            Source::Tables { eta, .. } => interpolate(&eta.nm, &eta.values, lambda),
        }
    }

    /// The extinction coefficient at `lambda` (nm): finite and `> 0` for every input.
    #[inline]
    pub fn k(&self, lambda: f64) -> f64 {
        match &self.source {
            Source::Metal(m) => m.k(lambda),
            Source::Tables { k, .. } => interpolate(&k.nm, &k.values, lambda),
        }
    }

    /// The unpolarised Fresnel reflectance at `lambda` (nm) for light arriving at `cos_i`
    /// ([`fresnel_conductor`]; `|cos_i|` is used).
    #[inline]
    pub fn reflectance(&self, cos_i: f64, lambda: f64) -> f64 {
        fresnel_conductor(cos_i, self.eta(lambda), self.k(lambda))
    }

    /// The catalog metal, if the index is one.
    pub fn catalog_metal(&self) -> Option<&'static Metal> {
        match self.source {
            Source::Metal(m) => Some(m),
            Source::Tables { .. } => None,
        }
    }

    /// The user tables `((eta nm, eta values), (k nm, k values))`, if the index is not a
    /// catalog metal.
    #[allow(clippy::type_complexity)]
    pub fn user_tables(&self) -> Option<((&[f64], &[f64]), (&[f64], &[f64]))> {
        match &self.source {
            Source::Metal(_) => None,
            Source::Tables { eta, k } => Some(((&eta.nm, &eta.values), (&k.nm, &k.values))),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_file_parses_into_the_catalog() {
        assert_eq!(metals().len(), FILES.len());
        for (m, (symbol, _)) in metals().iter().zip(FILES) {
            assert_eq!(m.symbol, symbol);
            assert!(!m.name.is_empty() && !m.source.is_empty(), "{m:?}");
            assert!(m.nm.len() >= 2);
        }
        assert_eq!(find_metal("Au").map(|m| m.name.as_str()), Some("Gold"));
        assert!(find_metal("au").is_none());
        assert_eq!(known_metals(), "Ag, Al, Au, Cr, Cu, Ni, Pt, Ti, W");
    }

    #[test]
    fn a_malformed_file_is_left_out() {
        assert!(parse_metal("X", "# X (X): x\n# source: s\nnm,n,k\n400,1,2\n500,1\n").is_none());
        assert!(parse_metal("X", "# X (X): x\nnm,n,k\n400,1,2\n500,1,0\n").is_none());
        assert!(parse_metal("X", "# X (X): x\nnm,n,k\n400,1,2\n500,1,2,3\n").is_none());
        let ok = parse_metal("X", "# Xium (X): x\n# source: s\nnm,n,k\n400,1,2\n500,1,3\n");
        assert_eq!(ok.map(|m| (m.name, m.k)), Some(("Xium".to_owned(), vec![2.0, 3.0])));
    }
}
