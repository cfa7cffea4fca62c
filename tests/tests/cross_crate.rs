//! Cross-crate tests: contracts between the Spectrace crates that no single crate can check.
#![allow(clippy::unwrap_used)]

mod camera_estimators;
mod environment;
mod estimate;
mod fluorescence;
mod fuzz;
mod hostile;
mod import;
mod integrators;
mod kernels;
mod many_lights;
mod measured_auto;
mod observers;
mod photometry;
mod real_luminaires;
mod rendering;
mod rough_materials;
mod textures;
mod time_budget;
mod variance;

use rand::SeedableRng;
use rand_pcg::Pcg64;
use serde::{Deserialize, Serialize};
use spectrace_sampling::{PiecewiseConstant, PiecewiseLinear};
use spectrace_spectrum::{Binned, SpectralPowerDistribution, Tabulated, xyz_of};

/// A spectrum samples exactly what the sampling crate's generator over the same table samples:
/// the spectrum layer adds validation and naming, never a different distribution.
#[test]
fn spectra_use_the_exact_generators_of_the_sampling_crate() {
    let nm = [380.0, 450.0, 451.0, 600.0, 780.0];
    let values = [0.0, 3.0, 0.2, 0.2, 1.0];
    let spd = Tabulated::new(&nm, &values).unwrap();
    let table = PiecewiseLinear::new(&nm, &values).unwrap();
    let edges = [400.0, 500.0, 600.0];
    let binned = Binned::new(&edges, &[1.0, 2.0]).unwrap();
    let choppy = PiecewiseConstant::new(&edges, &[1.0, 2.0]).unwrap();
    for k in 0..1000 {
        let u = k as f64 / 1000.0;
        assert_eq!(spd.sample_lambda(u).to_bits(), table.sample(u).to_bits());
        assert_eq!(binned.sample_lambda(u).to_bits(), choppy.sample(u).to_bits());
        let l = 380.0 + 0.4 * k as f64;
        assert_eq!(spd.value(l).to_bits(), table.pdf(l).to_bits());
    }
}

/// A third party adds an SPD type with `#[typetag::serde]`, outside `spectrace-spectrum`, and a
/// scene file names it next to the built-in ones.
#[derive(Debug, Serialize, Deserialize)]
struct Sawtooth {
    min_nm: f64,
    max_nm: f64,
}

#[typetag::serde]
impl SpectralPowerDistribution for Sawtooth {
    fn sample_lambda(&self, u: f64) -> f64 {
        // Density rising linearly from 0 at min to 2 / (max - min) at max: CDF t^2.
        self.min_nm + (self.max_nm - self.min_nm) * u.sqrt()
    }
    fn value(&self, lambda: f64) -> f64 {
        if (self.min_nm..=self.max_nm).contains(&lambda) {
            2.0 * (lambda - self.min_nm) / (self.max_nm - self.min_nm).powi(2)
        } else {
            0.0
        }
    }
    fn range(&self) -> (f64, f64) {
        (self.min_nm, self.max_nm)
    }
}

#[test]
fn third_party_spd_deserialises_beside_built_in_ones() {
    let json = r#"[
        {"type": "Sawtooth", "min_nm": 400, "max_nm": 700},
        {"type": "Tabulated", "nm": [400, 700], "values": [0, 1]}
    ]"#;
    let spds: Vec<Box<dyn SpectralPowerDistribution>> = serde_json::from_str(json).unwrap();
    assert_eq!(spds.len(), 2);
    // The plugin and the built-in table describe the same ramp: same colour, same samples.
    let (a, b) = (xyz_of(spds[0].as_ref()), xyz_of(spds[1].as_ref()));
    assert!((a.x - b.x).abs() < 1e-9 && (a.y - b.y).abs() < 1e-9 && (a.z - b.z).abs() < 1e-9);
    let mut rng = Pcg64::seed_from_u64(1);
    for _ in 0..100 {
        let u: f64 = rand::RngExt::random(&mut rng);
        assert!((spds[0].sample_lambda(u) - spds[1].sample_lambda(u)).abs() < 1e-9);
    }
    let back = serde_json::to_string(&spds).unwrap();
    assert!(back.contains(r#""type":"Sawtooth""#), "{back}");
}

// ---------------------------------------------------------------------------------------------
// Third-party lights by serialisation
// ---------------------------------------------------------------------------------------------

// Linking the plugin crate is what makes typetag's registry see `RingLight` (see its docs).
use spectrace_lights::{Beam, LightId, LightSet, LightSource};
use spectrace_plugin_ring_light as _;

const SCENE_LIGHTS: &str = r#"{"type": "LightSet", "lights": [
    {"type": "RingLight", "center": [0, 2, 0], "axis": [0, 1, 0], "radius": 0.3, "power": 40,
     "spd": {"type": "CieIlluminant", "name": "F2"}},
    {"type": "PointLight", "position": [1, 1, 1], "power": 10, "spd": {"type": "Blackbody", "kelvin": 2700}}
]}"#;

fn first_beams(light: &dyn LightSource) -> Vec<Beam> {
    let mut rng = Pcg64::seed_from_u64(3);
    (0..1000).map(|_| light.next_beam(&mut rng)).collect()
}

#[test]
fn plugin_light_loads_from_json_beside_built_in_lights() {
    let set: Box<dyn LightSource> = serde_json::from_str(SCENE_LIGHTS).unwrap();
    assert_eq!(set.power(), 50.0);
    let beams = first_beams(set.as_ref());
    let ring: Vec<&Beam> = beams.iter().filter(|b| b.parent == LightId(0)).collect();
    assert!(
        ring.len() > 700 && ring.len() < 900,
        "ring share {} of 1000 (expected 800)",
        ring.len()
    );
    for b in ring {
        // Origins on the circle of radius 0.3 around (0, 2, 0) in the y = 2 plane.
        let d = b.origin - glam::DVec3::new(0.0, 2.0, 0.0);
        assert!((d.length() - 0.3).abs() < 1e-12 && d.y.abs() < 1e-12, "{:?}", b.origin);
        assert!((b.direction.length() - 1.0).abs() < 1e-12);
    }
}

#[test]
fn plugin_light_round_trips_through_json_and_bincode() {
    let set: Box<dyn LightSource> = serde_json::from_str(SCENE_LIGHTS).unwrap();
    let json = serde_json::to_string(&set).unwrap();
    assert!(json.contains(r#""type":"RingLight""#), "{json}");
    let again: Box<dyn LightSource> = serde_json::from_str(&json).unwrap();
    let config = bincode::config::standard();
    let bytes = bincode::serde::encode_to_vec(&set, config).unwrap();
    let (binary, _): (Box<dyn LightSource>, usize) =
        bincode::serde::decode_from_slice(&bytes, config).unwrap();
    let reference = first_beams(set.as_ref());
    assert_eq!(first_beams(again.as_ref()), reference);
    assert_eq!(first_beams(binary.as_ref()), reference);
}

#[test]
fn unknown_light_types_are_named_in_the_error() {
    let e =
        serde_json::from_str::<LightSet>(r#"{"lights": [{"type": "CandleLight", "power": 1}]}"#)
            .unwrap_err();
    assert!(e.to_string().contains("CandleLight"), "{e}");
}
