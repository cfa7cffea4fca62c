//! [`LightSet`]: the seed's LightSourceManager ("master light source", seed 3.3).
//!
//! ```json
//! {"type": "LightSet", "lights": [
//!   {"type": "PointLight", "position": [0, 2, 0], "power": 60, "spd": {"type": "Blackbody", "kelvin": 2700}},
//!   {"type": "Laser", "position": [0, 1, 0], "direction": [1, 0, 0], "power": 0.005,
//!    "spd": {"type": "Monochromatic", "lambda_nm": 532}}
//! ]}
//! ```

use std::sync::Arc;

use glam::DVec3;
use rand::Rng;
use serde::{Deserialize, Serialize};
use spectrace_sampling::{Discrete, clamp_uniform};
use spectrace_spectrum::{Component, Mixture, SpectralPowerDistribution};

use crate::source::uniform;
use crate::{Beam, BeamCounter, LightError, LightFlags, LightId, LightSample, LightSource};

/// A set of lights that is itself a light: each beam comes from a light chosen with probability
/// proportional to its power, and carries that light's index as its `parent`. Sets inside sets are
/// flattened when the set is built (their lights take their places in order), so `parent` always
/// names a plain light.
///
/// Its power is the sum of the lights' powers and its SPD their power-weighted mixture. The
/// lights keep their own beam counts, so a beam's power can be computed from its parent
/// (`lights()[parent].power() / lights()[parent].number_of_beams() * scale`) or, equivalently in
/// expectation, from the set (`power() / number_of_beams() * scale`).
///
/// Estimators that connect to lights (next-event estimation, bidirectional methods) choose a
/// light with a light sampler (the renderer's is `spectrace_tracer::PowerLightSampler`, the same
/// power choice as [`pmf`](Self::pmf)) and ask that light, [`light(id)`](Self::light), for its
/// densities; [`sample_light`](Self::sample_light) is the set's own choice, which its
/// [`sample_towards`](LightSource::sample_towards) uses. The set itself keeps the trait's defaults for
/// the per-light methods (`emission_density`, `pdf_towards` and `emitted_radiance` 0,
/// `sample_emission`, `pdf_emission` and `surface` `None`), since its lights differ in kind.
/// Only [`sample_towards`](LightSource::sample_towards) is offered on the set, choosing the light
/// by power.
#[derive(Debug, Deserialize)]
#[serde(try_from = "LightSetRepr")]
pub struct LightSet {
    lights: Vec<Box<dyn LightSource>>,
    choice: Discrete,
    spd: Arc<dyn SpectralPowerDistribution>,
    power: f64,
    counter: BeamCounter,
}

/// Scene-file form of [`LightSet`].
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LightSetRepr {
    lights: Vec<Box<dyn LightSource>>,
}

impl TryFrom<LightSetRepr> for LightSet {
    type Error = LightError;
    fn try_from(r: LightSetRepr) -> Result<Self, LightError> {
        Self::new(r.lights)
    }
}

impl Serialize for LightSet {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        let mut s = serializer.serialize_struct("LightSet", 1)?;
        s.serialize_field("lights", &self.lights)?;
        s.end()
    }
}

impl LightSet {
    /// A set of lights.
    ///
    /// # Errors
    /// [`LightError::EmptySet`] when there are no lights, when every light has zero power, or
    /// when a power is not finite or the total overflows.
    pub fn new(lights: Vec<Box<dyn LightSource>>) -> Result<Self, LightError> {
        // Nested sets are flattened: a beam's parent is then always a plain light, whose
        // spectrum and emission describe that beam.
        let mut flat: Vec<Box<dyn LightSource>> = Vec::with_capacity(lights.len());
        let mut pending = lights;
        pending.reverse();
        while let Some(mut light) = pending.pop() {
            match light.take_lights() {
                Some(mut children) => {
                    children.reverse();
                    pending.extend(children);
                }
                None => flat.push(light),
            }
        }
        let lights = flat;
        if lights.is_empty() {
            return Err(LightError::EmptySet { reason: "a light set needs at least one light" });
        }
        let powers: Vec<f64> = lights.iter().map(|l| l.power()).collect();
        let choice = Discrete::new(&powers).map_err(|_| LightError::EmptySet {
            reason: "the lights' powers must be finite, >= 0, not all zero, with a finite total",
        })?;
        let power = choice.total();
        let components = lights
            .iter()
            .zip(&powers)
            .map(|(l, &weight)| Component { weight, spd: l.spd() })
            .collect();
        let spd = Arc::new(
            Mixture::new(components)
                .map_err(|source| LightError::Spectrum { light: "LightSet", source })?,
        );
        Ok(Self { lights, choice, spd, power, counter: BeamCounter::new() })
    }

    /// Calls `f` on every light in `parent` order (for experiment hooks such as
    /// [`LightSource::set_wavelength_sampling`]), then rebuilds the set's spectrum and light
    /// choice from the lights as they are now. The lights keep their order, so every
    /// [`LightId`] still names the same light.
    ///
    /// # Errors
    /// As [`LightSet::new`] (a light whose power `f` made invalid); the set is then empty.
    pub fn modify_lights(
        &mut self,
        f: &mut dyn FnMut(LightId, &mut dyn LightSource),
    ) -> Result<(), LightError> {
        for (i, light) in self.lights.iter_mut().enumerate() {
            f(LightId(i as u32), light.as_mut());
        }
        *self = Self::new(std::mem::take(&mut self.lights))?;
        Ok(())
    }

    /// The lights, in `parent` order.
    pub fn lights(&self) -> &[Box<dyn LightSource>] {
        &self.lights
    }

    /// The light a beam came from.
    pub fn light(&self, id: LightId) -> Option<&dyn LightSource> {
        self.lights.get(id.0 as usize).map(|l| l.as_ref())
    }

    /// The set's own choice of a light (for its [`sample_towards`](LightSource::sample_towards)):
    /// chooses a light with probability
    /// proportional to its power from a uniform `u`, and returns it with its probability mass
    /// ([`pmf`](Self::pmf)) and `u` remapped to a fresh uniform in `[0, 1)` for the light's own
    /// use. A `u` outside `[0, 1)` or NaN is clamped into it.
    pub fn sample_light(&self, u: f64) -> (LightId, f64, f64) {
        let (i, remapped) = self.choice.sample_remapped(clamp_uniform(u));
        (LightId(i as u32), self.choice.pmf(i), remapped)
    }

    /// Probability mass with which [`sample_light`](Self::sample_light) (and beam emission)
    /// chooses light `id`: its share of the total power.
    pub fn pmf(&self, id: LightId) -> f64 {
        self.choice.pmf(id.0 as usize)
    }

    /// Probability that a beam comes from light `id`: its share of the total power.
    pub fn probability(&self, id: LightId) -> f64 {
        self.choice.pmf(id.0 as usize)
    }
}

#[typetag::serde]
impl LightSource for LightSet {
    fn next_beam(&self, rng: &mut dyn Rng) -> Beam {
        let i = self.choice.sample(uniform(rng));
        let mut beam = self.lights[i].next_beam(rng);
        beam.parent = LightId(i as u32);
        self.counter.increment();
        beam
    }
    /// The light chosen from `rng` as in `next_beam`, its beam's wavelength from `u_lambda`.
    fn next_beam_at(&self, u_lambda: f64, rng: &mut dyn Rng) -> Beam {
        let i = self.choice.sample(uniform(rng));
        let mut beam = self.lights[i].next_beam_at(u_lambda, rng);
        beam.parent = LightId(i as u32);
        self.counter.increment();
        beam
    }
    fn number_of_beams(&self) -> u64 {
        self.counter.total()
    }
    fn power(&self) -> f64 {
        self.power
    }
    fn spd(&self) -> Arc<dyn SpectralPowerDistribution> {
        self.spd.clone()
    }
    fn reset_count(&self) {
        self.counter.reset();
        for l in &self.lights {
            l.reset_count();
        }
    }
    fn flags(&self) -> Option<LightFlags> {
        // The set is a delta in a dimension only if every light is.
        let all: Option<Vec<LightFlags>> = self.lights.iter().map(|l| l.flags()).collect();
        all.map(|f| LightFlags {
            delta_position: f.iter().all(|x| x.delta_position),
            delta_direction: f.iter().all(|x| x.delta_direction),
        })
    }
    fn uniform_spectrum(&self) -> bool {
        // Several lights colour their beams by their own spectra, not by the set's mixture.
        self.lights.len() == 1 && self.lights[0].uniform_spectrum()
    }
    fn take_lights(&mut self) -> Option<Vec<Box<dyn LightSource>>> {
        Some(std::mem::take(&mut self.lights))
    }
    fn origin_weight(&self, beam: &Beam) -> f64 {
        // The beam's own light knows how it weighed it.
        self.lights.get(beam.parent.0 as usize).map_or(beam.scale, |l| l.origin_weight(beam))
    }
    fn emission_density(&self, _origin: DVec3, _direction: DVec3) -> f64 {
        // A set's beams come from different lights: ask the beam's own light (its `parent`).
        0.0
    }
    fn sample_towards(&self, receiver: DVec3, u: [f64; 2]) -> Option<LightSample> {
        // Choose a light by power with the first uniform, remapped to drive the light's own choice.
        let (i, remapped) = self.choice.sample_remapped(clamp_uniform(u[0]));
        let p = self.choice.pmf(i);
        let mut s = self.lights[i].sample_towards(receiver, [remapped, u[1]])?;
        s.intensity /= p;
        s.pdf *= p;
        Some(s)
    }
}
