//! The [`LightSource`] trait (seed section 2), the records its optional methods return, and
//! [`SpdLight`], the seed's `spdLightSource` that every built-in light builds on.

use std::fmt::Debug;
use std::sync::Arc;

use glam::DVec3;
use rand::Rng;
use serde::{Deserialize, Serialize};
use spectrace_sampling::PiecewiseConstant;
use spectrace_spectrum::{SpectralPowerDistribution, cmf, integrate_panels, luminous_efficacy};

use crate::photometry::LuminaireLumens;
use crate::{Beam, BeamCounter, GlareView, LightBounds, LightError};

/// A light source as a beam generator (seed section 2).
///
/// A light gives out beams ([`next_beam`](Self::next_beam)) and counts them
/// ([`number_of_beams`](Self::number_of_beams)); a beam's power is
/// `power() / number_of_beams() * beam.scale`. Counting must be exact and cheap from many threads
/// at once ([`BeamCounter`] does that for the built-in lights).
///
/// The trait is typetag-serialisable: a scene file names any light by its type,
/// `{"type": "Laser", ...}`, and a crate that depends on `spectrace-lights` alone can add a light
/// type that the renderer then accepts from scene files (see the crate README).
///
/// Methods that bidirectional rendering needs (sampling the light towards a point, emission
/// densities, delta flags) are *default methods*: a light that implements only the seed's four
/// methods keeps working with the light tracer, and [`LightSource::sample_towards`] /
/// [`LightSource::flags`] report that it offers nothing more.
#[typetag::serde(tag = "type")]
pub trait LightSource: Send + Sync + Debug {
    /// Emits the next beam: origin, unit direction, a wavelength from the light's SPD, a weight,
    /// `level` 0. Counts it.
    fn next_beam(&self, rng: &mut dyn Rng) -> Beam;

    /// Emits the next beam as [`next_beam`](Self::next_beam) does, its wavelength drawn from
    /// the uniform `u_lambda` in `[0, 1)` by the same map as
    /// [`sample_wavelength`](Self::sample_wavelength) (and used for nothing else), its other
    /// draws from `rng`. A light tracer passes one `u_lambda` and draws the companions of the
    /// beam's wavelength bundle at `u_lambda + j / k` (mod 1), so that the bundle's `k`
    /// wavelengths are stratified together, as a camera path's hero wavelengths are. The
    /// default ignores `u_lambda` and calls `next_beam`: still unbiased (each wavelength keeps
    /// its density and the beam's path does not depend on `u_lambda`), only less stratified.
    /// Every light of this crate draws its wavelength first, so its `next_beam(rng)` is
    /// `next_beam_at(u, rng)` with `u` its first draw from `rng` (tested).
    fn next_beam_at(&self, u_lambda: f64, rng: &mut dyn Rng) -> Beam {
        let _ = u_lambda;
        self.next_beam(rng)
    }

    /// How many beams this light has emitted so far.
    fn number_of_beams(&self) -> u64;

    /// Total emitted power (W).
    fn power(&self) -> f64;

    /// The normalised spectral power distribution of the emitted light.
    fn spd(&self) -> Arc<dyn SpectralPowerDistribution>;

    /// Sets the beam count back to zero, before emitting for a new image. The default does
    /// nothing (for lights that do not count).
    fn reset_count(&self) {}

    /// What kind of light this is, for integrators that need to know (delta position or
    /// direction). `None` (the default) means the light does not say, and only the light tracer
    /// can use it.
    fn flags(&self) -> Option<LightFlags> {
        None
    }

    /// Solid-angle density (sr^-1) of the directions of the beams this light emits from
    /// `origin` (a beam's starting point) towards `direction` (unit): the radiant intensity
    /// of one beam's share of the power that way is `beam power * emission_density`. The light
    /// tracer uses it to connect emission points to the camera, so that lights seen directly
    /// appear in the image. The default, 0, means the light is never seen directly (right for
    /// parallel beams, whose direction is a delta).
    fn emission_density(&self, origin: DVec3, direction: DVec3) -> f64 {
        let _ = (origin, direction);
        0.0
    }

    /// Whether every beam's wavelength is drawn from [`spd`](Self::spd) whatever its origin
    /// and direction (true for every built-in light but a [`crate::LightSet`] of several
    /// lights). Renderers that let one path carry several wavelengths drawn from `spd()` rely
    /// on it; a light whose colour varies over its surface or with direction must return `false`.
    fn uniform_spectrum(&self) -> bool {
        true
    }

    /// Draws one more wavelength (nm) for a path that carries one of this light's beams (a
    /// companion of a light tracer's wavelength bundle) from a uniform `u` in `[0, 1)`, with its
    /// weight `spd(lambda) / q(lambda)` for the density `q` it was drawn from (the beam's own
    /// `scale` plays that part for the beam's wavelength). The default draws from
    /// [`spd`](Self::spd), weight 1; built-in lights with `wavelength_sampling: "observer"`
    /// draw from SPD x observer, as their beams do.
    fn sample_wavelength(&self, u: f64) -> (f64, f64) {
        (self.spd().sample_lambda(u), 1.0)
    }

    /// Experiment hook (the accuracy report's wavelength-strategy knob): switches how the light
    /// draws its beams' wavelengths, keeping its SPD and power. The default returns
    /// [`LightError::Unsupported`], so light types from other crates keep compiling; the
    /// built-in lights implement it through [`SpdLight::set_sampling`].
    ///
    /// # Errors
    /// [`LightError::Unsupported`] by default; as [`SpdLight::new`] otherwise (equal wavelengths
    /// for an SPD with delta lines).
    fn set_wavelength_sampling(&mut self, sampling: WavelengthSampling) -> Result<(), LightError> {
        let _ = sampling;
        Err(LightError::Unsupported { field: "wavelength_sampling" })
    }

    /// Experiment hook (the accuracy report's SPD-sampler knob): replaces the light's SPD by
    /// `f(spd)` where `f` returns one, keeping the power and wavelength sampling; `Ok(true)` if it
    /// was replaced, `Ok(false)` if `f` returned `None`. The default returns
    /// [`LightError::Unsupported`].
    ///
    /// # Errors
    /// [`LightError::Unsupported`] by default; as [`SpdLight::new`] for the new SPD.
    fn map_spd(&mut self, f: &SpdMap<'_>) -> Result<bool, LightError> {
        let _ = f;
        Err(LightError::Unsupported { field: "spd" })
    }

    /// For a group of lights (a [`crate::LightSet`]): hands over its lights, leaving it empty.
    /// [`crate::LightSet::new`] uses it to flatten nested sets, so that every beam's `parent` is
    /// a plain light. Plain lights return `None` (the default).
    fn take_lights(&mut self) -> Option<Vec<Box<dyn LightSource>>> {
        None
    }

    /// Samples the light as seen from `receiver` (for connecting a surface point to the light):
    /// a point on the light, the direction from it towards the receiver, the radiant intensity
    /// that way, and the density of the choice. `None` (the default) when the light cannot be
    /// sampled this way (a light that implements only the seed's methods, a laser of zero
    /// width) or sends no light to the receiver. Lights with a delta direction (skies, lasers
    /// of finite width) return the one beam through the receiver, as a delta sample: renderers
    /// count such a light as reachable from camera paths when it returns a sample for a point
    /// on one of its own beams (see [`sample_emission`](Self::sample_emission)).
    fn sample_towards(&self, receiver: DVec3, u: [f64; 2]) -> Option<LightSample> {
        let _ = (receiver, u);
        None
    }

    /// Solid-angle density (sr^-1, at `receiver`) with which
    /// [`sample_towards`](Self::sample_towards)`(receiver, u)` returns the point `position` of
    /// the light, for multiple importance sampling when a path from `receiver` hits the light by
    /// itself. 0 for delta lights and by default.
    fn pdf_towards(&self, receiver: DVec3, position: DVec3) -> f64 {
        let _ = (receiver, position);
        0.0
    }

    /// How the spectrum leaving `position` along the unit `direction` departs from
    /// [`spd`](Self::spd) at `lambda` (nm): the spectral radiance (or intensity) there is the
    /// whole-spectrum value ([`emitted_radiance`](Self::emitted_radiance),
    /// [`LightSample::intensity`]) times `spd().value(lambda)` times this factor. 1 (the default)
    /// for every light with [`uniform_spectrum`](Self::uniform_spectrum); a light whose colour
    /// varies with direction or over its surface returns its ratio (its mean over wavelengths
    /// drawn from `spd` is 1).
    fn spectral_factor(&self, position: DVec3, direction: DVec3, lambda: f64) -> f64 {
        let _ = (position, direction, lambda);
        1.0
    }

    /// [`spectral_factor`](Self::spectral_factor) at each of `lambdas`, into `out` (as many
    /// as the shorter of the two). The default asks one wavelength at a time; a light whose
    /// factor shares work between wavelengths (finding where a direction falls in a map)
    /// overrides it.
    fn spectral_factors(
        &self,
        position: DVec3,
        direction: DVec3,
        lambdas: &[f64],
        out: &mut [f64],
    ) {
        for (o, &l) in out.iter_mut().zip(lambdas) {
            *o = self.spectral_factor(position, direction, l);
        }
    }

    /// The part of `beam.scale` that weighs the beam's origin alone, for connections from the
    /// origin in other directions than the beam's own (a light tracer's or BDPT's connection to
    /// the camera, which multiply it by [`emission_density`](Self::emission_density) and
    /// [`spectral_factor`](Self::spectral_factor)). The default is the whole `scale`, right for
    /// every light whose beams' weights do not depend on the direction drawn. A light that draws
    /// directions from a density not proportional to its radiance (an environment map) weighs
    /// the direction in `scale` and returns the origin's weight here; its `emission_density` then
    /// gives the radiant intensity per unit of that weight. A value of 1 also says that the
    /// beam's wavelength was drawn from `spd`.
    fn origin_weight(&self, beam: &Beam) -> f64 {
        beam.scale
    }

    /// Radiance (W m^-2 sr^-1, whole spectrum: multiply by `spd().value(lambda)` for the
    /// spectral radiance) leaving the point `position` of the light's surface towards the unit
    /// `direction`: what a camera ray that hits an area light sees. 0 (the default) for lights
    /// without a surface, and on the back of a one-sided light.
    fn emitted_radiance(&self, position: DVec3, direction: DVec3) -> f64 {
        let _ = (position, direction);
        0.0
    }

    /// Samples an emission ray from four uniforms: a point of the light, its surface normal, a
    /// direction, and their densities (see [`EmissionSample`]), as the light's beams are
    /// distributed (a beam from [`next_beam`](Self::next_beam) and this sample have the same
    /// density). `None` (the default) for lights that offer only the seed's methods, and also
    /// for a draw of zero density (a grazing direction at the very rim of the uniforms' range),
    /// which the caller counts as no contribution. Uniforms outside `[0, 1)` or NaN are clamped.
    ///
    /// With it, `emitted_radiance * |cos(normal, direction)| / (pdf_position * pdf_direction)`
    /// is `power()` for every sample of an area light whose beams all weigh the same (each ray
    /// carries the whole power, as a beam does), and `power()` on average for one that weighs
    /// its beams' directions ([`origin_weight`](Self::origin_weight)); for delta lights the deltas stand as densities of 1 (see
    /// [`flags`](Self::flags)).
    fn sample_emission(&self, u: [f64; 4]) -> Option<EmissionSample> {
        let _ = u;
        None
    }

    /// The densities with which this light emits a beam from `position` along the unit
    /// `direction`: `(pdf_position, pdf_direction)` as in [`EmissionSample`]. `position` is taken
    /// to be a point the light emits from (it is not checked). A delta stands as a density of 1
    /// where the direction is the light's own (lasers, sky) and 0 elsewhere; the caller knows
    /// from [`flags`](Self::flags) which densities are deltas. `None` (the default) when the
    /// light does not say (only the light tracer can use it).
    fn pdf_emission(&self, position: DVec3, direction: DVec3) -> Option<(f64, f64)> {
        let _ = (position, direction);
        None
    }

    /// The unit normal of the light's surface at `position` (a point of it, such as a beam's
    /// origin), on the front side; `None` (the default) for lights without a surface. BDPT
    /// needs it to turn densities at the light into area densities.
    fn normal_at(&self, position: DVec3) -> Option<DVec3> {
        let _ = position;
        None
    }

    /// What the light did to read its input that its user should be told: a lamp set chosen
    /// among several, a file read as Windows-1252. Empty by default; renderers print these as
    /// warnings when the scene is loaded.
    fn notes(&self) -> Vec<String> {
        Vec::new()
    }

    /// The light's emitting surface, so a renderer can make it part of the scene: visible to
    /// camera rays (with [`emitted_radiance`](Self::emitted_radiance)) and blocking light. `None`
    /// (the default) for lights without one (points, parallel beams).
    fn surface(&self) -> Option<LightSurface> {
        None
    }

    /// For a measured luminaire: the flux of its candela table against its lamps' rated flux
    /// and its light output ratio (see [`LuminaireLumens`] for the definitions), for a
    /// renderer to print and record. `None` (the default) for lights that are not measured
    /// luminaires; [`crate::IesLight`] and [`crate::EulumdatLight`] return theirs.
    fn photometric_summary(&self) -> Option<LuminaireLumens> {
        None
    }

    /// What an eye at `eye` sees of the light, for a glare rating (CIE 117-1995's `L` and
    /// `omega`, see [`GlareView`]): the luminance and solid angle of its luminous parts. `None`
    /// (the default) for lights that do not say, for the eye at the light, for luminous parts
    /// of no projected area that way (a point source has no luminance; a flat opening seen
    /// edge-on or from its dark side shows none), or when nothing finite results.
    /// [`crate::IesLight`] and [`crate::EulumdatLight`] answer from the luminous opening of
    /// their file ([`crate::LuminousOpening`]).
    fn glare_view(&self, eye: DVec3) -> Option<GlareView> {
        let _ = eye;
        None
    }

    /// Where the light emits, which way and how strongly ([`LightBounds`]), for a light tree
    /// that chooses among many lights by their importance to a receiving point. `None` (the
    /// default) for lights without finite bounds (skies, environments) or that do not say: a
    /// tree chooses those by power beside it, so every light stays reachable.
    fn light_bounds(&self) -> Option<LightBounds> {
        None
    }
}

/// An emission ray drawn by [`LightSource::sample_emission`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EmissionSample {
    /// Where the ray starts.
    pub position: DVec3,
    /// The unit surface normal there (on the emitting side; for a two-sided light, on the side
    /// the ray leaves), or zero for a light without a surface (points, spots, a laser of radius
    /// 0). A sky gives its rectangle's normal on the side the beams leave, a laser of finite
    /// radius its direction (the disk its beams start from faces it).
    pub normal: DVec3,
    /// Unit direction of the ray.
    pub direction: DVec3,
    /// Area density of `position` (m^-2); 1 for a delta position.
    pub pdf_position: f64,
    /// Solid-angle density of `direction` given `position` (sr^-1); 1 for a delta direction.
    pub pdf_direction: f64,
}

/// The emitting surface of an area light (see [`LightSource::surface`]).
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum LightSurface {
    /// The parallelogram `corner + s edge_u + t edge_v`, `s, t` in `[0, 1]`; its front is
    /// `edge_u x edge_v`.
    Rectangle {
        /// A corner.
        corner: DVec3,
        /// First edge.
        edge_u: DVec3,
        /// Second edge.
        edge_v: DVec3,
    },
    /// A disk; its front is `normal`.
    Disk {
        /// Centre.
        center: DVec3,
        /// Unit normal of the front.
        normal: DVec3,
        /// Radius (m).
        radius: f64,
    },
    /// A sphere emitting from its inside (an environment around the scene); its front faces
    /// the centre.
    Sphere {
        /// Centre.
        center: DVec3,
        /// Radius (m).
        radius: f64,
    },
}

/// Which dimensions of a light's emission are Dirac deltas.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct LightFlags {
    /// All beams start at one point (point and spot lights, lasers).
    pub delta_position: bool,
    /// All beams share one direction (lasers, sky).
    pub delta_direction: bool,
}

/// A sample of a light as seen from a receiving point (see [`LightSource::sample_towards`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightSample {
    /// The point on the light.
    pub position: DVec3,
    /// Unit direction from `position` towards the receiver.
    pub direction: DVec3,
    /// Distance from `position` to the receiver (m).
    pub distance: f64,
    /// Radiant intensity towards the receiver (W/sr, whole spectrum: multiply by
    /// `spd().value(lambda)` for W/sr/nm), already divided by the density of the sampled point
    /// for area lights (`L cos(theta_light) * area`), so that for every light
    /// `intensity * cos(theta_receiver) / distance^2` is an unbiased estimate of the irradiance
    /// the light gives the receiver.
    pub intensity: f64,
    /// Density of having chosen this sample, in solid angle at the receiver (for multiple
    /// importance sampling); 1 for a delta position.
    pub pdf: f64,
    /// `true` if the sample is a delta (point and spot lights, and the parallel beams of skies
    /// and lasers): no path hits it by itself, so it takes no multiple importance sampling.
    pub delta: bool,
}

/// How a light gives its beams their wavelengths (seed 2.2 and 2.2.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum WavelengthSampling {
    /// `lambda` drawn from the normalised SPD, `scale` 1 (seed 2.2). The default.
    #[default]
    Importance,
    /// `lambda` uniform over the SPD's range, `scale = value(lambda) * (max - min)` (seed 2.2.2):
    /// every wavelength equally often, weighted by the spectrum.
    EqualWavelengths,
    /// `lambda` drawn with density `q ∝ SPD x (xbar + ybar + zbar)` (the CIE 1931 observer's
    /// sensitivity), `scale = SPD(lambda) / q(lambda)`: wavelengths where the eye sees nothing
    /// are never drawn, which is unbiased for XYZ images since they add nothing to them (the
    /// light's power, and the normalisation of its beams, are unchanged: the expected `scale` is
    /// the fraction of the SPD inside 360-830 nm). `q` is tabulated when the light is built (a
    /// piecewise-constant density on the 1 nm grid of the colour matching functions and the SPD's
    /// breakpoints, each bin's value the bin's integral of the product), and the weight uses the
    /// table's own density, so it is exact. SPDs with delta lines, and SPDs with nothing inside
    /// 360-830 nm, keep `Importance` (their lines are drawn as lines).
    Observer,
}

impl WavelengthSampling {
    /// The name used in scene files.
    pub fn name(self) -> &'static str {
        match self {
            Self::Importance => "importance",
            Self::EqualWavelengths => "equal_wavelengths",
            Self::Observer => "observer",
        }
    }
}

/// The density `q ∝ SPD x (xbar + ybar + zbar)` of [`WavelengthSampling::Observer`], tabulated;
/// `None` for an SPD with delta lines or nothing inside the observer's range.
fn observer_table(spd: &dyn SpectralPowerDistribution) -> Option<PiecewiseConstant> {
    const OBSERVER_MIN: f64 = 360.0;
    const OBSERVER_MAX: f64 = 830.0;
    let (lo, hi) = spd.range();
    if !(hi > lo) || spd.is_delta() {
        return None;
    }
    let mass = integrate_panels(&|l| spd.value(l), lo, hi, &spd.breakpoints());
    if (mass - 1.0).abs() > 1e-6 {
        return None;
    }
    let (a, b) = (lo.max(OBSERVER_MIN), hi.min(OBSERVER_MAX));
    if !(b > a) {
        return None;
    }
    let mut edges: Vec<f64> = (OBSERVER_MIN as u32..=OBSERVER_MAX as u32)
        .map(f64::from)
        .chain(spd.breakpoints())
        .chain([a, b])
        .filter(|x| (a..=b).contains(x))
        .collect();
    edges.sort_by(f64::total_cmp);
    edges.dedup();
    let sensitivity = |l: f64| {
        let c = cmf(l);
        spd.value(l) * (c.x + c.y + c.z)
    };
    // Simpson's rule: exact where the SPD and the observer are both linear on the bin (then a
    // bin whose product is positive anywhere has a positive value).
    let values: Vec<f64> = edges
        .windows(2)
        .map(|e| {
            let m = 0.5 * (e[0] + e[1]);
            (sensitivity(e[0]) + 4.0 * sensitivity(m) + sensitivity(e[1])) / 6.0
        })
        .collect();
    PiecewiseConstant::new(&edges, &values).ok()
}

/// The seed's `spdLightSource`: an SPD, a power, how wavelengths are drawn, and the beam count.
/// Every built-in light embeds one.
#[derive(Debug, Clone)]
pub struct SpdLight {
    /// The light type, for errors.
    light: &'static str,
    spd: Arc<dyn SpectralPowerDistribution>,
    power: f64,
    sampling: WavelengthSampling,
    /// The tabulated density of [`WavelengthSampling::Observer`] (`None`: importance sampling).
    observer: Option<Arc<PiecewiseConstant>>,
    counter: BeamCounter,
}

impl SpdLight {
    /// An emitter of `power` watts with spectrum `spd`. `light` names the light type in errors.
    ///
    /// # Errors
    /// [`LightError::Parameter`] for a power that is negative, NaN or infinite;
    /// [`LightError::Spectrum`] when `EqualWavelengths` is asked of an SPD with delta lines (they
    /// have no density to weight by: use `Importance`).
    pub fn new(
        light: &'static str,
        spd: Arc<dyn SpectralPowerDistribution>,
        power: f64,
        sampling: WavelengthSampling,
    ) -> Result<Self, LightError> {
        if !(power >= 0.0 && power.is_finite()) {
            return Err(LightError::parameter(
                light,
                "power",
                power,
                "must be finite and >= 0 (watts)",
            ));
        }
        if sampling == WavelengthSampling::EqualWavelengths {
            let (lo, hi) = spd.range();
            if hi > lo {
                let density_mass = integrate_panels(&|l| spd.value(l), lo, hi, &spd.breakpoints());
                if (density_mass - 1.0).abs() > 1e-6 {
                    return Err(LightError::parameter(
                        light,
                        "wavelength_sampling",
                        "equal_wavelengths",
                        "needs an SPD without delta lines (its density integrates to less than 1); use \"importance\"",
                    ));
                }
            }
        }
        let observer = if sampling == WavelengthSampling::Observer {
            observer_table(spd.as_ref()).map(Arc::new)
        } else {
            None
        };
        Ok(Self { light, spd, power, sampling, observer, counter: BeamCounter::new() })
    }

    /// Draws a wavelength (nm) and the beam's `scale` from a uniform `u` in `[0, 1)`, according
    /// to the light's [`WavelengthSampling`]. A pure line spectrum always gives its line with
    /// scale 1.
    #[inline]
    pub fn wavelength(&self, u: f64) -> (f64, f64) {
        match self.sampling {
            WavelengthSampling::Importance => (self.spd.sample_lambda(u), 1.0),
            WavelengthSampling::Observer => self.companion_wavelength(u),
            WavelengthSampling::EqualWavelengths => {
                let (lo, hi) = self.spd.range();
                if hi > lo {
                    let lambda = (lo + u * (hi - lo)).min(hi);
                    (lambda, self.spd.value(lambda) * (hi - lo))
                } else {
                    (self.spd.sample_lambda(u), 1.0)
                }
            }
        }
    }

    /// A companion wavelength of a bundle (see [`LightSource::sample_wavelength`]): from the
    /// observer-weighted density for [`WavelengthSampling::Observer`] (where it applies), else
    /// from the SPD with weight 1.
    #[inline]
    pub fn companion_wavelength(&self, u: f64) -> (f64, f64) {
        match &self.observer {
            Some(q) => {
                let lambda = q.sample(spectrace_sampling::clamp_uniform(u));
                let density = q.pdf(lambda);
                let scale = if density > 0.0 { self.spd.value(lambda) / density } else { 0.0 };
                (lambda, scale)
            }
            None => (self.spd.sample_lambda(u), 1.0),
        }
    }

    /// Counts one emitted beam.
    #[inline]
    pub fn count(&self) {
        self.counter.increment();
    }

    /// Beams emitted so far.
    pub fn number_of_beams(&self) -> u64 {
        self.counter.total()
    }

    /// Sets the beam count to zero.
    pub fn reset_count(&self) {
        self.counter.reset();
    }

    /// Emitted power (W).
    pub fn power(&self) -> f64 {
        self.power
    }

    /// The spectrum.
    pub fn spd(&self) -> &Arc<dyn SpectralPowerDistribution> {
        &self.spd
    }

    /// How wavelengths are drawn.
    pub fn sampling(&self) -> WavelengthSampling {
        self.sampling
    }

    /// Switches how wavelengths are drawn (rebuilding the observer table), keeping the SPD and
    /// power; the beam count starts again at zero.
    ///
    /// # Errors
    /// As [`SpdLight::new`].
    pub fn set_sampling(&mut self, sampling: WavelengthSampling) -> Result<(), LightError> {
        *self = Self::new(self.light, self.spd.clone(), self.power, sampling)?;
        Ok(())
    }

    /// Replaces the SPD by `f(spd)` when `f` returns one (keeping the power and sampling);
    /// whether it did.
    ///
    /// # Errors
    /// As [`SpdLight::new`] for the new SPD.
    pub fn map_spd(&mut self, f: &SpdMap<'_>) -> Result<bool, LightError> {
        let Some(spd) = f(self.spd.as_ref()) else { return Ok(false) };
        *self = Self::new(self.light, spd, self.power, self.sampling)?;
        Ok(true)
    }
}

/// A function that maps an SPD to its replacement, or `None` to keep it (see
/// [`LightSource::map_spd`]).
pub type SpdMap<'a> =
    dyn Fn(&dyn SpectralPowerDistribution) -> Option<Arc<dyn SpectralPowerDistribution>> + 'a;

/// Draws a uniform in `[0, 1)` from a generator (53 random bits).
#[inline]
pub(crate) fn uniform(rng: &mut dyn Rng) -> f64 {
    spectrace_sampling::uniform(rng)
}

/// Implements the counting, power and spectrum methods of [`LightSource`] by delegating to an
/// [`SpdLight`] field, inside an `impl LightSource for ...` block:
///
/// ```text
/// #[typetag::serde]
/// impl LightSource for MyLight {
///     fn next_beam(&self, rng: &mut dyn rand::Rng) -> Beam { ... }
///     spectrace_lights::delegate_to_spd_light!(emission);
/// }
/// ```
#[macro_export]
macro_rules! delegate_to_spd_light {
    ($field:ident) => {
        fn number_of_beams(&self) -> u64 {
            self.$field.number_of_beams()
        }
        fn power(&self) -> f64 {
            self.$field.power()
        }
        fn spd(&self) -> ::std::sync::Arc<dyn $crate::spectrum::SpectralPowerDistribution> {
            self.$field.spd().clone()
        }
        fn reset_count(&self) {
            self.$field.reset_count();
        }
        fn sample_wavelength(&self, u: f64) -> (f64, f64) {
            self.$field.companion_wavelength(u)
        }
        fn set_wavelength_sampling(
            &mut self,
            sampling: $crate::WavelengthSampling,
        ) -> ::std::result::Result<(), $crate::LightError> {
            self.$field.set_sampling(sampling)
        }
        fn map_spd(
            &mut self,
            f: &$crate::SpdMap<'_>,
        ) -> ::std::result::Result<bool, $crate::LightError> {
            self.$field.map_spd(f)
        }
    };
}

/// The radiant power (W) of a light whose scene file gives its output in one of three units:
/// `power` (W, returned as is), `lumens` (luminous flux, lm: `W = lm / K`) or `candela` (peak
/// luminous intensity, cd = lm/sr, given with the solid angle `omega` (sr) that the light's
/// intensity profile integrates to, its peak being 1: `W = cd * omega / K`), where
/// `K = luminous_efficacy(spd)` (lm/W, `683 * integral of spd(lambda) ybar(lambda)`).
/// `takes_candela` says whether the light offers the `candela` key (for the error that lists the
/// keys); `light` names the light in errors.
///
/// # Errors
/// [`LightError::Parameter`] naming `power` when no key is given, the second key when more than
/// one is, the key itself when its value is negative, NaN or infinite, `lumens` / `candela` when
/// the spectrum has no visible light (`K = 0`: no power makes any lumens) or the power in watts
/// overflows.
pub fn power_from_keys(
    light: &'static str,
    power: Option<f64>,
    lumens: Option<f64>,
    candela: Option<(f64, f64)>,
    takes_candela: bool,
    spd: &dyn SpectralPowerDistribution,
) -> Result<f64, LightError> {
    let reject = |field: &'static str, value: f64, reason: &'static str| {
        Err(LightError::parameter(light, field, value, reason))
    };
    match (power, lumens, candela) {
        (None, None, None) => Err(LightError::Parameter {
            light,
            field: "power",
            value: "missing".to_owned(),
            reason: if takes_candela {
                "the light's output is missing: give exactly one of `power` (W), `lumens` (lm) or `candela` (cd)"
            } else {
                "the light's output is missing: give exactly one of `power` (W) or `lumens` (lm)"
            },
        }),
        (Some(_), Some(l), None) => reject(
            "lumens",
            l,
            if takes_candela {
                "`power` is given too: give exactly one of `power` (W), `lumens` (lm) or `candela` (cd)"
            } else {
                "`power` is given too: give exactly one of `power` (W) or `lumens` (lm)"
            },
        ),
        (Some(_), None, Some((c, _))) => reject(
            "candela",
            c,
            "`power` is given too: give exactly one of `power` (W), `lumens` (lm) or `candela` (cd)",
        ),
        (None, Some(_), Some((c, _))) => reject(
            "candela",
            c,
            "`lumens` is given too: give exactly one of `power` (W), `lumens` (lm) or `candela` (cd)",
        ),
        (Some(_), Some(_), Some((c, _))) => reject(
            "candela",
            c,
            "`power` and `lumens` are given too: give exactly one of `power` (W), `lumens` (lm) or `candela` (cd)",
        ),
        (Some(w), None, None) => {
            if w >= 0.0 && w.is_finite() {
                Ok(w)
            } else {
                reject("power", w, "must be finite and >= 0 (watts)")
            }
        }
        (None, Some(l), None) => {
            if !(l >= 0.0 && l.is_finite()) {
                return reject("lumens", l, "must be finite and >= 0 (lumens)");
            }
            watts_of_flux(light, "lumens", l, l, spd)
        }
        (None, None, Some((c, omega))) => {
            if !(c >= 0.0 && c.is_finite()) {
                return reject("candela", c, "must be finite and >= 0 (candela)");
            }
            if !(omega > 0.0 && omega <= 4.0 * std::f64::consts::PI) {
                return reject(
                    "candela",
                    c,
                    "the light's intensity profile has no solid angle to spread it over",
                );
            }
            watts_of_flux(light, "candela", c, c * omega, spd)
        }
    }
}

/// Watts carrying the luminous flux `lumens` with spectrum `spd` (`lumens / K`); errors name
/// `field` (whose value was `value`) for an invisible spectrum or an overflow.
fn watts_of_flux(
    light: &'static str,
    field: &'static str,
    value: f64,
    lumens: f64,
    spd: &dyn SpectralPowerDistribution,
) -> Result<f64, LightError> {
    let efficacy = luminous_efficacy(spd);
    if !(efficacy > 0.0) {
        return Err(LightError::parameter(
            light,
            field,
            value,
            "the spectrum has no visible light (luminous efficacy 0 lm/W: nothing inside 360-830 nm), so no power gives it; give `power` in watts",
        ));
    }
    let watts = lumens / efficacy;
    if watts.is_finite() {
        Ok(watts)
    } else {
        Err(LightError::parameter(
            light,
            field,
            value,
            "too large: the power in watts it needs overflows",
        ))
    }
}
