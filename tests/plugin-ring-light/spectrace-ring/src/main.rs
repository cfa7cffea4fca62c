//! `spectrace-ring`: the `spectrace` command (every subcommand, option and message) with the
//! example plugin `spectrace-plugin-ring-light` linked in, so scene files may use `"RingLight"`.

// typetag registers the plugin's light at link time; naming the crate keeps it linked.
use spectrace_plugin_ring_light as _;

fn main() -> std::process::ExitCode {
    spectrace_renderer::cli::main()
}
