//! Mitsuba's colours and spectra as Spectrace's: reflectances (bounded, held as tables that are
//! zero outside Mitsuba's tables), emitted spectra in Mitsuba's units (spectral radiance,
//! intensity or irradiance per nm), and unbounded spectra (indices of refraction).
//!
//! | Mitsuba | reflectance | emission | unbounded |
//! |---|---|---|---|
//! | `<float value="v">` | `v` | D65 of luminance `v` | `v` |
//! | `<rgb value="r, g, b">` (or one value) | Jakob-Hanika fit | D65 times the fit (Mitsuba's `d65` plugin) | the fit, scaled |
//! | `<srgb>` (0.6) | as `rgb`, after sRGB decoding | as `rgb` | as `rgb` |
//! | `<spectrum value="v">` | `v` | `v` per nm (uniform, no D65) | `v` |
//! | `<spectrum value="l1:v1, l2:v2, ...">` | the table, zero outside it | the table | the table |
//! | `<spectrum type="blackbody">` (`temperature`, `scale`) | refused | Planck's law, W m^-2 sr^-1 nm^-1 | refused |
//! | `<spectrum type="d65">` (`scale`) | refused | D65 of luminance `scale` | refused |
//! | `<spectrum type="uniform/regular/irregular">` | as the value forms | as the value forms | as the value forms |

use spectrace_spectrum::rgb::{
    SigmoidSpectrum, VISIBLE_MAX_NM, VISIBLE_MIN_NM, d65_luminance, d65_visible, illuminant_table,
    unbounded_table, visible_grid,
};
use spectrace_spectrum::{PLANCK_C2_NM_K, srgb_decode};

use super::values::{number, numbers};
use super::xml::{Element, ImportError, error_at};

/// What a spectrum is used as.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Role {
    /// A reflectance or transmittance: values in `[0, 1]`.
    Reflectance,
    /// An emitted spectrum: radiance, intensity or irradiance per nm.
    Emission,
    /// An index of refraction or extinction coefficient.
    Unbounded,
}

/// A spectrum: one value at every wavelength, or a table (linear between points, zero outside).
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Spec {
    Constant(f64),
    Table(Vec<f64>, Vec<f64>),
}

impl Spec {
    /// The native JSON of a reflectance (a number, or a table padded with zeros beyond its ends
    /// where it does not span 360-830 nm, since Spectrace's tables hold their end values).
    pub(crate) fn reflectance_json(&self) -> serde_json::Value {
        match self {
            Spec::Constant(v) => serde_json::json!(v),
            Spec::Table(nm, values) => {
                let (mut nm, mut values) = (nm.clone(), values.clone());
                const STEP: f64 = 1e-3;
                if nm[0] > VISIBLE_MIN_NM && values[0] != 0.0 {
                    nm.insert(0, nm[0] - STEP);
                    values.insert(0, 0.0);
                }
                let last = nm.len() - 1;
                if nm[last] < VISIBLE_MAX_NM && values[last] != 0.0 {
                    nm.push(nm[last] + STEP);
                    values.push(0.0);
                }
                serde_json::json!({ "nm": nm, "values": values })
            }
        }
    }

    /// The native JSON of an unbounded spectrum as a table (`eta`, `k`).
    pub(crate) fn table_json(&self) -> serde_json::Value {
        match self {
            Spec::Constant(v) => {
                serde_json::json!({ "nm": [VISIBLE_MIN_NM, VISIBLE_MAX_NM], "values": [v, v] })
            }
            Spec::Table(nm, values) => serde_json::json!({ "nm": nm, "values": values }),
        }
    }

    /// An emitted spectrum as `(integral over wavelength, native Tabulated SPD)`; a constant
    /// spans 360-830 nm (Mitsuba's range). `None` when it emits nothing.
    pub(crate) fn emission(&self) -> Option<(f64, serde_json::Value)> {
        let (nm, values) = match self {
            Spec::Constant(v) => (vec![VISIBLE_MIN_NM, VISIBLE_MAX_NM], vec![*v, *v]),
            Spec::Table(nm, values) => (nm.clone(), values.clone()),
        };
        let integral: f64 = nm
            .windows(2)
            .zip(values.windows(2))
            .map(|(l, v)| (l[1] - l[0]) * (v[0] + v[1]) / 2.0)
            .sum();
        (integral > 0.0 && nm.len() >= 2).then(|| {
            (integral, serde_json::json!({ "type": "Tabulated", "nm": nm, "values": values }))
        })
    }

    /// The spectrum with `f(lambda, value)` applied to its values (a constant at 550 nm).
    pub(crate) fn map(&self, f: impl Fn(f64, f64) -> f64) -> Spec {
        match self {
            Spec::Constant(v) => Spec::Constant(f(550.0, *v)),
            Spec::Table(nm, values) => {
                Spec::Table(nm.clone(), nm.iter().zip(values).map(|(&l, &v)| f(l, v)).collect())
            }
        }
    }

    /// The value when constant.
    pub(crate) fn constant(&self) -> Option<f64> {
        match self {
            Spec::Constant(v) => Some(*v),
            Spec::Table(..) => None,
        }
    }
}

/// The spectrum of a property element used as `role`.
pub(crate) fn spectrum(el: &Element, role: Role) -> Result<Spec, ImportError> {
    let what = el.describe();
    let fail = |m: String| error_at(&el.loc, format!("{what}: {m}"));
    match el.tag.as_str() {
        "float" | "integer" => {
            let v = number(el)?;
            match role {
                Role::Emission => rgb(el, [v; 3], role),
                _ => Ok(Spec::Constant(v)),
            }
        }
        "rgb" | "srgb" | "color" => {
            let v = numbers(el, el.required("value")?)?;
            let mut c = match v.as_slice() {
                [g] => [*g; 3],
                [r, g, b] => [*r, *g, *b],
                _ => return Err(fail("one or three numbers expected".to_owned())),
            };
            if el.tag == "srgb" {
                c = c.map(srgb_decode);
            }
            rgb(el, c, role)
        }
        "spectrum" => match el.attr("type") {
            None => match el.attr("value") {
                Some(text) => value_spectrum(el, text),
                None if el.attr("filename").is_some() => spectrum_file(el),
                None => Err(fail("needs `value`".to_owned())),
            },
            Some(kind) => typed_spectrum(el, kind, role),
        },
        "texture" | "ref" => Err(fail(
            "textures are not supported yet (bitmap and checkerboard textures are planned); give a colour or spectrum"
                .to_owned(),
        )),
        other => Err(fail(format!("<{other}> is not a colour or spectrum"))),
    }
}

/// `value="0.5"` or `value="400:0.1, 500:0.2"`.
fn value_spectrum(el: &Element, text: &str) -> Result<Spec, ImportError> {
    if !text.contains(':') {
        return match numbers(el, text)?.as_slice() {
            [v] => Ok(Spec::Constant(*v)),
            _ => Err(error_at(
                &el.loc,
                format!("{}: one number or wavelength:value pairs expected", el.describe()),
            )),
        };
    }
    let mut nm = Vec::new();
    let mut values = Vec::new();
    for pair in text.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        let (l, v) = pair.split_once(':').ok_or_else(|| {
            error_at(&el.loc, format!("{}: `{pair}` is not a wavelength:value pair", el.describe()))
        })?;
        let parse = |s: &str| s.trim().parse::<f64>().ok().filter(|v| v.is_finite());
        match (parse(l), parse(v)) {
            (Some(l), Some(v)) => {
                nm.push(l);
                values.push(v);
            }
            _ => {
                return Err(error_at(
                    &el.loc,
                    format!("{}: `{pair}` is not two numbers", el.describe()),
                ));
            }
        }
    }
    table(el, nm, values)
}

/// `<spectrum filename="...">`: a text file of `wavelength value` lines (`#` comments), resolved
/// against the folder of the file that names it, at most `MAX_SCENE_BYTES` long, under the scene
/// folder's path policy.
fn spectrum_file(el: &Element) -> Result<Spec, ImportError> {
    let name = el.required("filename")?;
    let path = el.loc.file.parent().unwrap_or_else(|| std::path::Path::new(".")).join(name);
    let fail = |m: String| error_at(&el.loc, format!("{}: {m}", path.display()));
    let (_, text) = spectrace_sampling::files::read_scene_input(
        &path,
        crate::files::MAX_SCENE_BYTES,
        "spectrum file",
    )
    .map_err(|e| error_at(&el.loc, e))?;
    let (mut nm, mut values) = (Vec::new(), Vec::new());
    for (i, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let parsed: Vec<f64> = line
            .split_whitespace()
            .filter_map(|t| t.parse().ok())
            .filter(|v: &f64| v.is_finite())
            .collect();
        match parsed.as_slice() {
            [l, v] => {
                nm.push(*l);
                values.push(*v);
            }
            _ => {
                return Err(fail(format!(
                    "line {}: `{line}` is not two numbers (wavelength value)",
                    i + 1
                )));
            }
        }
    }
    table(el, nm, values)
}

/// A checked table: increasing wavelengths, at least one point.
fn table(el: &Element, nm: Vec<f64>, values: Vec<f64>) -> Result<Spec, ImportError> {
    if nm.is_empty() || nm.len() != values.len() {
        return Err(error_at(
            &el.loc,
            format!("{}: a table needs as many values as wavelengths, at least one", el.describe()),
        ));
    }
    if let Some(i) = (1..nm.len()).find(|&i| nm[i] <= nm[i - 1]) {
        return Err(error_at(
            &el.loc,
            format!("{}: wavelengths must increase ({} after {})", el.describe(), nm[i], nm[i - 1]),
        ));
    }
    Ok(if nm.len() == 1 { Spec::Constant(values[0]) } else { Spec::Table(nm, values) })
}

/// `<spectrum type="...">`.
fn typed_spectrum(el: &Element, kind: &str, role: Role) -> Result<Spec, ImportError> {
    let fail = |m: String| error_at(&el.loc, format!("{}: {m}", el.describe()));
    let param = |name: &str| el.children.iter().find(|c| c.attr("name") == Some(name));
    let float = |name: &str, default: Option<f64>| match param(name) {
        Some(p) => number(p),
        None => default.ok_or_else(|| fail(format!("needs <float name=\"{name}\">"))),
    };
    let list = |name: &str| -> Result<Vec<f64>, ImportError> {
        let p = param(name).ok_or_else(|| fail(format!("needs `{name}`")))?;
        numbers(p, p.required("value")?)
    };
    match kind {
        "uniform" => Ok(Spec::Constant(float("value", None)?)),
        "irregular" => table(el, list("wavelengths")?, list("values")?),
        "regular" => {
            let values = list("values")?;
            let (lo, hi) = (float("wavelength_min", None)?, float("wavelength_max", None)?);
            let n = values.len();
            let nm = (0..n)
                .map(|i| if n == 1 { lo } else { lo + (hi - lo) * i as f64 / (n - 1) as f64 })
                .collect();
            table(el, nm, values)
        }
        "blackbody" if role == Role::Emission => {
            let t = float("temperature", None)?;
            let scale = float("scale", Some(1.0))?;
            if !(t > 0.0) {
                return Err(fail(format!("temperature {t}: must be above 0 K")));
            }
            let nm = visible_grid();
            let values = nm.iter().map(|&l| scale * planck(l, t)).collect();
            Ok(Spec::Table(nm, values))
        }
        "d65" if role == Role::Emission => {
            let scale = float("scale", Some(1.0))?;
            let nm = visible_grid();
            let values = nm.iter().map(|&l| scale * d65_visible(l) / d65_luminance()).collect();
            Ok(Spec::Table(nm, values))
        }
        "srgb" => {
            let c = param("color").ok_or_else(|| fail("needs <rgb name=\"color\">".to_owned()))?;
            spectrum(c, role)
        }
        "blackbody" | "d65" => {
            Err(fail("is an emission spectrum; here a reflectance is expected".to_owned()))
        }
        other => Err(fail(format!(
            "spectrum type \"{other}\" is not supported (uniform, regular, irregular, blackbody, d65, srgb are)"
        ))),
    }
}

/// Planck's law: spectral radiance in W m^-2 sr^-1 nm^-1 at `nm` and `kelvin`, as Mitsuba 3's
/// `blackbody` gives it.
fn planck(nm: f64, kelvin: f64) -> f64 {
    const C: f64 = 299_792_458.0;
    const H: f64 = 6.626_070_15e-34;
    let l = nm * 1e-9;
    let c1 = 2.0 * H * C * C;
    // per m of wavelength, then per nm
    c1 / (l.powi(5) * ((PLANCK_C2_NM_K / (nm * kelvin)).exp() - 1.0)) * 1e-9
}

/// An RGB colour used as `role`.
fn rgb(el: &Element, c: [f64; 3], role: Role) -> Result<Spec, ImportError> {
    let fail =
        |e: spectrace_spectrum::SpectrumError| error_at(&el.loc, format!("{}: {e}", el.describe()));
    match role {
        Role::Reflectance => {
            if c[0] == c[1] && c[1] == c[2] {
                return Ok(Spec::Constant(c[0]));
            }
            let s = SigmoidSpectrum::fit(c).map_err(fail)?;
            let (nm, values) = s.table();
            Ok(Spec::Table(nm, values))
        }
        Role::Emission => illuminant_table(c).map(|(n, v)| Spec::Table(n, v)).map_err(fail),
        Role::Unbounded => {
            if c[0] == c[1] && c[1] == c[2] {
                return Ok(Spec::Constant(c[0]));
            }
            unbounded_table(c).map(|(n, v)| Spec::Table(n, v)).map_err(fail)
        }
    }
}
