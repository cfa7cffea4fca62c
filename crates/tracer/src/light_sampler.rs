//! Which light a connection goes to: the [`LightSampler`] interface and its power-proportional
//! implementation, [`PowerLightSampler`].
//!
//! Every estimator that picks a light (the path tracer's next-event estimation, BDPT's `s = 1`
//! strategy and the MIS weights that must know the probability of that pick) asks one sampler,
//! so the probability a strategy used and the one its MIS weight assumes are the same number.
//! A lookup is `O(log n)` to sample (binary search of a cumulative table) and `O(1)` for the
//! probability of a given light (an index from light to entry), so a scene of thousands of
//! lights does not cost a scan per vertex. Choosing by power alone ignores where the receiver
//! is.
//!
//! BDPT also chooses lights *given the sample's wavelength*, `pmf(l | lambda) = pmf(l)
//! spd_l(lambda) / p(lambda)`, so that both ends of a path agree on the density of a light
//! vertex ([`PowerLightSampler::sample_given`]). Where every light shares one spectrum (one
//! light, or lights whose spectrum is the same object: the renderer gives lights with equal
//! spectra one object) that is the power choice itself, `O(log n)` per lookup; otherwise it
//! weighs each distinct spectrum at `lambda`, then chooses by power among that spectrum's
//! lights: `O(spectra + log n)`.
//!
//! Next-event estimation's choice among many lights by where they are is the light tree's
//! (`light_tree`), which implements a choice for a receiving point rather than this trait.

use std::sync::Arc;

use spectrace_lights::{LightId, LightSet, LightSource};
use spectrace_sampling::Discrete;
use spectrace_spectrum::SpectralPowerDistribution;

/// A light chosen by a [`LightSampler`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SampledLight {
    /// The light of the set.
    pub id: LightId,
    /// The probability it was chosen with.
    pub pmf: f64,
    /// The uniform that chose it, remapped to `[0, 1)` for reuse (a point on the light).
    pub u: f64,
}

/// Chooses lights for connections, with the probability of each choice.
pub trait LightSampler: Send + Sync + std::fmt::Debug {
    /// Chooses a light from the uniform `u`; `None` when there is nothing to choose.
    fn sample(&self, u: f64) -> Option<SampledLight>;

    /// The probability that [`sample`](Self::sample) chooses light `id` (0 for a light it never
    /// chooses).
    fn pmf(&self, id: LightId) -> f64;
}

/// Lights chosen in proportion to their power, among those a filter admits.
#[derive(Debug, Clone, Default)]
pub struct PowerLightSampler {
    /// The cumulative table over the admitted lights; `None` when none has power.
    choice: Option<Discrete>,
    /// The admitted lights, in table order.
    ids: Vec<LightId>,
    /// For each light of the set, its entry in the table.
    entry: Vec<Option<u32>>,
    /// Each admitted light's spectrum (for choices given a wavelength).
    spds: Vec<Arc<dyn SpectralPowerDistribution>>,
    /// The admitted lights grouped by spectrum object, in order of first appearance: a choice
    /// given a wavelength weighs each group's spectrum once.
    groups: Vec<SpectrumGroup>,
}

/// The admitted lights that share one spectrum object.
#[derive(Debug, Clone)]
struct SpectrumGroup {
    /// The shared spectrum.
    spd: Arc<dyn SpectralPowerDistribution>,
    /// The group's share of the power choice.
    share: f64,
    /// Its members (table entries), in table order.
    members: Vec<usize>,
    /// The choice among its members by power.
    choice: Discrete,
}

impl PowerLightSampler {
    /// A sampler over the lights of `lights` for which `admit` holds, by power.
    pub fn new(lights: &LightSet, admit: impl Fn(LightId, &dyn LightSource) -> bool) -> Self {
        let mut entry = vec![None; lights.lights().len()];
        let (mut ids, mut powers, mut spds) = (Vec::new(), Vec::new(), Vec::new());
        for (i, light) in lights.lights().iter().enumerate() {
            let power = light.power();
            let id = LightId(i as u32);
            if admit(id, light.as_ref()) && power > 0.0 && power.is_finite() {
                entry[i] = Some(ids.len() as u32);
                ids.push(id);
                powers.push(power);
                spds.push(light.spd());
            }
        }
        let choice = Discrete::new(&powers).ok();
        let groups = choice.as_ref().map_or_else(Vec::new, |c| spectrum_groups(&spds, &powers, c));
        Self { choice, ids, entry, spds, groups }
    }

    /// Whether no light can be chosen.
    pub fn is_empty(&self) -> bool {
        self.choice.is_none()
    }

    /// The table entry of light `id`.
    #[inline]
    fn index(&self, id: LightId) -> Option<usize> {
        self.entry.get(id.0 as usize).copied().flatten().map(|k| k as usize)
    }

    /// The probability of choosing light `id` given the wavelength `lambda` (nm):
    /// `pmf(l) spd_l(lambda) / density`, where `density = sum_k pmf(k) spd_k(lambda)` is the
    /// admitted lights' spectrum at `lambda`, which the caller has (for the whole set, the set's
    /// own SPD): `O(1)`.
    pub fn pmf_given(&self, id: LightId, lambda: f64, density: f64) -> f64 {
        let (Some(choice), Some(k)) = (&self.choice, self.index(id)) else { return 0.0 };
        if self.groups.len() == 1 {
            return choice.pmf(k);
        }
        if density > 0.0 && density.is_finite() {
            choice.pmf(k) * self.spds.get(k).map_or(0.0, |s| s.value(lambda)) / density
        } else {
            0.0
        }
    }

    /// Chooses a light with probability [`pmf_given`](Self::pmf_given) from `u`: `O(1)` where
    /// the lights share one spectrum; otherwise a scan of the distinct spectra at `lambda`,
    /// then a choice by power within the chosen spectrum's lights.
    pub fn sample_given(&self, u: f64, lambda: f64) -> Option<SampledLight> {
        if self.groups.len() == 1 {
            return self.sample(u);
        }
        let weight = |g: &SpectrumGroup| g.share * g.spd.value(lambda);
        let total: f64 = self.groups.iter().map(weight).sum();
        if !(total > 0.0 && total.is_finite()) {
            return None;
        }
        let target = u * total;
        let (mut below, mut last) = (0.0, None);
        for g in &self.groups {
            let w = weight(g);
            if w > 0.0 {
                last = Some((g, below, w));
                if target < below + w {
                    break;
                }
                below += w;
            }
        }
        let (g, below, w) = last?;
        let remapped = ((target - below) / w).clamp(0.0, spectrace_sampling::ONE_MINUS_EPSILON);
        let (m, u) = g.choice.sample_remapped(remapped);
        let k = *g.members.get(m)?;
        Some(SampledLight { id: self.ids[k], pmf: w / total * g.choice.pmf(m), u })
    }
}

/// The admitted lights grouped by spectrum object (`Arc` identity), in order of first
/// appearance, each with its share of `choice` and a choice by power among its members.
fn spectrum_groups(
    spds: &[Arc<dyn SpectralPowerDistribution>],
    powers: &[f64],
    choice: &Discrete,
) -> Vec<SpectrumGroup> {
    let mut index: std::collections::HashMap<*const (), usize> = std::collections::HashMap::new();
    let mut members: Vec<Vec<usize>> = Vec::new();
    for (k, spd) in spds.iter().enumerate() {
        let key = Arc::as_ptr(spd) as *const ();
        let g = *index.entry(key).or_insert_with(|| {
            members.push(Vec::new());
            members.len() - 1
        });
        members[g].push(k);
    }
    members
        .into_iter()
        .filter_map(|m| {
            let p: Vec<f64> = m.iter().map(|&k| powers[k]).collect();
            Some(SpectrumGroup {
                spd: spds[*m.first()?].clone(),
                share: m.iter().map(|&k| choice.pmf(k)).sum(),
                choice: Discrete::new(&p).ok()?,
                members: m,
            })
        })
        .collect()
}

impl LightSampler for PowerLightSampler {
    #[inline]
    fn sample(&self, u: f64) -> Option<SampledLight> {
        let choice = self.choice.as_ref()?;
        let (k, remapped) = choice.sample_remapped(u);
        Some(SampledLight { id: *self.ids.get(k)?, pmf: choice.pmf(k), u: remapped })
    }

    #[inline]
    fn pmf(&self, id: LightId) -> f64 {
        match (&self.choice, self.index(id)) {
            (Some(choice), Some(k)) => choice.pmf(k),
            _ => 0.0,
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    #![allow(clippy::unwrap_used)]

    use super::*;

    /// A light set from a JSON list of lights (the light samplers' tests share it).
    pub(crate) fn set(json: &str) -> LightSet {
        let lights: Vec<Box<dyn LightSource>> = serde_json::from_str(json).unwrap();
        LightSet::new(lights).unwrap()
    }

    const THREE: &str = r#"[
      {"type": "PointLight", "position": [0, 0, 0], "power": 1,
       "spd": {"type": "Uniform", "min_nm": 400, "max_nm": 500}},
      {"type": "PointLight", "position": [1, 0, 0], "power": 3,
       "spd": {"type": "Uniform", "min_nm": 450, "max_nm": 700}},
      {"type": "PointLight", "position": [2, 0, 0], "power": 0.5,
       "spd": {"type": "Uniform", "min_nm": 400, "max_nm": 700}}
    ]"#;

    #[test]
    fn power_choice_frequencies_match_the_pmf_and_the_pmf_sums_to_one() {
        let lights = set(THREE);
        let sampler = PowerLightSampler::new(&lights, |_, _| true);
        let total: f64 = (0..3).map(|i| sampler.pmf(LightId(i))).sum();
        assert!((total - 1.0).abs() < 1e-12);
        assert!((sampler.pmf(LightId(1)) - 3.0 / 4.5).abs() < 1e-12);
        // 9000 stratified uniforms: each light's count is its pmf to within one stratum.
        let mut counts = [0u32; 3];
        for i in 0..9000 {
            let s = sampler.sample((f64::from(i) + 0.5) / 9000.0).unwrap();
            assert!((0.0..1.0).contains(&s.u));
            assert_eq!(s.pmf, sampler.pmf(s.id));
            counts[s.id.0 as usize] += 1;
        }
        for (i, &c) in counts.iter().enumerate() {
            let expected = 9000.0 * sampler.pmf(LightId(i as u32));
            assert!((f64::from(c) - expected).abs() <= 1.0, "light {i}: {c} vs {expected}");
        }
    }

    #[test]
    fn the_filter_leaves_lights_out_with_pmf_zero() {
        let lights = set(THREE);
        let sampler = PowerLightSampler::new(&lights, |_, l| l.power() > 2.0);
        assert_eq!(sampler.pmf(LightId(0)), 0.0);
        assert_eq!(sampler.pmf(LightId(2)), 0.0);
        assert_eq!(sampler.pmf(LightId(1)), 1.0);
        assert_eq!(sampler.sample(0.3).unwrap().id, LightId(1));
        assert!(PowerLightSampler::new(&lights, |_, _| false).sample(0.5).is_none());
        assert_eq!(PowerLightSampler::new(&lights, |_, _| false).pmf(LightId(7)), 0.0);
    }

    #[test]
    fn the_choice_given_a_wavelength_weighs_each_spectrum() {
        let lights = set(THREE);
        let sampler = PowerLightSampler::new(&lights, |_, _| true);
        // At 420 nm only lights 0 (1 W over 100 nm) and 2 (0.5 W over 300 nm) emit.
        let (w0, w2) = (1.0 / 100.0, 0.5 / 300.0);
        let expected = [w0 / (w0 + w2), 0.0, w2 / (w0 + w2)];
        // The set's own spectrum is the mixture sum_k pmf(k) spd_k: the density `pmf_given` takes.
        let density = LightSource::spd(&lights).value(420.0);
        assert!((density - (w0 + w2) / 4.5).abs() < 1e-15);
        for (i, e) in expected.iter().enumerate() {
            let pmf = sampler.pmf_given(LightId(i as u32), 420.0, density);
            assert!((pmf - e).abs() < 1e-12, "light {i}");
        }
        let mut counts = [0u32; 3];
        for i in 0..7000 {
            let s = sampler.sample_given((f64::from(i) + 0.5) / 7000.0, 420.0).unwrap();
            assert!((s.pmf - sampler.pmf_given(s.id, 420.0, density)).abs() < 1e-12);
            assert!((0.0..1.0).contains(&s.u));
            counts[s.id.0 as usize] += 1;
        }
        for (i, e) in expected.iter().enumerate() {
            assert!((f64::from(counts[i]) - 7000.0 * e).abs() <= 1.0, "light {i}");
        }
        // Where no light emits there is nothing to choose.
        assert!(sampler.sample_given(0.5, 800.0).is_none());
        assert_eq!(
            sampler.pmf_given(LightId(1), 800.0, LightSource::spd(&lights).value(800.0)),
            0.0
        );
    }

    #[test]
    fn lights_sharing_a_spectrum_are_weighed_once_and_chosen_by_power_among_them() {
        use spectrace_lights::{PointLight, WavelengthSampling};
        use spectrace_spectrum::Uniform;
        let blue: Arc<dyn SpectralPowerDistribution> =
            Arc::new(Uniform::new(400.0, 500.0).unwrap());
        let wide: Arc<dyn SpectralPowerDistribution> =
            Arc::new(Uniform::new(400.0, 700.0).unwrap());
        let light = |x: f64, power: f64, spd: &Arc<dyn SpectralPowerDistribution>| {
            let p = PointLight::new(
                glam::DVec3::new(x, 0.0, 0.0),
                power,
                spd.clone(),
                WavelengthSampling::Importance,
            );
            Box::new(p.unwrap()) as Box<dyn LightSource>
        };
        let lights = LightSet::new(vec![
            light(0.0, 1.0, &blue),
            light(1.0, 2.0, &wide),
            light(2.0, 3.0, &blue),
            light(3.0, 4.0, &wide),
        ])
        .unwrap();
        let sampler = PowerLightSampler::new(&lights, |_, _| true);
        assert_eq!(sampler.groups.len(), 2);
        let density = LightSource::spd(&lights).value(450.0);
        // pmf(l) spd_l(450) / density, with spd = 1/100 (blue) or 1/300 (wide) per nm.
        let w = [1.0 / 100.0, 2.0 / 300.0, 3.0 / 100.0, 4.0 / 300.0];
        let total: f64 = w.iter().sum();
        let n = 10_000;
        let mut counts = [0u32; 4];
        for k in 0..n {
            let s = sampler.sample_given((f64::from(k) + 0.5) / f64::from(n), 450.0).unwrap();
            assert!((s.pmf - sampler.pmf_given(s.id, 450.0, density)).abs() < 1e-12);
            counts[s.id.0 as usize] += 1;
        }
        for (i, w) in w.iter().enumerate() {
            let pmf = sampler.pmf_given(LightId(i as u32), 450.0, density);
            assert!((pmf - w / total).abs() < 1e-12, "light {i}");
            // Two levels of stratification (the spectrum, then the light): within two strata.
            assert!((f64::from(counts[i]) - f64::from(n) * pmf).abs() <= 2.0, "light {i}");
        }
        // Beyond 500 nm only the wide lights emit, by power among them.
        let s = sampler.sample_given(0.1, 600.0).unwrap();
        assert_eq!(s.id, LightId(1));
        assert!((s.pmf - 2.0 / 6.0).abs() < 1e-12);
    }
}
