//! [`Fluorescent`]: a bispectral diffuse surface that absorbs light at one wavelength and
//! re-emits part of it at longer ones (fluorescence), over a Lambertian base for the light it
//! does not absorb.
//!
//! | field | unit | default | meaning |
//! |---|---|---|---|
//! | `reflectance` | fraction in `[0, 1]`, a number or `{"nm": [...], "values": [...]}` | required | the base albedo `R(lambda)` of the light that is *not* absorbed |
//! | `absorption` | `{"nm": [...], "values": [...]}`, fractions in `[0, 1]` | required | `a(lambda)`: the fraction of arriving power absorbed by the fluorescent dye; linear between points, **zero outside the table** |
//! | `emission` | an SPD, as a light's `spd` (e.g. `{"type": "Tabulated", ...}`, `{"type": "Gaussian", ...}`) | required | `e(lambda)`: the spectrum of the re-emitted light, normalised to integral 1 and sampled by its inverse CDF; it must have a density (no line spectra) |
//! | `quantum_yield` | fraction in `[0, 1]` | required | `Y`: the fraction of the absorbed power that is re-emitted |
//!
//! ```json
//! {"type": "Fluorescent", "reflectance": 0.8,
//!  "absorption": {"nm": [340, 400, 460, 500], "values": [0.0, 0.9, 0.6, 0.0]},
//!  "emission": {"type": "Gaussian", "center_nm": 520, "fwhm_nm": 40},
//!  "quantum_yield": 0.9}
//! ```
//!
//! # The model
//! Light of wavelength `lambda_i` arriving at the surface is absorbed with probability
//! `a(lambda_i)`. What is not absorbed meets the base: a Lambertian reflection with albedo
//! `(1 - a(lambda_i)) R(lambda_i)`, the *elastic* part, which is what this material's
//! [`Material::scatter`], [`Material::eval`] and [`Material::pdf`] describe. Of the absorbed
//! power the fraction `Y` is re-emitted, diffusely (a Lambertian lobe on the side the light came
//! from), with the spectrum `e`. In power, the re-radiation kernel is separable:
//!
//! `f_fl(lambda_i -> lambda_o, wi, wo) = Y a(lambda_i) e(lambda_o) / pi` (sr^-1 nm^-1),
//!
//! so a beam of power `P` at `lambda_i` leaves `P Y a(lambda_i)` of re-emitted power spread over
//! `e`, and never more than `P`: `(1 - a) R + Y a <= 1` at every wavelength. `Y` is applied to
//! power (an energy yield): a measured photon quantum yield `Phi` corresponds to
//! `Y = Phi lambda_i / lambda_o` for the mean wavelengths, which folds the Stokes shift in.
//!
//! # How integrators use it
//! [`Material::fluorescence`] returns the material, and an integrator decides at each
//! fluorescent vertex, *before* connecting or scattering, between the elastic branch and
//! re-emission, with [`Fluorescent::choose_forward`] (paths from lights: importance/flux, the
//! new wavelength drawn from `e`) or [`Fluorescent::choose_adjoint`] (paths from the camera:
//! radiance, the wavelength the light had before, drawn from `a`). Both use the separability:
//! a whole bundle of wavelengths re-emits at *one* new wavelength, so the bundle collapses to it
//! exactly, with no wavelength chosen among the bundle. After re-emission the vertex scatters
//! with [`reemission_lobe`] (a white Lambertian lobe), after the elastic choice with the
//! material itself.

use std::f64::consts::FRAC_1_PI;
use std::sync::LazyLock;

use glam::DVec3;
use serde::{Deserialize, Serialize};
use spectrace_sampling::{PiecewiseLinear, clamp_uniform};
use spectrace_spectrum::{Reflectance, SpectralPowerDistribution};

use crate::{BundleScattered, Diffuse, Incoming, Material, MaterialError, Scattered, Transport};

/// A fluorescent diffuse surface: absorption, re-emission spectrum, yield, base reflectance.
#[derive(Debug, Deserialize)]
#[serde(try_from = "FluorescentRepr")]
pub struct Fluorescent {
    reflectance: Reflectance,
    absorption: PiecewiseLinear,
    emission: Box<dyn SpectralPowerDistribution>,
    quantum_yield: f64,
}

/// Scene-file form of [`Fluorescent`].
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct FluorescentRepr {
    reflectance: Reflectance,
    absorption: AbsorptionRepr,
    emission: Box<dyn SpectralPowerDistribution>,
    quantum_yield: f64,
}

/// `{"nm": [...], "values": [...]}` for the absorption.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct AbsorptionRepr {
    nm: Vec<f64>,
    values: Vec<f64>,
}

impl TryFrom<FluorescentRepr> for Fluorescent {
    type Error = MaterialError;
    fn try_from(r: FluorescentRepr) -> Result<Self, MaterialError> {
        Self::new(
            r.reflectance,
            &r.absorption.nm,
            &r.absorption.values,
            r.emission,
            r.quantum_yield,
        )
    }
}

impl Serialize for Fluorescent {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        let mut st = serializer.serialize_struct("Fluorescent", 4)?;
        st.serialize_field("reflectance", &self.reflectance)?;
        st.serialize_field(
            "absorption",
            &AbsorptionRepr {
                nm: self.absorption.xs().to_vec(),
                values: self.absorption.ys().to_vec(),
            },
        )?;
        st.serialize_field("emission", &self.emission)?;
        st.serialize_field("quantum_yield", &self.quantum_yield)?;
        st.end()
    }
}

/// How a camera path draws the wavelength light had before it was re-emitted
/// ([`Fluorescent::choose_adjoint`]): by default with density `a / A`; guided by the spectrum of
/// the light that reaches the scene, with the mixture `q = (a / A + a s / B) / 2` (`s` the
/// lights' spectrum, `B = integral a s`), which puts the samples where something both absorbs
/// and is lit, and keeps a density wherever anything absorbs (light re-emitted by another
/// fluorescent surface can arrive at wavelengths no light emits).
#[derive(Debug, Clone)]
pub struct ExcitationSampler {
    /// `a s` tabulated at 1 nm over the absorption's range; `None` when it is zero everywhere.
    guided: Option<PiecewiseLinear>,
}

/// What [`Fluorescent::choose_forward`] and [`Fluorescent::choose_adjoint`] decided.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Reemission {
    /// The elastic branch: the weights were divided by its probability; scatter with the
    /// material itself.
    Elastic,
    /// Re-emission: the bundle now travels at `lambda` (nm); scatter with [`reemission_lobe`].
    Reemitted {
        /// The new wavelength the path travels at beyond this vertex.
        lambda: f64,
    },
    /// Nothing is reflected or re-emitted at any live wavelength.
    Absorbed,
}

/// The white Lambertian lobe (`f = 1 / pi`, cosine-sampled, two-sided) a path scatters with
/// after re-emission: the directional part of the re-radiation kernel.
pub fn reemission_lobe() -> &'static dyn Material {
    static LOBE: LazyLock<Diffuse> = LazyLock::new(|| Diffuse::new(Reflectance::white()));
    &*LOBE
}

impl Fluorescent {
    /// A fluorescent surface with base `reflectance`, absorption table (`nm`, `values` in
    /// `[0, 1]`, zero outside `[nm[0], nm[last]]`), re-emission spectrum `emission` and yield.
    ///
    /// # Errors
    /// [`MaterialError::Parameter`] naming `Fluorescent.absorption.values[i]` (outside
    /// `[0, 1]`), `Fluorescent.absorption` (not a valid table, or zero everywhere),
    /// `Fluorescent.emission` (a line spectrum or zero density) or `Fluorescent.quantum_yield`
    /// (outside `[0, 1]`).
    pub fn new(
        reflectance: Reflectance,
        nm: &[f64],
        values: &[f64],
        emission: Box<dyn SpectralPowerDistribution>,
        quantum_yield: f64,
    ) -> Result<Self, MaterialError> {
        for (i, &v) in values.iter().enumerate() {
            if !(0.0..=1.0).contains(&v) {
                return Err(MaterialError::parameter(
                    "Fluorescent",
                    format!("absorption.values[{i}]"),
                    v,
                    "an absorbed fraction must be in [0, 1]",
                ));
            }
        }
        if let Some((i, &l)) = nm.iter().enumerate().find(|(_, l)| !(**l > 0.0)) {
            return Err(MaterialError::parameter(
                "Fluorescent",
                format!("absorption.nm[{i}]"),
                l,
                "wavelengths must be positive (nm)",
            ));
        }
        let absorption = PiecewiseLinear::new(nm, values).map_err(|e| {
            MaterialError::parameter(
                "Fluorescent",
                "absorption",
                format!("{{nm: {} points, values: {} points}}", nm.len(), values.len()),
                format!("{e} (a table of increasing nm with some absorption is required)"),
            )
        })?;
        if emission.is_delta() {
            return Err(MaterialError::parameter(
                "Fluorescent",
                "emission",
                "a line spectrum",
                "the re-emission spectrum must have a density (camera paths look it up per \
                 wavelength); use a narrow Gaussian or a table instead of a line",
            ));
        }
        let (lo, hi) = emission.range();
        let mass = emission.integrate(&|_| 1.0);
        if !(lo < hi && mass > 0.5 && mass.is_finite()) {
            return Err(MaterialError::parameter(
                "Fluorescent",
                "emission",
                format!("range [{lo}, {hi}] nm, integral {mass}"),
                "the re-emission spectrum must be a normalised density over a wavelength range",
            ));
        }
        if !(0.0..=1.0).contains(&quantum_yield) {
            return Err(MaterialError::parameter(
                "Fluorescent",
                "quantum_yield",
                quantum_yield,
                "the fraction of absorbed power re-emitted must be in [0, 1]",
            ));
        }
        Ok(Self { reflectance, absorption, emission, quantum_yield })
    }

    /// `a(lambda)`: the absorbed fraction at `lambda` (nm), 0 outside the table.
    pub fn absorbed(&self, lambda: f64) -> f64 {
        (self.absorption.pdf(lambda) * self.absorption.integral()).clamp(0.0, 1.0)
    }

    /// `A = integral a(lambda) d lambda` (nm): the absorption's total.
    pub fn absorption_integral(&self) -> f64 {
        self.absorption.integral()
    }

    /// The quantum (power) yield `Y`.
    pub fn quantum_yield(&self) -> f64 {
        self.quantum_yield
    }

    /// The base reflectance `R`.
    pub fn reflectance(&self) -> &Reflectance {
        &self.reflectance
    }

    /// The re-emission spectrum `e` (normalised, nm^-1).
    pub fn emission(&self) -> &dyn SpectralPowerDistribution {
        self.emission.as_ref()
    }

    /// The elastic albedo `(1 - a(lambda)) R(lambda)`.
    pub fn elastic_albedo(&self, lambda: f64) -> f64 {
        (1.0 - self.absorbed(lambda)) * self.reflectance.value(lambda)
    }

    /// The re-emitted fraction of power arriving at `lambda_i`: `Y a(lambda_i)`.
    pub fn reemitted(&self, lambda_i: f64) -> f64 {
        self.quantum_yield * self.absorbed(lambda_i)
    }

    /// The re-radiation kernel in power, `Y a(lambda_i) e(lambda_o)` (nm^-1), without the
    /// Lambertian `1 / pi`.
    pub fn kernel(&self, lambda_i: f64, lambda_o: f64) -> f64 {
        self.reemitted(lambda_i) * self.emission.value(lambda_o)
    }

    /// The adjoint albedo at `lambda_o`: `integral kernel(lambda_i, lambda_o) d lambda_i
    /// = Y e(lambda_o) A`, what a camera path at `lambda_o` gains through re-emission.
    pub fn adjoint_reemitted(&self, lambda_o: f64) -> f64 {
        self.quantum_yield * self.emission.value(lambda_o) * self.absorption.integral()
    }

    /// A re-emitted wavelength, drawn from `e` by its inverse CDF.
    pub fn sample_emission(&self, u: f64) -> f64 {
        self.emission.sample_lambda(clamp_uniform(u))
    }

    /// An absorbed wavelength, drawn with density `a(lambda) / A` by the inverse CDF of the
    /// absorption table.
    pub fn sample_excitation(&self, u: f64) -> f64 {
        self.absorption.sample(clamp_uniform(u))
    }

    /// Density of [`sample_excitation`](Self::sample_excitation), `a(lambda) / A` (nm^-1).
    pub fn excitation_pdf(&self, lambda: f64) -> f64 {
        self.absorption.pdf(lambda)
    }

    /// An [`ExcitationSampler`] guided by `light(lambda)`, the spectral density of the light
    /// that reaches the scene (any positive scale; e.g. the light set's SPD): `a light` is
    /// tabulated at 1 nm steps over the absorption table's range (at most 2048 steps).
    pub fn excitation_sampler(&self, light: &dyn Fn(f64) -> f64) -> ExcitationSampler {
        let (lo, hi) = self.absorption.range();
        let steps = ((hi - lo).ceil() as usize).clamp(1, 2048);
        let xs: Vec<f64> = (0..=steps).map(|i| lo + (hi - lo) * i as f64 / steps as f64).collect();
        let ys: Vec<f64> = xs
            .iter()
            .map(|&l| {
                let v = self.absorbed(l) * light(l);
                if v.is_finite() && v > 0.0 { v } else { 0.0 }
            })
            .collect();
        ExcitationSampler { guided: PiecewiseLinear::new(&xs, &ys).ok() }
    }

    /// A wavelength drawn by `sampler` (`None`: the density `a / A`) from one uniform, and its
    /// density (nm^-1).
    pub fn sample_excitation_with(
        &self,
        sampler: Option<&ExcitationSampler>,
        u: f64,
    ) -> (f64, f64) {
        let u = clamp_uniform(u);
        let Some(guided) = sampler.and_then(|s| s.guided.as_ref()) else {
            let lambda = self.absorption.sample(u);
            return (lambda, self.absorption.pdf(lambda));
        };
        let lambda = if u < 0.5 {
            self.absorption.sample(2.0 * u)
        } else {
            guided.sample((2.0 * u - 1.0).min(spectrace_sampling::ONE_MINUS_EPSILON))
        };
        (lambda, 0.5 * (self.absorption.pdf(lambda) + guided.pdf(lambda)))
    }

    /// The branch at a fluorescent vertex on a path from a light (flux), for a bundle of
    /// wavelengths `lambdas` with weights `weights` (live where `> 0`): re-emission with
    /// probability `p = sum w Y a / sum w (Y a + (1 - a) R)`, chosen by `u_choice`.
    ///
    /// * Re-emission: the bundle collapses to one wavelength `lambda_o` drawn from `e` with
    ///   `u_lambda`: `lambdas[0] = lambda_o`, `weights[0] = sum w Y a / p`, every other weight 0.
    /// * Elastic: every live weight is divided by `1 - p`; the caller scatters with the material
    ///   (whose albedo is `(1 - a) R`).
    pub fn choose_forward(
        &self,
        lambdas: &mut [f64],
        weights: &mut [f64],
        u_choice: f64,
        u_lambda: f64,
    ) -> Reemission {
        let (mut reemit, mut elastic) = (0.0, 0.0);
        for (&w, &l) in weights.iter().zip(lambdas.iter()) {
            if w > 0.0 {
                reemit += w * self.reemitted(l);
                elastic += w * self.elastic_albedo(l);
            }
        }
        let Some(p) = reemission_probability(reemit, elastic, u_choice, weights) else {
            return Reemission::Elastic;
        };
        if !(p > 0.0) {
            return Reemission::Absorbed;
        }
        let lambda = self.sample_emission(u_lambda);
        weights.fill(0.0);
        if let (Some(w), Some(l)) = (weights.first_mut(), lambdas.first_mut()) {
            *w = reemit / p;
            *l = lambda;
        }
        Reemission::Reemitted { lambda }
    }

    /// The branch at a fluorescent vertex on a path from the camera (radiance, the adjoint of
    /// [`choose_forward`](Self::choose_forward)): re-emission with probability
    /// `p = sum w Y e A / sum w (Y e A + (1 - a) R)` over the live wavelengths (`e` at each
    /// one's `lambda_o`).
    ///
    /// * Re-emission: one excitation wavelength `lambda_i` is drawn by `sampler` (density `q`;
    ///   `None`: `q = a / A`) with `u_lambda`, and *every* live wavelength continues at it (the
    ///   kernel is separable, so the source wavelength is the same for all):
    ///   `lambdas[j] = lambda_i`, and each weight is multiplied by
    ///   `Y e(lambda_o_j) a(lambda_i) / (q(lambda_i) p)` (`Y e A / p` for the default). The
    ///   caller keeps the wavelengths the path's values are recorded at (its film wavelengths)
    ///   separately.
    /// * Elastic: every live weight is divided by `1 - p`.
    pub fn choose_adjoint(
        &self,
        lambdas: &mut [f64],
        weights: &mut [f64],
        u_choice: f64,
        u_lambda: f64,
        sampler: Option<&ExcitationSampler>,
    ) -> Reemission {
        let (mut reemit, mut elastic) = (0.0, 0.0);
        for (&w, &l) in weights.iter().zip(lambdas.iter()) {
            if w > 0.0 {
                reemit += w * self.adjoint_reemitted(l);
                elastic += w * self.elastic_albedo(l);
            }
        }
        let Some(p) = reemission_probability(reemit, elastic, u_choice, weights) else {
            return Reemission::Elastic;
        };
        if !(p > 0.0) {
            return Reemission::Absorbed;
        }
        let (lambda, q) = self.sample_excitation_with(sampler, u_lambda);
        // The kernel over the density of lambda_i: Y e(lambda_o) a(lambda_i) / q(lambda_i),
        // which for the default q = a / A is Y e(lambda_o) A exactly.
        let per_emission = match sampler {
            Some(_) => self.quantum_yield * self.absorbed(lambda) / q,
            None => self.quantum_yield * self.absorption.integral(),
        };
        if !(q > 0.0 && per_emission.is_finite()) {
            weights.fill(0.0);
            return Reemission::Absorbed;
        }
        for (w, l) in weights.iter_mut().zip(lambdas.iter_mut()) {
            if *w > 0.0 {
                *w *= per_emission * self.emission.value(*l) / p;
                *l = lambda;
            }
        }
        Reemission::Reemitted { lambda }
    }
}

/// The shared choice of [`Fluorescent::choose_forward`] and [`Fluorescent::choose_adjoint`]:
/// `Some(p)` to re-emit, with `p = reemit / (reemit + elastic)` its probability (0 when
/// nothing leaves at all: absorbed); `None` for the elastic branch, after dividing the live
/// weights by `1 - p`.
fn reemission_probability(
    reemit: f64,
    elastic: f64,
    u_choice: f64,
    weights: &mut [f64],
) -> Option<f64> {
    let total = reemit + elastic;
    if !(total > 0.0 && total.is_finite()) {
        return Some(0.0);
    }
    let p = reemit / total;
    if clamp_uniform(u_choice) < p {
        return Some(p);
    }
    let keep = 1.0 - p;
    for w in weights.iter_mut() {
        if *w > 0.0 {
            *w /= keep;
        }
    }
    None
}

#[typetag::serde]
impl Material for Fluorescent {
    /// The elastic part: a Lambertian reflection with albedo `(1 - a) R`.
    fn scatter(&self, incoming: &Incoming, u: [f64; 3]) -> Option<Scattered> {
        let albedo = self.elastic_albedo(incoming.lambda);
        if !(albedo > 0.0) {
            return None;
        }
        let mut s = reemission_lobe().scatter(incoming, u)?;
        s.weight = albedo;
        Some(s)
    }

    fn scatter_bundle(
        &self,
        direction: DVec3,
        normal: DVec3,
        lambdas: &[f64],
        weights: &mut [f64],
        u: [f64; 3],
        transport: Transport,
    ) -> Option<BundleScattered> {
        if !crate::scale_bundle(lambdas, weights, |l| self.elastic_albedo(l)) {
            return None;
        }
        let mut ones = [1.0];
        reemission_lobe().scatter_bundle(direction, normal, &[lambdas[0]], &mut ones, u, transport)
    }

    fn eval(&self, wi: DVec3, wo: DVec3, normal: DVec3, lambda: f64) -> f64 {
        if wi.dot(normal) * wo.dot(normal) > 0.0 {
            self.elastic_albedo(lambda) * FRAC_1_PI
        } else {
            0.0
        }
    }

    fn pdf(&self, wi: DVec3, wo: DVec3, normal: DVec3, lambda: f64) -> f64 {
        reemission_lobe().pdf(wi, wo, normal, lambda)
    }

    fn is_specular(&self) -> bool {
        false
    }

    fn is_dispersive(&self) -> bool {
        false
    }

    fn fluorescence(&self) -> Option<&Fluorescent> {
        Some(self)
    }
}
