//! The measured metal tables in `data/metals/` (groundwork for a metal catalog): every file
//! parses, names its source, ascends, is physical (n > 0, k > 0), covers 360-830 nm, and its
//! normal-incidence reflectance at 550 nm agrees with other, independent measurements; gold and
//! copper look warm and silver neutral.

/// The tables: chemical symbol and file contents.
const METALS: [(&str, &str); 9] = [
    ("Ag", include_str!("../../data/metals/Ag.csv")),
    ("Al", include_str!("../../data/metals/Al.csv")),
    ("Au", include_str!("../../data/metals/Au.csv")),
    ("Cr", include_str!("../../data/metals/Cr.csv")),
    ("Cu", include_str!("../../data/metals/Cu.csv")),
    ("Ni", include_str!("../../data/metals/Ni.csv")),
    ("Pt", include_str!("../../data/metals/Pt.csv")),
    ("Ti", include_str!("../../data/metals/Ti.csv")),
    ("W", include_str!("../../data/metals/W.csv")),
];

/// One row of a table: wavelength in nm, n, k.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Row {
    nm: f64,
    n: f64,
    k: f64,
}

/// Header keys every table must carry, in `# key: value` comment lines.
const REQUIRED_KEYS: [&str; 3] = ["source", "via", "units"];

/// Parses and checks one table: `#` comment lines (which must include `source:`, `via:` and
/// `units:`), then the column line `nm,n,k`, then rows of three finite numbers with the
/// wavelength strictly ascending and n, k positive. Errors name the file and line.
fn parse(name: &str, text: &str) -> Result<Vec<Row>, String> {
    let mut keys = Vec::new();
    let mut columns_seen = false;
    let mut rows: Vec<Row> = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let at = format!("{name}.csv line {}", i + 1);
        let line = line.trim();
        if let Some(comment) = line.strip_prefix('#') {
            if columns_seen {
                return Err(format!("{at}: comment after the column line"));
            }
            if let Some((key, value)) = comment.split_once(':')
                && !value.trim().is_empty()
            {
                keys.push(key.trim().to_owned());
            }
            continue;
        }
        if !columns_seen {
            if line != "nm,n,k" {
                return Err(format!("{at}: expected the column line `nm,n,k`, found `{line}`"));
            }
            columns_seen = true;
            continue;
        }
        let fields: Vec<&str> = line.split(',').collect();
        let [nm, n, k] = fields.as_slice() else {
            return Err(format!("{at}: expected 3 fields, found {}", fields.len()));
        };
        let number = |field: &str, what: &str| -> Result<f64, String> {
            match field.trim().parse::<f64>() {
                Ok(v) if v.is_finite() => Ok(v),
                _ => Err(format!("{at}: {what} `{field}` is not a finite number")),
            }
        };
        let row = Row { nm: number(nm, "nm")?, n: number(n, "n")?, k: number(k, "k")? };
        if !(row.n > 0.0) || !(row.k > 0.0) {
            return Err(format!("{at}: n = {} and k = {} must both be > 0", row.n, row.k));
        }
        if let Some(last) = rows.last()
            && !(row.nm > last.nm)
        {
            return Err(format!(
                "{at}: wavelength {} nm does not ascend (previous {})",
                row.nm, last.nm
            ));
        }
        rows.push(row);
    }
    for key in REQUIRED_KEYS {
        if !keys.iter().any(|k| k == key) {
            return Err(format!("{name}.csv: no `# {key}: ...` header line"));
        }
    }
    if rows.len() < 2 {
        return Err(format!("{name}.csv: {} data rows, need at least 2", rows.len()));
    }
    Ok(rows)
}

/// The table of the metal with this symbol, parsed.
fn table(symbol: &str) -> Vec<Row> {
    let (_, text) = METALS.iter().find(|(s, _)| *s == symbol).unwrap();
    parse(symbol, text).unwrap()
}

/// n and k at `nm` by linear interpolation between the bracketing rows; `None` outside.
fn nk_at(rows: &[Row], nm: f64) -> Option<(f64, f64)> {
    let pair = rows.windows(2).find(|w| w[0].nm <= nm && nm <= w[1].nm)?;
    let t = (nm - pair[0].nm) / (pair[1].nm - pair[0].nm);
    Some((pair[0].n + t * (pair[1].n - pair[0].n), pair[0].k + t * (pair[1].k - pair[0].k)))
}

/// Normal-incidence reflectance from air, `((n-1)^2 + k^2) / ((n+1)^2 + k^2)`.
fn reflectance(n: f64, k: f64) -> f64 {
    ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k)
}

/// Normal-incidence reflectance of the tabulated metal at `nm`.
fn reflectance_at(rows: &[Row], nm: f64) -> f64 {
    let (n, k) = nk_at(rows, nm).unwrap();
    reflectance(n, k)
}

#[test]
fn every_metal_table_parses_names_its_source_and_is_ascending_and_physical() {
    let mut report = String::new();
    for (symbol, text) in METALS {
        let rows = parse(symbol, text).unwrap_or_else(|e| panic!("{e}"));
        let (first, last) = (rows[0].nm, rows[rows.len() - 1].nm);
        report += &format!("{symbol:2}: {} rows, {first}-{last} nm\n", rows.len());
    }
    print!("\n{report}");
}

#[test]
fn every_metal_table_covers_360_to_830_nm() {
    for (symbol, _) in METALS {
        let rows = table(symbol);
        let (first, last) = (rows[0].nm, rows[rows.len() - 1].nm);
        assert!(first <= 360.0 && last >= 830.0, "{symbol}: {first}-{last} nm");
        // No gap wider than 120 nm inside the visible range (Palik's Cr has 611 -> 700 -> 816).
        for w in rows.windows(2) {
            assert!(w[1].nm - w[0].nm <= 120.0, "{symbol}: gap {} -> {} nm", w[0].nm, w[1].nm);
        }
    }
}

#[test]
fn the_table_checks_reject_broken_tables() {
    let head = "# source: s\n# via: v\n# units: nm, n, k\nnm,n,k\n";
    let good = format!("{head}400,1,2\n500,1,2\n");
    assert!(parse("good", &good).is_ok());
    let cases = [
        (format!("{head}500,1,2\n400,1,2\n"), "does not ascend"),
        (format!("{head}400,1,2\n400,1,2\n"), "does not ascend"),
        (format!("{head}400,1,2\n500,1,0\n"), "must both be > 0"),
        (format!("{head}400,-1,2\n500,1,2\n"), "must both be > 0"),
        (format!("{head}400,1,2\n500,1\n"), "expected 3 fields"),
        (format!("{head}400,1,2\n500,x,2\n"), "n `x` is not a finite number"),
        (format!("{head}400,1,2\n500,1,NaN\n"), "k `NaN` is not a finite number"),
        ("# source: s\n# via: v\n# units: u\n400,1,2\n".to_owned(), "column line"),
        ("# source: s\n# units: u\nnm,n,k\n400,1,2\n500,1,2\n".to_owned(), "# via:"),
        (format!("{head}400,1,2\n"), "need at least 2"),
    ];
    for (text, expected) in cases {
        let err = parse("bad", &text).unwrap_err();
        assert!(err.contains(expected), "`{err}` should mention `{expected}`");
        assert!(err.starts_with("bad.csv"), "`{err}` should name the file");
    }
}

/// Plausible normal-incidence reflectance at 550 nm, `(symbol, low, high)`. Each band holds
/// the reflectance computed the same way (linear interpolation of n, k at 550 nm) from other,
/// independent measurements than the one in our file, read from the refractiveindex.info
/// database and Mitsuba's Palik tables (see data/metals/README.md):
/// - Ag 0.95-0.995: Johnson & Christy 1972 0.983, Babar & Weaver 2015 0.985, Palik 0.960.
/// - Al 0.90-0.935: Rakic 1995 0.915, Cheng et al. 2016 0.922, Palik 0.921.
/// - Au 0.76-0.88: Johnson & Christy 0.792, Olmon et al. 2012 0.822-0.838, Babar & Weaver
///   0.842, Palik 0.847.
/// - Cu 0.58-0.70: Querry 1985 0.606, Johnson & Christy 0.624, Palik 0.641, Babar & Weaver 0.656.
/// - Cr 0.54-0.72: Johnson & Christy 1974 0.555, Rakic et al. 1998 0.650, Sytchkova et al.
///   2021 (12 nm film) 0.681.
/// - Ni 0.58-0.68: Rakic et al. 0.609, Palik 0.612.
/// - Pt 0.60-0.78: Rakic et al. 0.641 (our Tselin et al. 2024 film is brighter, 0.73).
/// - Ti 0.50-0.62: Mash & Motulevich 1973 0.529, Rakic et al. 0.574.
/// - W 0.46-0.54: Weaver, Olson & Lynch 1975 0.496, Rakic et al. 0.496.
const REFLECTANCE_550: [(&str, f64, f64); 9] = [
    ("Ag", 0.95, 0.995),
    ("Al", 0.90, 0.935),
    ("Au", 0.76, 0.88),
    ("Cr", 0.54, 0.72),
    ("Cu", 0.58, 0.70),
    ("Ni", 0.58, 0.68),
    ("Pt", 0.60, 0.78),
    ("Ti", 0.50, 0.62),
    ("W", 0.46, 0.54),
];

#[test]
fn reflectance_at_550_nm_agrees_with_independent_measurements() {
    assert_eq!(REFLECTANCE_550.len(), METALS.len());
    let mut report = String::new();
    for (symbol, low, high) in REFLECTANCE_550 {
        let r = reflectance_at(&table(symbol), 550.0);
        report += &format!("{symbol:2}: R(550 nm) = {r:.3} (plausible {low}-{high})\n");
    }
    print!("\n{report}");
    for (symbol, low, high) in REFLECTANCE_550 {
        let r = reflectance_at(&table(symbol), 550.0);
        assert!((low..=high).contains(&r), "{symbol}: R(550 nm) = {r:.4}, outside {low}-{high}");
    }
}

#[test]
fn gold_and_copper_look_warm_and_silver_neutral() {
    // sRGB-ish: the reflectance at 650 (R), 550 (G) and 450 nm (B).
    let rgb = |symbol: &str| {
        let rows = table(symbol);
        [650.0, 550.0, 450.0].map(|nm| reflectance_at(&rows, nm))
    };
    let mut report = String::from("normal-incidence reflectance at 650 / 550 / 450 nm:\n");
    for (symbol, _) in METALS {
        let [r, g, b] = rgb(symbol);
        report += &format!("{symbol:2}: R {r:.3}  G {g:.3}  B {b:.3}\n");
    }
    print!("\n{report}");
    for warm in ["Au", "Cu"] {
        let [r, g, b] = rgb(warm);
        assert!(r > g && g > b, "{warm} should be warm: R {r} G {g} B {b}");
    }
    // Gold's and copper's blue is well below their red (< 0.7 of it); silver's channels all lie
    // within 3 % of the largest.
    for warm in ["Au", "Cu"] {
        let [r, _, b] = rgb(warm);
        assert!(b < 0.7 * r, "{warm}: B {b} vs R {r}");
    }
    let silver = rgb("Ag");
    let max = silver.iter().copied().fold(f64::MIN, f64::max);
    let min = silver.iter().copied().fold(f64::MAX, f64::min);
    assert!(min > 0.97 * max, "silver should be neutral: {silver:?}");
}
