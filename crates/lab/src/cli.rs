//! The `spectrace-lab` command line: `spectrace-lab accuracy [SCENES] [options]`.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

use crate::accuracy::{AccuracyOptions, Configuration};

/// Spectrace's experiment harness.
#[derive(Debug, Parser)]
#[command(name = "spectrace-lab", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Error against time for every accuracy knob: writes docs/accuracy.md and docs/accuracy.svg.
    Accuracy {
        /// Scene files (default: every scenes/*.json).
        scenes: Vec<PathBuf>,
        /// Beams of the cached reference image.
        #[arg(long)]
        reference_beams: Option<u64>,
        /// Beams of the first sweep point (doubled at each step).
        #[arg(long)]
        start_beams: Option<u64>,
        /// Number of sweep points.
        #[arg(long)]
        steps: Option<u32>,
        /// Largest image width (scenes are scaled down to it; 0 keeps their size).
        #[arg(long)]
        max_width: Option<u32>,
        /// The configurations to sweep, comma-separated (default: all): baseline (or light),
        /// equal_wavelengths, piecewise_constant_spd, effects_off, path, bdpt, auto,
        /// observer_wavelengths, sobol, path_sobol, bdpt_sobol, path_uniform_wavelengths.
        #[arg(long, value_delimiter = ',', value_parser = parse_configuration)]
        configurations: Vec<Configuration>,
        /// Where accuracy.md and accuracy.svg go.
        #[arg(long, default_value = "docs")]
        out: PathBuf,
    },
}

/// An accuracy configuration's name.
fn parse_configuration(s: &str) -> Result<Configuration, String> {
    Configuration::from_name(s.trim()).ok_or_else(|| {
        let names: Vec<&str> = Configuration::ALL.iter().map(|c| c.name()).collect();
        format!("`{s}`: must be one of {} (or light for baseline)", names.join(", "))
    })
}

/// Runs the command line of the process; the exit code (2 for bad arguments or a failed run).
pub fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            // Printing fails only if the stream is closed; there is nobody left to tell.
            let _ = e.print();
            return ExitCode::from(u8::try_from(e.exit_code()).unwrap_or(2));
        }
    };
    match cli.command {
        Command::Accuracy {
            scenes,
            reference_beams,
            start_beams,
            steps,
            max_width,
            configurations,
            out,
        } => {
            let mut options = AccuracyOptions::default();
            if !scenes.is_empty() {
                options.scenes = scenes;
            }
            if let Some(b) = reference_beams {
                options.reference_beams = b;
            }
            if let Some(b) = start_beams {
                options.start_beams = b;
            }
            if let Some(n) = steps {
                options.steps = n;
            }
            if let Some(w) = max_width {
                options.max_width = (w > 0).then_some(w);
            }
            if !configurations.is_empty() {
                options.configurations = configurations;
            }
            options.out_dir = out;
            match crate::accuracy::run(&options) {
                Ok(report) => {
                    println!("wrote {}", report.files.join(", "));
                    ExitCode::SUCCESS
                }
                Err(e) => {
                    eprintln!("error: {e}");
                    ExitCode::from(2)
                }
            }
        }
    }
}
