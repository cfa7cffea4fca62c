//! Reference colorimetric values for tests, all for the CIE 1931 2° standard
//! observer ([`super::cie1931::CIE_1931_2DEG`], 1 nm, 360..830 nm).
//!
//! Sources:
//! - Computed values: computed by `extract_cie.py` in this directory with
//!   colour-science 0.4.7 (numpy 2.4.6) from the tables of colour-science's bundled copy
//!   of the CIE data (the same numbers as in [`super::cie1931`] and
//!   [`super::illuminants`]). How each was computed is stated on each constant.
//! - Published chromaticities: colour-science 0.4.7's
//!   `colour.CCS_ILLUMINANTS["CIE 1931 2 Degree Standard Observer"]`, which
//!   colour-science cites to CIE 15:2004 / CIE 015:2018 and Wikipedia's "Standard
//!   illuminant" table; D50 and D65 are deliberately rounded there to 4 decimals
//!   (see [`ILLUMINANT_XY_PUBLISHED`]).
//!
//! x and y are independent of the normalisation constant k, so none is applied
//! (the ratios are taken of the unnormalised sums).

/// ∫ȳ(λ)dλ over 360..=830 nm by the trapezoid rule on the 1 nm table (nm units).
///
/// Plain 1 nm sum (Σȳ·1 nm, colour-science's "Integration" normalisation) is
/// 106.856917101172; the trapezoid rule subtracts half the two end values.
pub const YBAR_INTEGRAL_TRAPEZOID: f64 = 106.856914916767;

/// Plain 1 nm sum Σȳ(λ)·1 nm over 360..=830 nm (rectangle rule, no end halving).
pub const YBAR_SUM_1NM: f64 = 106.856917101172;

/// Chromaticities (name, x, y) computed with colour-science from the 5 nm CIE tables.
///
/// Method: each illuminant table ([`super::illuminants::D65`], `A`, `F2`, `F11`
/// and colour-science's own CIE 15:2004 5 nm tables for D50, D55 and D75, which
/// are *not* in [`super::illuminants`]) is linearly interpolated to 1 nm over
/// 360..=830 nm (`sd.align(SpectralShape(360, 830, 1), interpolator=LinearInterpolator)`),
/// using colour-science's default *constant* extrapolation outside the table
/// (D65/A/D50/D55/D75 hold their 780 nm value up to 830 nm; F2/F11 hold their
/// 380 nm value below 380 nm and their 780 nm value above 780 nm), then
/// `colour.sd_to_XYZ(sd, cmfs, method="Integration")`, i.e. the plain 1 nm sum
/// Σ S(λ)·x̄(λ) etc. over 360..=830 nm, and x = X/(X+Y+Z), y = Y/(X+Y+Z).
///
/// For comparison, colour-science's *default* `colour.sd_to_XYZ(sd, cmfs)` (ASTM
/// E308 method: a 5 nm table is summed at 5 nm over the 360..780 nm "practice
/// range" with the CMFs sampled at 5 nm, no interpolation; F2/F11 hold their
/// 380 nm value at 360..375 nm) gives:
/// - D65: (0.31271107, 0.32900848)
/// - A: (0.44757143, 0.40744043)
/// - F2: (0.37206556, 0.37511770)
/// - F11: (0.38053539, 0.37691153)
/// - D50: (0.34566804, 0.35849684)
/// - D55: (0.33242410, 0.34742804)
/// - D75: (0.29902230, 0.31485274)
pub const ILLUMINANT_XY_1NM: [(&str, f64, f64); 7] = [
    ("D65", 0.3127269499795597, 0.32902321829706677),
    ("A", 0.4475607217685672, 0.4074312565119517),
    ("F2", 0.372081545137761, 0.37528329080736955),
    ("F11", 0.38051524925104846, 0.37712096250192373),
    ("D50", 0.34568422281358774, 0.35850409475144085),
    ("D55", 0.33244050020834076, 0.34743847510470194),
    ("D75", 0.29903752861940774, 0.31487041680810435),
];

/// Same as [`ILLUMINANT_XY_1NM`] but with the illuminant taken as zero outside its table.
///
/// Linear interpolation to 1 nm inside the tabulated range (300..780 nm for D65,
/// A, D50, D55, D75; 380..780 nm for F2, F11), zero outside, plain 1 nm sum over
/// 360..=830 nm (`numpy.interp(..., left=0, right=0)` then a dot product with
/// the CMF table). Differs from [`ILLUMINANT_XY_1NM`] by at most
/// 6.3e-06.
pub const ILLUMINANT_XY_1NM_ZERO_OUTSIDE: [(&str, f64, f64); 7] = [
    ("D65", 0.3127263193728546, 0.3290233135138928),
    ("A", 0.4475587375242862, 0.4074322386594068),
    ("F2", 0.3720848890953865, 0.3752895997732256),
    ("F11", 0.3805179603421151, 0.37712587316352164),
    ("D50", 0.345683435841975, 0.35850428328619033),
    ("D55", 0.33243977703264593, 0.3474386227576305),
    ("D75", 0.2990369595718056, 0.3148704815437319),
];

/// Chromaticities (name, x, y) of D50, D55, D65, D75 computed from [`super::illuminants::D_S0`]..`D_S2`.
///
/// `colour.sd_CIE_illuminant_D_series(CCT_to_xy_CIE_D(T · 1.4388/1.4380))`
/// (M1, M2 rounded to 3 decimals; 300..830 nm at 5 nm), linearly interpolated to
/// 1 nm, plain 1 nm sum over 360..=830 nm (no extrapolation needed), for T =
/// 5000, 5500, 6500, 7500 K.
pub const D_SERIES_XY_FROM_BASIS: [(&str, f64, f64); 4] = [
    ("D50", 0.345684223692743, 0.3585040310469979),
    ("D55", 0.33244047895673373, 0.3474383394345967),
    ("D65", 0.31272687508438235, 0.3290234507499356),
    ("D75", 0.2990374796457199, 0.3148705219185706),
];

/// Published chromaticities (name, x, y) as listed in colour-science 0.4.7's `CCS_ILLUMINANTS`.
///
/// Taken verbatim from `colour.CCS_ILLUMINANTS["CIE 1931 2 Degree Standard
/// Observer"]` (keys `D65`, `A`, `FL2`, `FL11`, `D50`, `D55`, `D75`).
/// Caveats, per colour-science's own notes: D65 (0.3127, 0.3290) and D50 (0.3457,
/// 0.3585) are rounded to 4 decimals "as specified in typical RGB colourspaces
/// literature"; the 5-decimal CIE values are [`D65_XY_CIE`] and [`D50_XY_CIE`].
/// A is listed as (0.44758, 0.40745) by colour-science, whereas the value usually
/// quoted from CIE 15:2004 is (0.44757, 0.40745). F2 and F11 are the 4-decimal
/// values of CIE 15:2004's colorimetric data for the F illuminants.
pub const ILLUMINANT_XY_PUBLISHED: [(&str, f64, f64); 7] = [
    ("D65", 0.3127, 0.329),
    ("A", 0.44758, 0.40745),
    ("F2", 0.3721, 0.3751),
    ("F11", 0.3805, 0.3769),
    ("D50", 0.3457, 0.3585),
    ("D55", 0.33243, 0.34744),
    ("D75", 0.29903, 0.31488),
];

/// CIE chromaticity of D65, (0.31272, 0.32903), as quoted in colour-science 0.4.7's `CCS_ILLUMINANTS` notes.
///
/// colour-science attributes it to CIE 015:2004 (`CIETC1-482004h`); CIE 15:2004's
/// own 5 nm computation is usually quoted as (0.31271, 0.32902).
pub const D65_XY_CIE: (f64, f64) = (0.31272, 0.32903);

/// CIE chromaticity of D50, (0.34567, 0.35851), as quoted in colour-science 0.4.7's `CCS_ILLUMINANTS` notes.
pub const D50_XY_CIE: (f64, f64) = (0.34567, 0.35851);

/// Second radiation constant c2 = 1.4388e-2 m·K used by colour-science 0.4.7 (`CONSTANT_C2`, ITS-90 value).
pub const PLANCK_C2_M_K: f64 = 0.014388;

/// First radiation constant c1 = 3.741771e-16 W·m² used by colour-science 0.4.7 (`CONSTANT_C1`; irrelevant to x, y).
pub const PLANCK_C1_W_M2: f64 = 3.741771e-16;

/// Planckian (blackbody) chromaticities (kelvin, x, y): 1 nm trapezoid rule over 360..=830 nm.
///
/// Spectrum: `colour.sd_blackbody(T, SpectralShape(360, 830, 1))`, i.e. Planck's
/// law `B(λ,T) = c1 / (π·λ^5·(exp(c2/(λ·T)) − 1))` with c1 = 3.741771e-16 W·m²,
/// c2 = 0.014388 m·K ([`PLANCK_C2_M_K`]), n = 1, sampled at integer nm.
/// `X = Σ w_i·B(λ_i)·x̄(λ_i)` over `λ_i` = 360..=830 nm with trapezoid weights `w_i` = 1
/// except 1/2 at 360 and 830 nm (likewise Y, Z, all with the same normalisation),
/// x = X/(X+Y+Z), y = Y/(X+Y+Z).
///
/// Comparison (all with the same CMF table; "sum" = plain 1 nm rectangle sum over
/// 360..=830 nm = `colour.sd_to_XYZ(sd, cmfs, method="Integration")`; "default" =
/// colour-science's default `colour.sd_to_XYZ(sd, cmfs)`, the ASTM E308 method,
/// which for 1 nm data trims the CMFs to the 360..780 nm practice range):
///
/// |     T | x trapezoid | y trapezoid | x sum | y sum | x default | y default |
/// |------:|------:|------:|------:|------:|------:|------:|
/// |  1000 | 0.65275291 | 0.34445970 | 0.65275297 | 0.34445964 | 0.65272523 | 0.34448643 |
/// |  1500 | 0.58572098 | 0.39311970 | 0.58572099 | 0.39311969 | 0.58571265 | 0.39312684 |
/// |  2000 | 0.52668099 | 0.41329647 | 0.52668099 | 0.41329646 | 0.52667680 | 0.41329944 |
/// |  2856 | 0.44753866 | 0.40742934 | 0.44753864 | 0.40742930 | 0.44753661 | 0.40743031 |
/// |  3000 | 0.43693450 | 0.40407519 | 0.43693448 | 0.40407515 | 0.43693262 | 0.40407601 |
/// |  4000 | 0.38044243 | 0.37674871 | 0.38044236 | 0.37674859 | 0.38044124 | 0.37674894 |
/// |  5000 | 0.34510354 | 0.35161007 | 0.34510343 | 0.35160985 | 0.34510263 | 0.35161003 |
/// |  6500 | 0.31352766 | 0.32363025 | 0.31352751 | 0.32362989 | 0.31352694 | 0.32362997 |
/// | 10000 | 0.28063467 | 0.28828946 | 0.28063446 | 0.28828889 | 0.28063408 | 0.28828891 |
/// | 20000 | 0.25645784 | 0.25763214 | 0.25645758 | 0.25763132 | 0.25645731 | 0.25763132 |
///
/// Max |trapezoid − sum| = 8.1e-07; max |trapezoid − default| =
/// 2.8e-05 (the 780..830 nm tail matters most at low T).
pub const PLANCKIAN_XY: [(f64, f64, f64); 10] = [
    (1000.0, 0.6527529131955004, 0.34445969513646363),
    (1500.0, 0.5857209799735594, 0.3931196980367234),
    (2000.0, 0.5266809914843354, 0.4132964666815286),
    (2856.0, 0.4475386612203518, 0.4074293364931873),
    (3000.0, 0.43693450239949333, 0.4040751907336769),
    (4000.0, 0.3804424323779021, 0.3767487141526064),
    (5000.0, 0.34510353941914773, 0.3516100735751924),
    (6500.0, 0.3135276640831466, 0.32363024903753246),
    (10000.0, 0.280634672850747, 0.2882894629309421),
    (20000.0, 0.2564578358980917, 0.2576321353333847),
];

#[cfg(test)]
mod tests {
    use super::super::cie1931::{CIE_1931_2DEG, CMF_START_NM, CMF_STEP_NM};
    use super::super::illuminants::{
        A, D_S0, D_S1, D_S2, D_SERIES_START_NM, D_SERIES_STEP_NM, D65, D65_START_NM, D65_STEP_NM,
        F, F_START_NM, F_STEP_NM,
    };
    use super::*;

    /// Linear interpolation of a uniformly sampled table, zero outside it.
    fn lerp_table(table: &[f64], start: f64, step: f64, nm: f64) -> f64 {
        let t = (nm - start) / step;
        if t < 0.0 || t > (table.len() - 1) as f64 {
            return 0.0;
        }
        let i = (t.floor() as usize).min(table.len() - 2);
        let f = t - i as f64;
        table[i] * (1.0 - f) + table[i + 1] * f
    }

    fn xy(spd: impl Fn(f64) -> f64, trapezoid: bool) -> (f64, f64) {
        let n = CIE_1931_2DEG.len();
        let mut xyz = [0.0_f64; 3];
        for (i, row) in CIE_1931_2DEG.iter().enumerate() {
            let nm = CMF_START_NM + i as f64 * CMF_STEP_NM;
            let w = if trapezoid && (i == 0 || i == n - 1) { 0.5 } else { 1.0 };
            let s = spd(nm) * w;
            for (acc, v) in xyz.iter_mut().zip(row) {
                *acc += s * v;
            }
        }
        let sum = xyz[0] + xyz[1] + xyz[2];
        (xyz[0] / sum, xyz[1] / sum)
    }

    fn find(table: &[(&str, f64, f64)], name: &str) -> (f64, f64) {
        let r = table.iter().find(|r| r.0 == name).map(|r| (r.1, r.2));
        r.unwrap_or((f64::NAN, f64::NAN))
    }

    #[test]
    fn ybar_integral_matches_table() {
        let n = CIE_1931_2DEG.len();
        let sum: f64 = CIE_1931_2DEG.iter().map(|r| r[1]).sum();
        let trap = sum - 0.5 * (CIE_1931_2DEG[0][1] + CIE_1931_2DEG[n - 1][1]);
        assert!((trap - YBAR_INTEGRAL_TRAPEZOID).abs() < 1e-10);
        assert!((sum - YBAR_SUM_1NM).abs() < 1e-10);
    }

    #[test]
    fn planckian_matches_trapezoid_in_rust() {
        for &(t, x, y) in PLANCKIAN_XY.iter() {
            let c2_nm_k = PLANCK_C2_M_K * 1e9;
            let got = xy(|nm| 1.0 / (nm.powi(5) * ((c2_nm_k / (nm * t)).exp() - 1.0)), true);
            assert!((got.0 - x).abs() < 1e-12 && (got.1 - y).abs() < 1e-12, "{t} K: {got:?}");
        }
    }

    #[test]
    fn illuminants_zero_outside_match() {
        let cases: [(&str, &[f64], f64, f64); 4] = [
            ("D65", &D65, D65_START_NM, D65_STEP_NM),
            ("A", &A, D65_START_NM, D65_STEP_NM),
            ("F2", &F[1], F_START_NM, F_STEP_NM),
            ("F11", &F[10], F_START_NM, F_STEP_NM),
        ];
        for (name, table, start, step) in cases {
            let got = xy(|nm| lerp_table(table, start, step, nm), false);
            let want = find(&ILLUMINANT_XY_1NM_ZERO_OUTSIDE, name);
            assert!((got.0 - want.0).abs() < 1e-12 && (got.1 - want.1).abs() < 1e-12, "{name}");
        }
    }

    #[test]
    fn d_series_from_basis_matches() {
        for (name, t) in [("D50", 5000.0), ("D55", 5500.0), ("D65", 6500.0), ("D75", 7500.0)] {
            let tc: f64 = t * 1.4388 / 1.4380;
            let xd = if tc <= 7000.0 {
                -4.6070e9 / tc.powi(3) + 2.9678e6 / tc.powi(2) + 0.09911e3 / tc + 0.244063
            } else {
                -2.0064e9 / tc.powi(3) + 1.9018e6 / tc.powi(2) + 0.24748e3 / tc + 0.237040
            };
            let yd = -3.0 * xd * xd + 2.870 * xd - 0.275;
            let m = 0.0241 + 0.2562 * xd - 0.7341 * yd;
            let m1 = ((-1.3515 - 1.7703 * xd + 5.9114 * yd) / m * 1000.0).round() / 1000.0;
            let m2 = ((0.0300 - 31.4424 * xd + 30.0717 * yd) / m * 1000.0).round() / 1000.0;
            let spd: Vec<f64> =
                (0..D_S0.len()).map(|i| D_S0[i] + m1 * D_S1[i] + m2 * D_S2[i]).collect();
            let got = xy(|nm| lerp_table(&spd, D_SERIES_START_NM, D_SERIES_STEP_NM, nm), false);
            let want = find(&D_SERIES_XY_FROM_BASIS, name);
            assert!(
                (got.0 - want.0).abs() < 1e-9 && (got.1 - want.1).abs() < 1e-9,
                "{name}: {got:?}"
            );
        }
    }

    #[test]
    fn computed_close_to_published() {
        for (name, x, y) in ILLUMINANT_XY_1NM {
            let p = find(&ILLUMINANT_XY_PUBLISHED, name);
            // Published values are rounded to 4-5 decimals and computed at 5 nm.
            assert!((x - p.0).abs() < 3e-4 && (y - p.1).abs() < 3e-4, "{name}");
        }
    }
}
