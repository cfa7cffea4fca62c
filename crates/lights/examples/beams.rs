//! Loads a light from JSON (a file, or the argument itself) and prints its first beams:
//!
//! ```sh
//! cargo run -p spectrace-lights --example beams -- '{"type": "PointLight", "position": [0, 0, 0], "power": 1, "spd": {"type": "Blackbody", "kelvin": 3000}}'
//! ```

use std::process::ExitCode;

use rand::SeedableRng;
use spectrace_lights::LightSource;

fn main() -> ExitCode {
    let Some(arg) = std::env::args().nth(1) else {
        eprintln!("usage: beams '<light JSON>' | <file.json> [count]");
        return ExitCode::from(2);
    };
    let json = std::fs::read_to_string(&arg).unwrap_or(arg);
    let count: usize = std::env::args().nth(2).and_then(|c| c.parse().ok()).unwrap_or(5);
    let light: Box<dyn LightSource> = match serde_json::from_str(&json) {
        Ok(l) => l,
        Err(e) => {
            eprintln!("invalid light: {e}");
            return ExitCode::from(2);
        }
    };
    let mut rng = rand_pcg::Pcg64::seed_from_u64(1);
    let beams: Vec<_> = (0..count).map(|_| light.next_beam(&mut rng)).collect();
    for b in &beams {
        println!(
            "origin {:?} direction {:?} lambda {:.3} nm scale {:.4} parent {} power {:.6e} W",
            b.origin.to_array(),
            b.direction.to_array(),
            b.lambda,
            b.scale,
            b.parent.0,
            b.power(light.power(), light.number_of_beams())
        );
    }
    ExitCode::SUCCESS
}
