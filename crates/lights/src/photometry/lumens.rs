//! [`LuminaireLumens`]: a measured luminaire's luminous flux against its lamps' rated flux, the
//! light output ratio lighting designers read off a photometric file.

#[cfg(doc)]
use super::{EulumdatLight, IesLight};
#[cfg(doc)]
use crate::LightSource;

/// A measured luminaire's luminous flux against its lamps' ([`IesLight::lumens_summary`],
/// [`EulumdatLight::lumens_summary`], [`LightSource::photometric_summary`]). Its
/// [`Display`](std::fmt::Display) reads `table 2340.5 lm, lamps 2 x 1500 lm = 3000 lm, LOR 0.780`
/// (with a EULUMDAT file, ` (file states 0.780)` after it).
///
/// Definitions, with `flux(T)` the luminous flux of a candela table `T` (its integral over the
/// sphere, interpolated as the module documentation says):
/// - `table_lumens = flux(the light's table)`: what the light emits, every factor applied (an
///   IES file's candela multiplier and ballast factor, EULUMDAT's set flux / 1000, the scene's
///   `multiplier`, or the scene's `lumens` itself): [`IesLight::lumens`].
/// - `file_lumens = flux(the file's table at its own scale)`: IES candela values times the
///   file's candela multiplier (not its ballast factor, nor the scene's factors); EULUMDAT
///   cd/klm times the fitted lamp set's flux / 1000.
/// - `lamp_lumens`: the rated flux of the lamps the table is relative to, IES `lamps x
///   lumens per lamp`, EULUMDAT the fitted set's total flux; `None` for absolute photometry
///   (IES lumens per lamp `-1`, EULUMDAT negative lamp counts), where the table is the
///   luminaire's own measurement and no lamp is rated.
/// - `light_output_ratio = file_lumens / lamp_lumens` (a fraction, the luminaire's LOR: the
///   share of its lamps' flux that leaves it). The ballast factor scales the lamps and the
///   luminaire alike, so it is left out of both; so are the scene's factors.
/// - `stated_light_output_ratio`: EULUMDAT only, the file's own LORL (line 23) / 100, to compare
///   with the computed one (a file whose two disagree was written with another table or lamp
///   flux); `None` for IES files, which state none.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LuminaireLumens {
    /// Flux (lm) the light emits: its candela table with every factor applied.
    pub table_lumens: f64,
    /// Flux (lm) of the file's table at its own scale (see the type's documentation).
    pub file_lumens: f64,
    /// Number of lamps: the IES file's count, or the fitted EULUMDAT set's (its magnitude).
    pub lamp_count: u32,
    /// Rated flux (lm) of all the lamps together; `None` for absolute photometry.
    pub lamp_lumens: Option<f64>,
    /// `file_lumens / lamp_lumens` (fraction); `None` for absolute photometry.
    pub light_output_ratio: Option<f64>,
    /// The light output ratio a EULUMDAT file states (LORL / 100, fraction); `None` for IES.
    pub stated_light_output_ratio: Option<f64>,
}

impl std::fmt::Display for LuminaireLumens {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        /// Lumens to 0.1 lm, without a trailing `.0`.
        fn lm(x: f64) -> f64 {
            (x * 10.0).round() / 10.0
        }
        write!(f, "table {} lm", lm(self.table_lumens))?;
        match (self.lamp_lumens, self.light_output_ratio) {
            (Some(lamps), Some(lor)) => {
                let each = lamps / f64::from(self.lamp_count.max(1));
                write!(
                    f,
                    ", lamps {} x {} lm = {} lm, LOR {lor:.3}",
                    self.lamp_count,
                    lm(each),
                    lm(lamps)
                )?;
            }
            _ => write!(f, ", absolute photometry (no rated lamp flux)")?,
        }
        if let Some(stated) = self.stated_light_output_ratio {
            write!(f, " (file states {stated:.3})")?;
        }
        Ok(())
    }
}
