//! Which light a connection goes to: the [`LightSampler`] interface and its power-proportional
//! implementation, [`PowerLightSampler`].
//!
//! Every estimator that picks a light (the path tracer's next-event estimation, BDPT's `s = 1`
//! strategy and the MIS weights that must know the probability of that pick) asks one sampler,
//! so the probability a strategy used and the one its MIS weight assumes are the same number.
//! A lookup is `O(log n)` to sample (binary search of a cumulative table) and `O(1)` for the
//! probability of a given light (an index from light to entry), so a scene of thousands of
//! lights does not cost a scan per vertex. Choosing by power alone ignores where the receiver
//! is; a spatial sampler (a light tree) would implement the same trait.
//!
//! BDPT also chooses lights *given the sample's wavelength*, `pmf(l | lambda) = pmf(l)
//! spd_l(lambda) / p(lambda)`, so that both ends of a path agree on the density of a light
//! vertex ([`PowerLightSampler::sample_given`]). Where every light shares one spectrum (one
//! light, or lights whose spectrum is the same object) that is the power choice itself, `O(1)`
//! per lookup; otherwise it weighs each light's spectrum at `lambda`, `O(n)`.

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
    /// Whether all admitted lights share one spectrum object, so that the choice given a
    /// wavelength is the power choice.
    shared_spectrum: bool,
}

impl PowerLightSampler {
    /// A sampler over the lights of `lights` for which `admit` holds, by power.
    pub fn new(lights: &LightSet, admit: impl Fn(&dyn LightSource) -> bool) -> Self {
        let mut entry = vec![None; lights.lights().len()];
        let (mut ids, mut powers, mut spds) = (Vec::new(), Vec::new(), Vec::new());
        for (i, light) in lights.lights().iter().enumerate() {
            let power = light.power();
            if admit(light.as_ref()) && power > 0.0 && power.is_finite() {
                entry[i] = Some(ids.len() as u32);
                ids.push(LightId(i as u32));
                powers.push(power);
                spds.push(light.spd());
            }
        }
        let shared_spectrum = spds.windows(2).all(|w| Arc::ptr_eq(&w[0], &w[1]));
        let choice = Discrete::new(&powers).ok();
        Self { choice, ids, entry, spds, shared_spectrum }
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

    /// The weight of table entry `k` given `lambda`: its power probability times its spectrum.
    #[inline]
    fn weight_given(&self, choice: &Discrete, k: usize, lambda: f64) -> f64 {
        choice.pmf(k) * self.spds.get(k).map_or(0.0, |s| s.value(lambda))
    }

    /// The probability of choosing light `id` given the wavelength `lambda` (nm):
    /// `pmf(l) spd_l(lambda) / density`, where `density = sum_k pmf(k) spd_k(lambda)` is the
    /// admitted lights' spectrum at `lambda`, which the caller has (for the whole set, the set's
    /// own SPD): `O(1)`.
    pub fn pmf_given(&self, id: LightId, lambda: f64, density: f64) -> f64 {
        let (Some(choice), Some(k)) = (&self.choice, self.index(id)) else { return 0.0 };
        if self.shared_spectrum {
            return choice.pmf(k);
        }
        if density > 0.0 && density.is_finite() {
            self.weight_given(choice, k, lambda) / density
        } else {
            0.0
        }
    }

    /// Chooses a light with probability [`pmf_given`](Self::pmf_given) from `u`: `O(1)` where
    /// the lights share one spectrum, a scan of the lights' spectra at `lambda` otherwise.
    pub fn sample_given(&self, u: f64, lambda: f64) -> Option<SampledLight> {
        let choice = self.choice.as_ref()?;
        if self.shared_spectrum {
            return self.sample(u);
        }
        let n = self.ids.len();
        let total: f64 = (0..n).map(|i| self.weight_given(choice, i, lambda)).sum();
        if !(total > 0.0 && total.is_finite()) {
            return None;
        }
        let target = u * total;
        let (mut below, mut last) = (0.0, None);
        for k in 0..n {
            let w = self.weight_given(choice, k, lambda);
            if w > 0.0 {
                last = Some((k, below, w));
                if target < below + w {
                    break;
                }
                below += w;
            }
        }
        let (k, below, w) = last?;
        let remapped = ((target - below) / w).clamp(0.0, spectrace_sampling::ONE_MINUS_EPSILON);
        Some(SampledLight { id: self.ids[k], pmf: w / total, u: remapped })
    }
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
mod tests {
    #![allow(clippy::unwrap_used)]

    use super::*;

    fn set(json: &str) -> LightSet {
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
        let sampler = PowerLightSampler::new(&lights, |_| true);
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
        let sampler = PowerLightSampler::new(&lights, |l| l.power() > 2.0);
        assert_eq!(sampler.pmf(LightId(0)), 0.0);
        assert_eq!(sampler.pmf(LightId(2)), 0.0);
        assert_eq!(sampler.pmf(LightId(1)), 1.0);
        assert_eq!(sampler.sample(0.3).unwrap().id, LightId(1));
        assert!(PowerLightSampler::new(&lights, |_| false).sample(0.5).is_none());
        assert_eq!(PowerLightSampler::new(&lights, |_| false).pmf(LightId(7)), 0.0);
    }

    #[test]
    fn the_choice_given_a_wavelength_weighs_each_spectrum() {
        let lights = set(THREE);
        let sampler = PowerLightSampler::new(&lights, |_| true);
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
}
