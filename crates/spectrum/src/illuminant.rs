//! [`CieIlluminant`]: the CIE standard and recommended illuminants by name.
//!
//! | name | definition | range |
//! |---|---|---|
//! | `A` | Planck's law at 2848 K with c2 = 1.435e7 nm K (the CIE's defining formula) | 300-830 nm |
//! | `D65` | the CIE table (CIE 15:2004 Table T.1, 5 nm, linear interpolation) | 300-780 nm |
//! | `D50`, `D55`, `D75` | the CIE daylight method from S0, S1, S2 (CIE 15:2004 Table T.2) at 5003 K, 5503 K, 7504 K | 300-830 nm |
//! | `E` | equal energy | 360-830 nm |
//! | `F1` ... `F12` | the CIE fluorescent tables (CIE 15:2004 Table T.6, 5 nm) | 380-780 nm |
//!
//! JSON: `{"type": "CieIlluminant", "name": "D65"}`. Each is normalised to integral 1 over its
//! range, like every SPD. Each is built once per process and shared by every light that names
//! it (a scene of 20,000 D65 lamps builds one table).

use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock, PoisonError};

use serde::{Deserialize, Serialize};

use crate::blackbody::Blackbody;
use crate::data::illuminants as tables;
use crate::error::SpectrumError;
use crate::spd::SpectralPowerDistribution;
use crate::{Tabulated, Uniform};

/// The illuminant names [`CieIlluminant::new`] accepts.
pub const KNOWN_ILLUMINANTS: &str =
    "A, D50, D55, D65, D75, E, F1, F2, F3, F4, F5, F6, F7, F8, F9, F10, F11, F12";

/// A CIE illuminant by name, normalised like every SPD.
#[derive(Debug, Deserialize)]
#[serde(try_from = "IlluminantRepr")]
pub struct CieIlluminant {
    name: String,
    spd: Arc<dyn SpectralPowerDistribution>,
}

/// Scene-file form of [`CieIlluminant`].
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct IlluminantRepr {
    name: String,
}

impl TryFrom<IlluminantRepr> for CieIlluminant {
    type Error = SpectrumError;
    fn try_from(r: IlluminantRepr) -> Result<Self, SpectrumError> {
        Self::new(&r.name)
    }
}

impl Serialize for CieIlluminant {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        IlluminantRepr { name: self.name.clone() }.serialize(serializer)
    }
}

impl CieIlluminant {
    /// The illuminant called `name` (see [`KNOWN_ILLUMINANTS`]; case-sensitive).
    ///
    /// # Errors
    /// [`SpectrumError::UnknownIlluminant`] listing the known names.
    pub fn new(name: &str) -> Result<Self, SpectrumError> {
        // At most one entry per known name: unknown names are refused before they are cached.
        static BUILT: OnceLock<Mutex<HashMap<String, Arc<dyn SpectralPowerDistribution>>>> =
            OnceLock::new();
        let built = BUILT.get_or_init(Default::default);
        if let Some(spd) = built.lock().unwrap_or_else(PoisonError::into_inner).get(name) {
            return Ok(Self { name: name.to_owned(), spd: spd.clone() });
        }
        let spd = Self::build(name)?;
        built.lock().unwrap_or_else(PoisonError::into_inner).insert(name.to_owned(), spd.clone());
        Ok(Self { name: name.to_owned(), spd })
    }

    /// Builds illuminant `name`'s spectrum.
    fn build(name: &str) -> Result<Arc<dyn SpectralPowerDistribution>, SpectrumError> {
        let spd: Arc<dyn SpectralPowerDistribution> = match name {
            "A" => Arc::new(Blackbody::with_c2(
                "CieIlluminant",
                tables::A_FORMULA_T_K,
                300.0,
                830.0,
                tables::A_FORMULA_C2_NM_K,
            )?),
            "D65" => Arc::new(Tabulated::regular(
                tables::D65_START_NM,
                tables::D65_STEP_NM,
                &tables::D65,
            )?),
            "D50" => Arc::new(daylight(5000.0)?),
            "D55" => Arc::new(daylight(5500.0)?),
            "D75" => Arc::new(daylight(7500.0)?),
            "E" => Arc::new(Uniform::equal_energy()),
            _ => match name.strip_prefix('F').and_then(|k| k.parse::<usize>().ok()) {
                Some(k @ 1..=12) if name == format!("F{k}") => Arc::new(Tabulated::regular(
                    tables::F_START_NM,
                    tables::F_STEP_NM,
                    &tables::F[k - 1],
                )?),
                _ => {
                    return Err(SpectrumError::UnknownIlluminant {
                        name: name.to_owned(),
                        known: KNOWN_ILLUMINANTS,
                    });
                }
            },
        };
        Ok(spd)
    }

    /// The illuminant's name.
    pub fn name(&self) -> &str {
        &self.name
    }
}

/// The relative SPD of CIE daylight at nominal temperature `nominal_k` (CIE 15:2004 section 3.1):
/// `S0 + M1 S1 + M2 S2`, with the temperature corrected for the 1968 change of c2 and `M1`, `M2`
/// rounded to three decimals as the CIE prescribes.
pub fn daylight(nominal_k: f64) -> Result<Tabulated, SpectrumError> {
    if !(4000.0..=25_000.0).contains(&nominal_k) {
        return Err(SpectrumError::parameter(
            "daylight",
            "kelvin",
            nominal_k,
            "must lie in [4000, 25000] K",
        ));
    }
    let t = nominal_k * 1.4388 / 1.4380;
    let xd = if t <= 7000.0 {
        -4.6070e9 / t.powi(3) + 2.9678e6 / t.powi(2) + 0.09911e3 / t + 0.244063
    } else {
        -2.0064e9 / t.powi(3) + 1.9018e6 / t.powi(2) + 0.24748e3 / t + 0.237040
    };
    let yd = -3.000 * xd * xd + 2.870 * xd - 0.275;
    let m = 0.0241 + 0.2562 * xd - 0.7341 * yd;
    let round3 = |v: f64| (v * 1000.0).round() / 1000.0;
    let m1 = round3((-1.3515 - 1.7703 * xd + 5.9114 * yd) / m);
    let m2 = round3((0.0300 - 31.4424 * xd + 30.0717 * yd) / m);
    let values: Vec<f64> = (0..tables::D_SERIES_LEN)
        .map(|i| tables::D_S0[i] + m1 * tables::D_S1[i] + m2 * tables::D_S2[i])
        .collect();
    Tabulated::regular(tables::D_SERIES_START_NM, tables::D_SERIES_STEP_NM, &values)
}

#[typetag::serde]
impl SpectralPowerDistribution for CieIlluminant {
    fn sample_lambda(&self, u: f64) -> f64 {
        self.spd.sample_lambda(u)
    }
    fn value(&self, lambda: f64) -> f64 {
        self.spd.value(lambda)
    }
    fn range(&self) -> (f64, f64) {
        self.spd.range()
    }
    fn integrate(&self, f: &dyn Fn(f64) -> f64) -> f64 {
        self.spd.integrate(f)
    }
    fn breakpoints(&self) -> Vec<f64> {
        self.spd.breakpoints()
    }
    fn piecewise_constant(&self) -> Option<Box<dyn SpectralPowerDistribution>> {
        // The D and F series are tables; A (a formula) and E (constant) have none.
        self.spd.piecewise_constant()
    }
}
