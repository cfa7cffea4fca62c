//! The `spectrace` command line as a library: the `spectrace` binary is one call to [`main`], and a
//! binary that links a plugin crate (a third-party light or SPD registered with typetag) is the same
//! few lines, so the plugin's types are accepted in scene files:
//!
//! ```no_run
//! // src/bin/spectrace-ring.rs of a crate depending on the plugin and on spectrace-renderer:
//! // use spectrace_plugin_ring_light as _; // keep the plugin's typetag registrations linked
//! fn main() -> std::process::ExitCode {
//!     spectrace_renderer::cli::main()
//! }
//! ```
//!
//! ```sh
//! spectrace render scenes/prism.json --beams 2000000 --out out/ --threads 2 --seed 7
//! spectrace render scenes/prism.json --shard 0/4 --out parts/      # one of four machines
//! spectrace merge parts/*.bin --out out/                           # the same image, bit for bit
//! ```

use std::ffi::OsString;
use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use spectrace_tracer::{EffectsMode, ErrorMeasure, IntegratorChoice, Kernel};

use crate::say::{say, tell};
use crate::{ErrorImage, RenderOptions, merge_parts, render_file};

/// Spectrace: a spectral Monte Carlo renderer built around light sources as beam generators.
#[derive(Debug, Parser)]
#[command(version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Render a scene file to EXR (linear), PNG (sRGB) and a JSON sidecar.
    Render {
        /// The scene file: Spectrace's JSON (scenes/README.md) or a Mitsuba XML scene
        /// (docs/import.md).
        scene: PathBuf,
        /// For a Mitsuba scene: set `$NAME` to VALUE (over the file's <default>); repeatable.
        #[arg(short = 'D', value_name = "NAME=VALUE", value_parser = parse_define)]
        define: Vec<(String, String)>,
        /// Beams for the whole image (overrides settings.beams); for path and bdpt, exactly N
        /// camera samples: whole passes, then the first pixels of one more pass.
        #[arg(long, conflicts_with = "time", allow_negative_numbers = true, value_parser = parse_count)]
        beams: Option<u64>,
        /// Camera samples per pixel for the camera integrators, path and bdpt (overrides
        /// settings.spp).
        #[arg(long, conflicts_with = "time", allow_negative_numbers = true, value_parser = parse_count)]
        spp: Option<u64>,
        /// The estimator: auto (the effects analysis chooses), light, path or bdpt (overrides
        /// settings.integrator).
        #[arg(long, value_parser = parse_integrator)]
        integrator: Option<IntegratorChoice>,
        /// The kernel of the path tracer's camera paths: scalar (one path at a time, the
        /// default) or batched (16 paths stage by stage); overrides settings.kernel; the image
        /// is the same.
        #[arg(long, value_parser = parse_kernel)]
        kernel: Option<Kernel>,
        /// Render for this many seconds instead of a fixed number of beams (with
        /// --target-error: at most this long).
        #[arg(long, allow_negative_numbers = true, value_parser = parse_seconds)]
        time: Option<f64>,
        /// Render until the estimated relative error of the image (in --error-measure) is at
        /// most E (0.05 = 5%; overrides settings.target_error); --time and --beams/--spp cap it.
        #[arg(long, value_name = "E", allow_negative_numbers = true, value_parser = parse_target_error)]
        target_error: Option<f64>,
        /// What the estimated error and the target measure: relmse (per-pixel relative error,
        /// the default), energy (relative RMSE weighted by energy) or mean (RMSE over the
        /// image's mean); overrides settings.error_measure.
        #[arg(long, value_name = "MEASURE", value_parser = parse_error_measure)]
        error_measure: Option<ErrorMeasure>,
        /// Write NAME.error.exr: off, absolute (each pixel's standard error) or relative (over
        /// its value, with a false-colour NAME.error.png); overrides output.error_image.
        #[arg(long, value_name = "KIND", value_parser = parse_error_image)]
        error_image: Option<ErrorImage>,
        /// Output directory.
        #[arg(long, default_value = "out")]
        out: PathBuf,
        /// Worker threads (0: one per core; overrides settings.threads).
        #[arg(long, allow_negative_numbers = true, value_parser = parse_threads)]
        threads: Option<usize>,
        /// Seed of every random stream (overrides settings.seed).
        #[arg(long, allow_negative_numbers = true, value_parser = parse_seed)]
        seed: Option<u64>,
        /// Render only the work chunks whose index is K mod N and write a partial film (K/N);
        /// `auto` takes K and N from a Slurm, Kubernetes or AWS Batch array job
        /// (docs/cluster.md).
        #[arg(long, value_parser = parse_shard)]
        shard: Option<ShardArg>,
        /// The number of shards N, for `--shard auto` under Kubernetes (which does not say
        /// it); elsewhere it must agree with the scheduler's.
        #[arg(long, value_parser = clap::value_parser!(u64).range(1..))]
        shards: Option<u64>,
        /// Effects analysis: auto, off or direct_only (overrides effects.mode).
        #[arg(long, value_parser = parse_effects)]
        effects: Option<EffectsMode>,
        /// No progress bar or effects line.
        #[arg(long)]
        quiet: bool,
        /// Refuse any file the scene names (OBJ meshes, luminaire files) outside the scene file's folder, symlinks
        /// resolved: for scenes from others (see docs/robustness.md).
        #[arg(long)]
        restrict_paths: bool,
    },
    /// Measure paths/s of scenes with every estimator (light, path, bdpt, auto) and what the
    /// effects analysis saves the light tracer (auto against off).
    Bench {
        /// Scene files.
        #[arg(required = true)]
        scenes: Vec<PathBuf>,
        /// Paths per render: beams for the light tracer, ceil(N / pixels) samples per pixel for
        /// path and bdpt.
        #[arg(long, default_value_t = 1_000_000, allow_negative_numbers = true, value_parser = parse_count)]
        beams: u64,
        /// Worker threads (0: one per core).
        #[arg(long, default_value_t = 0, allow_negative_numbers = true, value_parser = parse_threads)]
        threads: usize,
    },
    /// Predict, from a short pilot render of each estimator, how long the scene takes to reach a
    /// target error, and recommend the fastest estimator.
    Estimate {
        /// The scene file (JSON; see scenes/README.md).
        scene: PathBuf,
        /// The target relative error (0.05 = 5%), in --error-measure.
        #[arg(long, value_name = "E", allow_negative_numbers = true, value_parser = parse_target_error)]
        target_error: f64,
        /// What the target measures: relmse (the default), energy or mean; overrides
        /// settings.error_measure.
        #[arg(long, value_name = "MEASURE", value_parser = parse_error_measure)]
        error_measure: Option<ErrorMeasure>,
        /// Pilot time per estimator, in seconds (the pilot renders at least 4 whole chunks).
        #[arg(long, default_value_t = crate::pilot::DEFAULT_PILOT_SECONDS, allow_negative_numbers = true, value_parser = parse_seconds)]
        pilot_seconds: f64,
        /// The estimators to try, comma-separated (default: light,path,bdpt).
        #[arg(long, value_delimiter = ',', value_parser = parse_integrator)]
        integrators: Vec<IntegratorChoice>,
        /// Worker threads (0: one per core).
        #[arg(long, default_value_t = 0, allow_negative_numbers = true, value_parser = parse_threads)]
        threads: usize,
        /// Also write the report as JSON to this file (it must not be the scene file).
        #[arg(long)]
        json: Option<PathBuf>,
        /// Refuse any file the scene names outside the scene file's folder.
        #[arg(long)]
        restrict_paths: bool,
    },
    /// Convert a Mitsuba XML scene into Spectrace's JSON scene (docs/import.md).
    Convert {
        /// The Mitsuba scene file (.xml).
        scene: PathBuf,
        /// The JSON file to write (never one of the scene's own files).
        #[arg(long)]
        out: PathBuf,
        /// Set `$NAME` to VALUE (over the file's <default>); repeatable.
        #[arg(short = 'D', value_name = "NAME=VALUE", value_parser = parse_define)]
        define: Vec<(String, String)>,
    },
    /// Merge partial films (from `render --shard`) into the final outputs.
    Merge {
        /// The partial films (.bin).
        #[arg(required = true)]
        parts: Vec<PathBuf>,
        /// Output directory.
        #[arg(long, default_value = "out")]
        out: PathBuf,
    },
}

/// A `-D NAME=VALUE` definition.
fn parse_define(s: &str) -> Result<(String, String), String> {
    match s.split_once('=') {
        Some((k, v))
            if !k.is_empty() && k.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') =>
        {
            Ok((k.to_owned(), v.to_owned()))
        }
        _ => Err(format!("`{s}`: must be NAME=VALUE, NAME of letters, digits and _")),
    }
}

/// An error measure's name.
fn parse_error_measure(s: &str) -> Result<ErrorMeasure, String> {
    ErrorMeasure::from_name(s.trim())
        .ok_or_else(|| format!("`{s}`: must be relmse, energy or mean"))
}

/// An error image kind.
fn parse_error_image(s: &str) -> Result<ErrorImage, String> {
    [ErrorImage::Off, ErrorImage::Absolute, ErrorImage::Relative]
        .into_iter()
        .find(|e| e.name() == s.trim())
        .ok_or_else(|| format!("`{s}`: must be off, absolute or relative"))
}

/// A kernel name.
fn parse_kernel(s: &str) -> Result<Kernel, String> {
    Kernel::from_name(s).ok_or_else(|| format!("`{s}`: must be batched or scalar"))
}

/// An integrator name.
fn parse_integrator(s: &str) -> Result<IntegratorChoice, String> {
    IntegratorChoice::from_name(s.trim())
        .ok_or_else(|| format!("`{s}`: must be {}", crate::integrators::choice_names()))
}

/// A whole number of at least 1 (beams).
fn parse_count(s: &str) -> Result<u64, String> {
    match s.trim().parse::<u64>() {
        Ok(0) => Err(format!("`{s}`: must be at least 1")),
        Ok(n) => Ok(n),
        Err(_) if s.trim().parse::<f64>().is_ok() => Err(format!(
            "`{s}`: must be a whole number from 1 to {} (no sign, no decimals)",
            u64::MAX
        )),
        Err(_) => Err(format!("`{s}`: not a whole number")),
    }
}

/// A positive, finite number of seconds.
fn parse_seconds(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(t) if t > 0.0 && t.is_finite() => Ok(t),
        Ok(_) => Err(format!("`{s}`: must be a positive, finite number of seconds")),
        Err(_) => Err(format!("`{s}`: not a number of seconds")),
    }
}

/// A target relative error in (0, 1).
fn parse_target_error(s: &str) -> Result<f64, String> {
    let e: f64 = s.trim().parse().map_err(|_| format!("`{s}`: not a number"))?;
    crate::check_target_error(e)?;
    Ok(e)
}

/// A thread count (0: one per core).
fn parse_threads(s: &str) -> Result<usize, String> {
    s.trim().parse::<usize>().map_err(|_| {
        format!("`{s}`: must be a whole number of threads, from 0 (one per core) to 256")
    })
}

/// A 64-bit seed.
fn parse_seed(s: &str) -> Result<u64, String> {
    s.trim()
        .parse::<u64>()
        .map_err(|_| format!("`{s}`: must be a whole number from 0 to {}", u64::MAX))
}

/// `--shard`: `K/N`, or `auto` (from the scheduler's environment).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum ShardArg {
    /// `K/N` as given.
    Given(u64, u64),
    /// `auto`.
    Auto,
}

fn parse_shard(s: &str) -> Result<ShardArg, String> {
    if s.trim() == "auto" {
        return Ok(ShardArg::Auto);
    }
    let (k, n) = parse_shard_k_n(s)?;
    Ok(ShardArg::Given(k, n))
}

/// `--shard K/N` as the pair.
fn parse_shard_k_n(s: &str) -> Result<(u64, u64), String> {
    let (k, n) = s.split_once('/').ok_or_else(|| format!("`{s}`: expected K/N, e.g. 0/4"))?;
    let k: u64 = k.trim().parse().map_err(|_| format!("`{s}`: K is not a number"))?;
    let n: u64 = n.trim().parse().map_err(|_| format!("`{s}`: N is not a number"))?;
    if n == 0 || k >= n {
        return Err(format!("`{s}`: need 0 <= K < N"));
    }
    Ok((k, n))
}

fn parse_effects(s: &str) -> Result<EffectsMode, String> {
    match s {
        "auto" => Ok(EffectsMode::Auto),
        "off" => Ok(EffectsMode::Off),
        "direct_only" | "direct-only" => Ok(EffectsMode::DirectOnly),
        _ => Err(format!("`{s}`: expected auto, off or direct_only")),
    }
}

/// Paths per second as millions, three significant digits.
fn millions(rate: f64) -> String {
    let m = rate / 1e6;
    if m >= 10.0 {
        format!("{m:.1} M")
    } else if m >= 1.0 {
        format!("{m:.2} M")
    } else {
        format!("{m:.3} M")
    }
}

/// `spectrace bench`: a Markdown table per scene of paths/s for every estimator with the same
/// paths (light, path, bdpt and auto, and which one auto picks), and what the effects analysis
/// saves the light tracer (auto against off).
fn bench(scenes: &[PathBuf], beams: u64, threads: usize) -> ExitCode {
    say!(
        "| scene | pixels | auto picks | paths/s, light | paths/s, path | paths/s, bdpt | paths/s, auto | light: beams/s with effects off | light: spectral samples on film per s, effects auto / off |"
    );
    say!("|---|---|---|---|---|---|---|---|---|");
    for path in scenes {
        let row = crate::Scene::load(path)
            .map_err(|e| crate::RenderError::from(e).to_string())
            .and_then(|scene| {
                let integrators = crate::integrator_benchmark(&scene, beams, threads)?;
                let effects =
                    crate::effects_benchmark(&scene, beams, threads).map_err(|e| e.to_string())?;
                Ok((integrators, effects))
            });
        match row {
            Ok((i, r)) => {
                let name = path
                    .file_stem()
                    .map_or_else(|| r.scene.clone(), |s| s.to_string_lossy().into_owned());
                let rates: Vec<String> =
                    i.timings.iter().map(|t| millions(t.paths_per_second())).collect();
                let effects_gain = r.auto_spectral_samples_per_second
                    / r.off_spectral_samples_per_second.max(1e-300);
                say!(
                    "| `{name}` | {}x{} | {} | {} | {} | {effects_gain:.2}x |",
                    i.width,
                    i.height,
                    i.auto_picks.name(),
                    rates.join(" | "),
                    millions(r.beams as f64 / r.off_seconds),
                );
            }
            Err(e) => {
                tell!("error: {e}");
                return ExitCode::from(2);
            }
        }
    }
    ExitCode::SUCCESS
}

/// `spectrace estimate`: the pilots, a Markdown table on stdout, and optionally the JSON.
fn estimate_command(
    scene: &std::path::Path,
    (target_error, error_measure): (f64, Option<ErrorMeasure>),
    pilot_seconds: f64,
    integrators: Vec<IntegratorChoice>,
    threads: usize,
    json: Option<&std::path::Path>,
    restrict_paths: bool,
) -> ExitCode {
    let run = || -> Result<String, String> {
        let scene = crate::Scene::load_with(scene, crate::LoadOptions { restrict_paths })
            .map_err(|e| e.to_string())?;
        if let Some(out) = json {
            // Never over an input: the scene file or a mesh it names.
            crate::check_no_input_replaced(&[out.to_path_buf()], &scene.inputs)?;
        }
        let mut options = crate::pilot::EstimateOptions {
            target_error,
            pilot_seconds,
            threads,
            error_measure,
            ..Default::default()
        };
        if !integrators.is_empty() {
            options.integrators =
                integrators.into_iter().filter(|&i| i != IntegratorChoice::Auto).collect();
        }
        let report = crate::pilot::estimate(&scene, &options).map_err(|e| e.to_string())?;
        if let Some(out) = json {
            let text = serde_json::to_string_pretty(&report).map_err(|e| e.to_string())?;
            crate::write_atomically(out, |p| std::fs::write(p, &text).map_err(|e| e.to_string()))
                .map_err(|e| format!("{}: {e}", out.display()))?;
        }
        Ok(crate::pilot::markdown(&report))
    };
    match run() {
        Ok(md) => {
            // As `say!`: a closed stdout loses the report, not the exit code.
            let _ = std::io::Write::write_all(&mut std::io::stdout().lock(), md.as_bytes());
            ExitCode::SUCCESS
        }
        Err(e) => {
            tell!("error: {e}");
            ExitCode::from(2)
        }
    }
}

/// Runs the `spectrace` command line on the process's arguments ([`std::env::args_os`]).
pub fn main() -> ExitCode {
    main_with_args(std::env::args_os())
}

/// Runs the `spectrace` command line on `args` (the first is the program name, as in
/// [`std::env::args_os`]): parses them, runs the subcommand, prints its report or error, and returns
/// the exit code (0 on success, 2 on a bad argument or a failed render).
///
/// `--help` and `--version` print to stdout and return 0; a bad argument prints clap's message,
/// which names the option and the cause, to stderr and returns 2.
pub fn main_with_args<I, T>(args: I) -> ExitCode
where
    I: IntoIterator<Item = T>,
    T: Into<OsString> + Clone,
{
    let cli = match Cli::try_parse_from(args) {
        Ok(cli) => cli,
        Err(e) => return clap_exit(&e),
    };
    let result = match cli.command {
        Command::Render {
            scene,
            define,
            beams,
            time,
            out,
            threads,
            seed,
            shard,
            shards,
            effects,
            quiet,
            restrict_paths,
            spp,
            integrator,
            target_error,
            error_measure,
            error_image,
            kernel,
        } => {
            let shard = match (shard, shards) {
                (None, None) => None,
                (Some(ShardArg::Given(k, n)), None) => Some((k, n)),
                (Some(ShardArg::Given(k, n)), Some(s)) if s == n => Some((k, n)),
                (Some(ShardArg::Given(_, n)), Some(s)) => {
                    tell!("error: --shards {s} disagrees with --shard's N = {n}");
                    return ExitCode::from(2);
                }
                (Some(ShardArg::Auto), shards) => {
                    match crate::shard_from_environment(|v| std::env::var(v).ok(), shards) {
                        Ok(shard) => Some(shard),
                        Err(e) => {
                            tell!("error: {e}");
                            return ExitCode::from(2);
                        }
                    }
                }
                (None, Some(_)) => {
                    tell!("error: --shards N goes with --shard auto (or --shard K/N)");
                    return ExitCode::from(2);
                }
            };
            let options = RenderOptions {
                kernel,
                error_measure,
                error_image,
                target_error,
                spp,
                integrator,
                beams,
                time,
                threads,
                seed,
                shard,
                effects,
                out_dir: out,
                verbose: !quiet,
                restrict_paths,
            };
            if define.is_empty() {
                render_file(&scene, &options)
            } else {
                crate::Scene::import_with(&scene, &define, crate::LoadOptions { restrict_paths })
                    .map_err(crate::RenderError::from)
                    .and_then(|scene| crate::render_scene(&scene, &options))
            }
        }
        Command::Convert { scene, out, define } => {
            return crate::convert::convert_command(&scene, &out, &define);
        }
        Command::Merge { parts, out } => merge_parts(&parts, &out),
        Command::Estimate {
            scene,
            target_error,
            error_measure,
            pilot_seconds,
            integrators,
            threads,
            json,
            restrict_paths,
        } => {
            return estimate_command(
                &scene,
                (target_error, error_measure),
                pilot_seconds,
                integrators,
                threads,
                json.as_deref(),
                restrict_paths,
            );
        }
        Command::Bench { scenes, beams, threads } => return bench(&scenes, beams, threads),
    };
    match result {
        Ok(report) => {
            for w in &report.warnings {
                tell!("warning: {w}");
            }
            say!(
                "{} beams in {:.2} s ({:.3e} beams/s), {} rejected contributions; wrote {}",
                report.beams,
                report.wall_seconds,
                report.beams_per_second,
                report.rejected_contributions,
                report.outputs.join(", ")
            );
            if let Some(e) = &report.error_estimate {
                say!("{}", e.summary());
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            tell!("error: {e}");
            ExitCode::from(2)
        }
    }
}

/// Prints a clap error (or help or version) as `Cli::parse` would and returns its exit code.
fn clap_exit(e: &clap::Error) -> ExitCode {
    // Printing fails only if the stream is closed; there is nobody left to tell.
    let _ = e.print();
    ExitCode::from(u8::try_from(e.exit_code()).unwrap_or(2))
}
