//! Light sources as beam generators: the heart of Spectrace (seed section 2).
//!
//! Every light implements one small trait, [`LightSource`]: give me the next [`Beam`] (origin,
//! unit direction, a wavelength drawn from the light's normalised spectral power distribution, a
//! weight `scale`, the light it came from) and tell me how many beams you made. A beam's power is
//! `light.power() / light.number_of_beams() * beam.scale`. The renderer accepts any light type by
//! serialisation: the trait is typetag-serialisable, so scene files name a light by its type and a
//! crate that depends on `spectrace-lights` alone can add a new light type (see the README).
//!
//! This crate sits on `spectrace-spectrum` (every light owns an SPD) and `spectrace-sampling`
//! (exact generators for wavelengths and angular profiles), and under the tracer, which draws
//! beams from a [`LightSet`]. It re-exports both lower crates and `glam`, so a third-party light
//! needs no other Spectrace dependency.
//!
//! | light | what it emits |
//! |---|---|
//! | [`Laser`] | one direction from a point or a disk of `beam_radius` |
//! | [`Sky`] | parallel beams from a rectangle (the seed's "array of lasers") |
//! | [`UniformSpotLight`] | uniform intensity inside a cone |
//! | [`FadingSpotLight`] | the seed's fading spot, intensity per solid angle fading to 0 at the cone |
//! | [`PointLight`] | isotropic |
//! | [`RectangleLight`], [`DiskLight`] | Lambertian area lights, one- or two-sided |
//! | [`IesLight`], [`EulumdatLight`] | measured luminaires: intensity from an IES LM-63 or EULUMDAT candela table |
//! | [`LightSet`] | the seed's LightSourceManager: picks a light by power, itself a light |
//!
//! Beyond beams, every built-in light answers what path tracing and bidirectional methods ask of
//! it ([`LightSource::sample_towards`], [`LightSource::pdf_towards`],
//! [`LightSource::emitted_radiance`], [`LightSource::sample_emission`] with the same distribution
//! as `next_beam`, [`LightSource::pdf_emission`], [`LightSource::surface`] for area lights, and
//! [`LightSource::flags`] for which densities are deltas, [`LightSource::light_bounds`] for a
//! light tree's [`LightBounds`]); a [`LightSet`] chooses a light by
//! power ([`LightSet::sample_light`]) and defers to it. The crate README tabulates what each light returns.
//!
//! The key design decisions: [`SpdLight`] (the seed's `spdLightSource`) gives every built-in light
//! its spectrum, power, wavelength sampling (importance, or the seed's equal wavelengths with
//! weights) and its [`BeamCounter`], which counts per thread and sums, so counting never
//! serialises threads. Lights are validated when built and when deserialised: a bad parameter is a
//! [`LightError`] naming the light and the field, never a panic.

mod area;
mod beam;
mod bounds;
mod counter;
mod error;
mod geometry;
mod glare;
mod laser;
pub mod photometry;
mod set;
mod sky;
mod source;
mod spot;

pub use area::{DiskLight, RectangleLight};
pub use beam::{Beam, LightId};
pub use bounds::{LightBounds, PreparedBounds};
pub use counter::BeamCounter;
pub use error::LightError;
pub use glare::{GlareView, LuminousOpening};
pub use laser::Laser;
pub use photometry::{EulumdatLight, IesLight, LuminaireLumens};
pub use set::LightSet;
pub use sky::Sky;
pub use source::{
    EmissionSample, LightFlags, LightSample, LightSource, LightSurface, SpdLight, SpdMap,
    WavelengthSampling, power_from_keys,
};
pub use spot::{FadingSpotLight, PointLight, UniformSpotLight};

/// Vectors (`DVec3`) as used in [`Beam`], re-exported so plugins need no direct dependency.
pub use glam;
/// The exact generators, re-exported for plugins.
pub use spectrace_sampling as sampling;
/// Spectra, re-exported for plugins.
pub use spectrace_spectrum as spectrum;

/// Draws a uniform in `[0, 1)` from any generator (53 random bits), as the built-in lights do.
pub fn uniform(rng: &mut dyn rand::Rng) -> f64 {
    source::uniform(rng)
}
