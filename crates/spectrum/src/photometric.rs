//! Photometry: turning radiant quantities (watts) into luminous ones (lumens, lux, candela)
//! through the CIE photopic luminous efficiency `V(lambda)`, which is the 1931 observer's `ybar`.
//!
//! A watt of radiant power at wavelength `lambda` is `683 ybar(lambda)` lumens (683 lm/W at 555 nm,
//! where `ybar` is 1, by the definition of the candela). For a light whose normalised SPD is
//! `s(lambda)`, one watt is `K = 683 * integral of s(lambda) ybar(lambda) d lambda` lumens:
//! [`luminous_efficacy`]. Irradiance (W/m^2) becomes illuminance (lux) and radiant intensity
//! (W/sr) becomes luminous intensity (candela) by the same factor.

use crate::{SpectralPowerDistribution, cmf};

/// Lumens per watt of monochromatic light at 555 nm, where the photopic curve peaks (the SI
/// definition of the candela fixes 683 lm/W at 540 THz).
pub const PEAK_LUMINOUS_EFFICACY: f64 = 683.0;

/// Lumens per watt of radiant power at `lambda` (nm): `683 ybar(lambda)`; 0 outside 360-830 nm.
#[inline]
pub fn lumens_per_watt(lambda: f64) -> f64 {
    PEAK_LUMINOUS_EFFICACY * cmf(lambda).y
}

/// Lumens per watt of a light with the normalised spectrum `spd`:
/// `683 * integral of spd(lambda) ybar(lambda) d lambda` (delta lines included). 0 for a spectrum
/// the eye does not see (all of it below 360 nm or above 830 nm).
pub fn luminous_efficacy(spd: &dyn SpectralPowerDistribution) -> f64 {
    PEAK_LUMINOUS_EFFICACY * spd.integrate(&|l| cmf(l).y)
}

/// The radiant power (W) that carries `lumens` with the spectrum `spd`, or `None` when that
/// spectrum has no visible light (its efficacy is 0, so no power makes any lumens) or the result
/// is not finite.
pub fn watts_from_lumens(lumens: f64, spd: &dyn SpectralPowerDistribution) -> Option<f64> {
    let k = luminous_efficacy(spd);
    let watts = lumens / k;
    (k > 0.0 && watts.is_finite()).then_some(watts)
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::{Blackbody, Monochromatic, Uniform};

    #[test]
    fn a_watt_at_555_nm_is_683_lumens() {
        let line = Monochromatic::new(555.0).unwrap();
        assert!((luminous_efficacy(&line) - 683.0).abs() < 1e-9);
        assert!((lumens_per_watt(555.0) - 683.0).abs() < 1e-9);
        assert_eq!(lumens_per_watt(300.0), 0.0);
    }

    #[test]
    fn equal_energy_light_has_the_efficacy_of_the_mean_of_ybar() {
        // Uniform over 360-830 nm: 683 * (integral of ybar) / 470.
        let flat = Uniform::new(360.0, 830.0).unwrap();
        let expected = 683.0 * *crate::CIE_Y_INTEGRAL / 470.0;
        assert!((luminous_efficacy(&flat) - expected).abs() < 1e-6 * expected);
        // About 155 lm/W (106.857 * 683 / 470).
        assert!((luminous_efficacy(&flat) - 155.3).abs() < 0.1);
    }

    #[test]
    fn a_2856_k_blackbody_gives_the_textbook_efficacy() {
        // A 2856 K Planckian radiator (illuminant A), all of its power counted: about 15 lm/W.
        // Our blackbody SPD is normalised over its own range, so check against quadrature of
        // Planck's law over the same range instead of a published figure.
        let bb = Blackbody::new(2856.0).unwrap();
        let (lo, hi) = bb.range();
        let planck = |l: f64| {
            let x = l * 1e-9;
            1.0 / (x.powi(5) * ((crate::PLANCK_C2_NM_K / (l * 2856.0)).exp() - 1.0))
        };
        let total = crate::integrate_panels(&planck, lo, hi, &[]);
        let visible = crate::integrate_panels(&|l| planck(l) * cmf(l).y, lo, hi, &[]);
        let expected = 683.0 * visible / total;
        let k = luminous_efficacy(&bb);
        assert!((k - expected).abs() < 1e-6 * expected, "{k} vs {expected}");
        assert!((watts_from_lumens(1000.0, &bb).unwrap() * k - 1000.0).abs() < 1e-9);
    }

    #[test]
    fn invisible_light_has_no_power_for_any_lumens() {
        let uv = Monochromatic::new(300.0).unwrap();
        assert_eq!(luminous_efficacy(&uv), 0.0);
        assert_eq!(watts_from_lumens(100.0, &uv), None);
    }
}
