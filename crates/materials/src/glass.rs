//! [`Glass`]: the catalog of named optical glasses behind `{"glass": "BK7"}`.
//!
//! Every entry is a three-term Sellmeier law, `n^2 = 1 + sum B_i l^2 / (l^2 - C_i)` with the
//! wavelength `l` in micrometres and `C_i` in square micrometres, with the published coefficients
//! and the published `n_d` (at the helium d line, 587.56 nm) and Abbe number `V_d` that the tests
//! check the coefficients against.
//!
//! | name | aliases | n_d | V_d | source |
//! |---|---|---|---|---|
//! | `N-BK7` | `BK7` | 1.5168 | 64.17 | SCHOTT optical glass data sheet |
//! | `F2` | | 1.6200 | 36.37 | SCHOTT optical glass data sheet |
//! | `SF11` | `N-SF11` | 1.7847 | 25.68 | SCHOTT optical glass data sheet (N-SF11 coefficients) |
//! | `FusedSilica` | `fused silica`, `SiO2`, `fused_silica` | 1.4585 | 67.82 | Malitson, JOSA 55, 1205 (1965) |
//! | `CaF2` | `calcium fluoride`, `fluorite` | 1.4338 | 94.99 | Malitson, Appl. Opt. 2, 1103 (1963) |

/// A named glass: Sellmeier coefficients and its published reference values.
#[derive(Debug, Clone, PartialEq)]
pub struct Glass {
    /// Catalog name, e.g. `"N-BK7"`.
    pub name: &'static str,
    /// Other names accepted for it (matched case-insensitively, like `name`).
    pub aliases: &'static [&'static str],
    /// Sellmeier `B_i` (dimensionless).
    pub b: [f64; 3],
    /// Sellmeier `C_i` (µm²).
    pub c: [f64; 3],
    /// Published index at the d line, 587.5618 nm.
    pub n_d: f64,
    /// Published Abbe number `V_d = (n_d - 1) / (n_F - n_C)`.
    pub abbe_d: f64,
    /// Where the coefficients come from.
    pub source: &'static str,
}

/// The glass catalog.
pub static GLASSES: &[Glass] = &[
    Glass {
        name: "N-BK7",
        aliases: &["BK7"],
        b: [1.039_612_12, 0.231_792_344, 1.010_469_45],
        c: [0.006_000_698_67, 0.020_017_914_4, 103.560_653],
        n_d: 1.5168,
        abbe_d: 64.17,
        source: "SCHOTT optical glass data sheet, N-BK7",
    },
    Glass {
        name: "F2",
        aliases: &[],
        b: [1.345_333_59, 0.209_073_176, 0.937_357_162],
        c: [0.009_977_438_71, 0.047_045_076_7, 111.886_764],
        n_d: 1.6200,
        abbe_d: 36.37,
        source: "SCHOTT optical glass data sheet, F2",
    },
    Glass {
        name: "SF11",
        aliases: &["N-SF11"],
        b: [1.737_596_95, 0.313_747_346, 1.898_781_01],
        c: [0.013_188_707, 0.062_306_814_2, 155.236_29],
        n_d: 1.7847,
        abbe_d: 25.68,
        source: "SCHOTT optical glass data sheet, N-SF11",
    },
    Glass {
        name: "FusedSilica",
        aliases: &["fused silica", "fused_silica", "SiO2"],
        b: [0.696_166_3, 0.407_942_6, 0.897_479_4],
        c: [0.068_404_3 * 0.068_404_3, 0.116_241_4 * 0.116_241_4, 9.896_161 * 9.896_161],
        n_d: 1.4585,
        abbe_d: 67.82,
        source: "I. H. Malitson, J. Opt. Soc. Am. 55, 1205 (1965)",
    },
    Glass {
        name: "CaF2",
        aliases: &["calcium fluoride", "fluorite"],
        b: [0.567_588_8, 0.471_091_4, 3.848_472_3],
        c: [0.050_263_605 * 0.050_263_605, 0.100_390_9 * 0.100_390_9, 34.649_040 * 34.649_040],
        n_d: 1.4338,
        abbe_d: 94.99,
        source: "I. H. Malitson, Appl. Opt. 2, 1103 (1963)",
    },
];

/// The glass called `name` (its catalog name or an alias, case-insensitively).
pub fn find_glass(name: &str) -> Option<&'static Glass> {
    GLASSES.iter().find(|g| {
        g.name.eq_ignore_ascii_case(name) || g.aliases.iter().any(|a| a.eq_ignore_ascii_case(name))
    })
}

/// Every accepted glass name, comma-separated, for error messages.
pub fn known_glasses() -> String {
    GLASSES
        .iter()
        .flat_map(|g| std::iter::once(g.name).chain(g.aliases.iter().copied()))
        .collect::<Vec<_>>()
        .join(", ")
}
