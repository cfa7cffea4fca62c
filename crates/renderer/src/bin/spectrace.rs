//! The `spectrace` command: render a scene file, or merge the partial films of a sharded render.
//! Everything is in [`spectrace_renderer::cli`]; see there, or `spectrace --help`.

use std::process::ExitCode;

fn main() -> ExitCode {
    spectrace_renderer::cli::main()
}
