//! `spectrace-lab`: the experiment harness's command line (see [`spectrace_lab::cli`]).

fn main() -> std::process::ExitCode {
    spectrace_lab::cli::main()
}
