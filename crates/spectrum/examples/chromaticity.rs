//! Prints the CIE 1931 chromaticity and linear sRGB of every CIE illuminant and of blackbodies,
//! or of an SPD given as JSON on the command line:
//!
//! ```sh
//! cargo run --release -p spectrace-spectrum --example chromaticity
//! cargo run --release -p spectrace-spectrum --example chromaticity -- '{"type": "Gaussian", "center_nm": 532, "fwhm_nm": 2}'
//! ```

use std::process::ExitCode;

use spectrace_spectrum::{Blackbody, CieIlluminant, SpectralPowerDistribution, xyz_of};

fn report(name: &str, spd: &dyn SpectralPowerDistribution) {
    let xyz = xyz_of(spd);
    let (x, y) = xyz.chromaticity().unwrap_or((f64::NAN, f64::NAN));
    // Scale so Y = 1 before converting, to show the colour rather than the brightness.
    let rgb = (xyz * (1.0 / xyz.y)).to_linear_srgb();
    let (lo, hi) = spd.range();
    println!(
        "{name:<18} {lo:>6.1}-{hi:<6.1} nm  x = {x:.5}  y = {y:.5}  linear sRGB (Y = 1) = ({:.3}, {:.3}, {:.3})",
        rgb[0], rgb[1], rgb[2]
    );
}

fn main() -> ExitCode {
    if let Some(json) = std::env::args().nth(1) {
        return match serde_json::from_str::<Box<dyn SpectralPowerDistribution>>(&json) {
            Ok(spd) => {
                report("given SPD", spd.as_ref());
                ExitCode::SUCCESS
            }
            Err(e) => {
                eprintln!("invalid SPD: {e}");
                ExitCode::from(2)
            }
        };
    }
    for name in spectrace_spectrum::KNOWN_ILLUMINANTS.split(", ") {
        match CieIlluminant::new(name) {
            Ok(spd) => report(&format!("CIE {name}"), &spd),
            Err(e) => eprintln!("{e}"),
        }
    }
    for kelvin in [1000.0, 2000.0, 2856.0, 4000.0, 5000.0, 6500.0, 10000.0, 20000.0] {
        match Blackbody::new(kelvin) {
            Ok(spd) => report(&format!("blackbody {kelvin} K"), &spd),
            Err(e) => eprintln!("{e}"),
        }
    }
    ExitCode::SUCCESS
}
