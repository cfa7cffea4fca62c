//! Spot lights: [`UniformSpotLight`] (uniform intensity inside a cone) and [`FadingSpotLight`]
//! (the seed's fading spot, section 2.4.3), plus [`PointLight`] (isotropic).
//!
//! Angles in scene files are in degrees, measured from `direction`.
//!
//! | light | field | unit | default | meaning |
//! |---|---|---|---|---|
//! | all | `position` | m | required | the point the light shines from |
//! | all | `power` | W | one of `power`, `lumens`, `candela` | total emitted power |
//! | all | `lumens` | lm | one of `power`, `lumens`, `candela` | total luminous flux instead: `power = lumens / K` |
//! | all | `candela` | cd | one of `power`, `lumens`, `candela` | peak luminous intensity instead (on the axis; a point light's everywhere): `power = candela * omega / K` |
//! | all | `spd` | SPD | required | spectrum |
//! | all | `wavelength_sampling` | | `"importance"` | `"importance"` or `"equal_wavelengths"` |
//! | spots | `direction` | | required | axis of the cone |
//! | spots | `cone_angle` | degrees | required | half-angle of the cone, in (0, 180) |
//! | fading | `fade_per_angle` | 1/degree | required | intensity lost per degree in the fading ring; > 0 and `1 / fade_per_angle <= cone_angle` |
//!
//! ```json
//! {"type": "UniformSpotLight", "position": [0, 2, 0], "direction": [0, -1, 0], "cone_angle": 30,
//!  "power": 100, "spd": {"type": "Blackbody", "kelvin": 3200}}
//! {"type": "FadingSpotLight", "position": [0, 2, 0], "direction": [0, -1, 0], "cone_angle": 30,
//!  "fade_per_angle": 0.1, "power": 100, "spd": {"type": "Blackbody", "kelvin": 3200}}
//! {"type": "PointLight", "position": [0, 2, 0], "power": 60, "spd": {"type": "CieIlluminant", "name": "A"}}
//! {"type": "PointLight", "position": [0, 2, 0], "lumens": 800, "spd": {"type": "CieIlluminant", "name": "A"}}
//! {"type": "UniformSpotLight", "position": [0, 2, 0], "direction": [0, -1, 0], "cone_angle": 20,
//!  "candela": 2000, "spd": {"type": "CieIlluminant", "name": "A"}}
//! ```
//!
//! # Photometric units
//! `K = luminous_efficacy(spd)` is the light's luminous efficacy, `683 * integral of spd(lambda)
//! ybar(lambda)` lm/W. `omega` is the solid angle the intensity profile (peak 1) integrates to,
//! so that the flux is `candela * omega`: `4 pi` for a point light, `2 pi (1 - cos cone_angle)` for
//! a uniform spot ([`UniformSpotLight::solid_angle_of`]), and for a fading spot the integral of its
//! profile that its beams are normalised by ([`FadingSpotLight::solid_angle_of`]), so that the
//! peak intensity of the built light is exactly `candela / K` W/sr. A spectrum with no visible
//! light cannot be given in lumens or candela (an error). Serialising a light writes `power` (W).
//!
//! # The fading profile
//! The fading spot's intensity per solid angle is 1 up to `fade_angle = cone_angle -
//! 1 / fade_per_angle` and then falls linearly to 0 at `cone_angle`:
//! `I(theta) = (cone_angle - theta) * fade_per_angle` there. (The seed writes the fading part as
//! `1 - (cone_angle - x) * fade_per_angle`, which rises towards the edge; its text and figure 4
//! describe the fade this implements.) Because `I` is a density per *solid angle*, the polar
//! angle is drawn with density proportional to `I(theta) sin(theta)` (DESIGN.md: the seed omits
//! the Jacobian and would over-weight the centre). That density is tabulated on 2048 segments with
//! a node at the fade angle and sampled exactly by [`PiecewiseLinear`]; the tabulated density
//! differs from `I(theta) sin(theta)` by less than 1e-6 of its peak (tested).

use std::f64::consts::{PI, TAU};
use std::sync::Arc;

use glam::DVec3;
use rand::Rng;
use serde::{Deserialize, Serialize};
use spectrace_sampling::{
    Frame, PiecewiseLinear, clamp_uniform, one_minus_cos, sample_uniform_cone,
    sample_uniform_sphere, spherical_direction_turn,
};
use spectrace_spectrum::SpectralPowerDistribution;

use crate::geometry::{finite_point, positive, unit_direction};
use crate::source::{power_from_keys, uniform};
use crate::{
    Beam, EmissionSample, LightBounds, LightError, LightFlags, LightSample, LightSource, SpdLight,
    WavelengthSampling,
};

/// Checks a cone half-angle in degrees: inside (0, 180).
fn cone(light: &'static str, cone_angle: f64) -> Result<f64, LightError> {
    if cone_angle > 0.0 && cone_angle < 180.0 {
        Ok(cone_angle)
    } else {
        Err(LightError::parameter(light, "cone_angle", cone_angle, "must lie in (0, 180) degrees"))
    }
}

/// A delta-position sample towards `receiver` with the given intensity function of the cosine to
/// the axis.
pub(crate) fn point_sample(
    position: DVec3,
    axis: DVec3,
    receiver: DVec3,
    intensity: impl Fn(f64) -> f64,
) -> Option<LightSample> {
    let to = receiver - position;
    let distance = to.length();
    if !(distance > 0.0 && distance.is_finite()) {
        return None;
    }
    let direction = to / distance;
    Some(LightSample {
        position,
        direction,
        distance,
        intensity: intensity(direction.dot(axis)),
        pdf: 1.0,
        delta: true,
    })
}

/// The emission ray of a light at the point `position` along `direction`, whose directions have
/// solid-angle density `pdf_direction` there; `None` when that density is 0 (a direction drawn
/// exactly on a fading spot's rim).
pub(crate) fn point_emission(
    position: DVec3,
    direction: DVec3,
    pdf_direction: f64,
) -> Option<EmissionSample> {
    (pdf_direction > 0.0).then_some(EmissionSample {
        position,
        normal: DVec3::ZERO,
        direction,
        pdf_position: 1.0,
        pdf_direction,
    })
}

// ---------------------------------------------------------------------------------------------

/// A point light emitting uniformly per solid angle inside a cone of half-angle `cone_angle`.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(try_from = "SpotRepr", into = "SpotRepr")]
pub struct UniformSpotLight {
    emission: SpdLight,
    position: DVec3,
    direction: DVec3,
    cone_angle: f64,
    /// `1 - cos(cone)`, computed as `2 sin^2(cone / 2)` (no cancellation for narrow cones).
    one_minus_cos: f64,
    frame: Frame,
}

/// Scene-file form of [`UniformSpotLight`].
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct SpotRepr {
    position: DVec3,
    direction: DVec3,
    cone_angle: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    power: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    lumens: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    candela: Option<f64>,
    spd: Arc<dyn SpectralPowerDistribution>,
    #[serde(default)]
    wavelength_sampling: WavelengthSampling,
}

impl TryFrom<SpotRepr> for UniformSpotLight {
    type Error = LightError;
    fn try_from(r: SpotRepr) -> Result<Self, LightError> {
        const L: &str = "UniformSpotLight";
        let candela = match r.candela {
            Some(c) => Some((c, Self::solid_angle_of(cone(L, r.cone_angle)?))),
            None => None,
        };
        let power = power_from_keys(L, r.power, r.lumens, candela, true, r.spd.as_ref())?;
        Self::new(r.position, r.direction, r.cone_angle, power, r.spd, r.wavelength_sampling)
    }
}

impl From<UniformSpotLight> for SpotRepr {
    fn from(s: UniformSpotLight) -> Self {
        Self {
            position: s.position,
            direction: s.direction,
            cone_angle: s.cone_angle,
            power: Some(s.emission.power()),
            lumens: None,
            candela: None,
            spd: s.emission.spd().clone(),
            wavelength_sampling: s.emission.sampling(),
        }
    }
}

impl UniformSpotLight {
    /// A uniform spot at `position` with axis `direction` and half-angle `cone_angle` degrees.
    ///
    /// # Errors
    /// [`LightError::Parameter`] naming `position`, `direction`, `cone_angle` or `power`.
    pub fn new(
        position: DVec3,
        direction: DVec3,
        cone_angle: f64,
        power: f64,
        spd: Arc<dyn SpectralPowerDistribution>,
        wavelength_sampling: WavelengthSampling,
    ) -> Result<Self, LightError> {
        const L: &str = "UniformSpotLight";
        let position = finite_point(L, "position", position)?;
        let direction = unit_direction(L, "direction", direction)?;
        let cone_angle = cone(L, cone_angle)?;
        let emission = SpdLight::new(L, spd, power, wavelength_sampling)?;
        let one_minus_cos = one_minus_cos(cone_angle.to_radians());
        Ok(Self {
            emission,
            position,
            direction,
            cone_angle,
            one_minus_cos,
            frame: Frame::from_normal(direction),
        })
    }

    /// Radiant intensity (W/sr) inside the cone: `power / (2 pi (1 - cos cone))`.
    pub fn intensity(&self) -> f64 {
        self.emission.power() / (TAU * self.one_minus_cos)
    }

    /// The solid angle (sr) of a cone of half-angle `cone_angle` degrees, `2 pi (1 - cos cone)`
    /// with `1 - cos` free of cancellation: the flux per unit of intensity, which turns a
    /// `candela` key into lumens.
    pub fn solid_angle_of(cone_angle: f64) -> f64 {
        TAU * one_minus_cos(cone_angle.to_radians())
    }

    /// `cos(cone_angle)`.
    pub fn cos_cone(&self) -> f64 {
        1.0 - self.one_minus_cos
    }

    /// A beam direction from two uniforms: `cos(theta)` uniform on `[cos(cone), 1]`, uniform per
    /// solid angle inside the cone.
    fn direction_from(&self, u: [f64; 2]) -> DVec3 {
        self.frame.to_world(sample_uniform_cone(u, self.one_minus_cos)).normalize()
    }
}

#[typetag::serde]
impl LightSource for UniformSpotLight {
    fn next_beam(&self, rng: &mut dyn Rng) -> Beam {
        self.next_beam_at(uniform(rng), rng)
    }
    fn next_beam_at(&self, u_lambda: f64, rng: &mut dyn Rng) -> Beam {
        let (lambda, scale) = self.emission.wavelength(u_lambda);
        let direction = self.direction_from([uniform(rng), uniform(rng)]);
        self.emission.count();
        Beam::new(self.position, direction, lambda, scale)
    }
    crate::delegate_to_spd_light!(emission);
    fn flags(&self) -> Option<LightFlags> {
        Some(LightFlags { delta_position: true, delta_direction: false })
    }
    fn light_bounds(&self) -> Option<LightBounds> {
        let phi = 4.0 * PI * self.intensity();
        Some(LightBounds::spot(self.position, self.direction, self.cos_cone(), phi))
    }
    fn emission_density(&self, _origin: DVec3, direction: DVec3) -> f64 {
        if direction.dot(self.direction) >= self.cos_cone() {
            1.0 / (TAU * self.one_minus_cos)
        } else {
            0.0
        }
    }
    fn sample_towards(&self, receiver: DVec3, _u: [f64; 2]) -> Option<LightSample> {
        let (cos_cone, i) = (self.cos_cone(), self.intensity());
        point_sample(
            self.position,
            self.direction,
            receiver,
            |c| if c >= cos_cone { i } else { 0.0 },
        )
    }
    fn sample_emission(&self, u: [f64; 4]) -> Option<EmissionSample> {
        let direction = self.direction_from([u[0], u[1]]);
        point_emission(self.position, direction, self.emission_density(self.position, direction))
    }
    fn pdf_emission(&self, position: DVec3, direction: DVec3) -> Option<(f64, f64)> {
        Some((1.0, self.emission_density(position, direction)))
    }
}

// ---------------------------------------------------------------------------------------------

/// Segments of the tabulated polar-angle density of a fading spot.
const FADE_SEGMENTS: usize = 2048;

/// The seed's fading spot light: full intensity up to `cone_angle - 1 / fade_per_angle`, then a
/// linear fade to zero at `cone_angle` (intensity per solid angle; see the module docs).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(try_from = "FadingRepr", into = "FadingRepr")]
pub struct FadingSpotLight {
    emission: SpdLight,
    position: DVec3,
    direction: DVec3,
    cone_angle: f64,
    fade_per_angle: f64,
    /// Polar-angle sampler (radians), density proportional to `I(theta) sin(theta)`.
    theta: PiecewiseLinear,
    /// Intensity at the centre (W/sr).
    peak_intensity: f64,
    /// Solid-angle density of the beam directions along the axis (sr^-1): the peak intensity per
    /// watt, kept apart so that a light of zero power still has a density.
    peak_density: f64,
    frame: Frame,
}

/// Scene-file form of [`FadingSpotLight`].
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct FadingRepr {
    position: DVec3,
    direction: DVec3,
    cone_angle: f64,
    fade_per_angle: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    power: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    lumens: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    candela: Option<f64>,
    spd: Arc<dyn SpectralPowerDistribution>,
    #[serde(default)]
    wavelength_sampling: WavelengthSampling,
}

impl TryFrom<FadingRepr> for FadingSpotLight {
    type Error = LightError;
    fn try_from(r: FadingRepr) -> Result<Self, LightError> {
        let candela = match r.candela {
            Some(c) => Some((c, Self::solid_angle_of(r.cone_angle, r.fade_per_angle)?)),
            None => None,
        };
        let power =
            power_from_keys("FadingSpotLight", r.power, r.lumens, candela, true, r.spd.as_ref())?;
        Self::new(
            r.position,
            r.direction,
            r.cone_angle,
            r.fade_per_angle,
            power,
            r.spd,
            r.wavelength_sampling,
        )
    }
}

impl From<FadingSpotLight> for FadingRepr {
    fn from(s: FadingSpotLight) -> Self {
        Self {
            position: s.position,
            direction: s.direction,
            cone_angle: s.cone_angle,
            fade_per_angle: s.fade_per_angle,
            power: Some(s.emission.power()),
            lumens: None,
            candela: None,
            spd: s.emission.spd().clone(),
            wavelength_sampling: s.emission.sampling(),
        }
    }
}

impl FadingSpotLight {
    /// A fading spot at `position`, axis `direction`, half-angle `cone_angle` degrees, losing
    /// `fade_per_angle` of its intensity per degree in the fading ring.
    ///
    /// # Errors
    /// [`LightError::Parameter`] naming `position`, `direction`, `cone_angle`, `fade_per_angle`
    /// (not positive, or a fade longer than the cone) or `power`.
    pub fn new(
        position: DVec3,
        direction: DVec3,
        cone_angle: f64,
        fade_per_angle: f64,
        power: f64,
        spd: Arc<dyn SpectralPowerDistribution>,
        wavelength_sampling: WavelengthSampling,
    ) -> Result<Self, LightError> {
        const L: &str = "FadingSpotLight";
        let position = finite_point(L, "position", position)?;
        let direction = unit_direction(L, "direction", direction)?;
        let (tc, tf) = fade_angles(cone_angle, fade_per_angle)?;
        let emission = SpdLight::new(L, spd, power, wavelength_sampling)?;
        // Nodes in proportion to each part's angle, with a node exactly at the fade angle.
        let core = ((FADE_SEGMENTS as f64 * tf / tc).round() as usize).min(FADE_SEGMENTS - 64);
        let ring = FADE_SEGMENTS - core;
        let mut thetas: Vec<f64> = (0..core).map(|i| tf * i as f64 / core as f64).collect();
        thetas.extend(
            (0..=ring)
                .map(|i| if i == ring { tc } else { tf + (tc - tf) * i as f64 / ring as f64 }),
        );
        let profile = |t: f64| if t <= tf { 1.0 } else { ((tc - t) / (tc - tf)).clamp(0.0, 1.0) };
        let density: Vec<f64> = thetas.iter().map(|&t| profile(t) * t.sin()).collect();
        let theta = PiecewiseLinear::new(&thetas, &density).map_err(|_| {
            LightError::parameter(L, "cone_angle", cone_angle, "the cone is too narrow to tabulate")
        })?;
        let peak_density = 1.0 / profile_solid_angle(tc, tf);
        let peak_intensity = power * peak_density;
        Ok(Self {
            emission,
            position,
            direction,
            cone_angle,
            fade_per_angle,
            theta,
            peak_intensity,
            peak_density,
            frame: Frame::from_normal(direction),
        })
    }

    /// The solid angle (sr) that the profile of a fading spot with these `cone_angle` and
    /// `fade_per_angle` integrates to (its peak being 1): the flux per unit of peak intensity,
    /// which turns a `candela` key into lumens. It is the integral the light normalises its
    /// beams' directions by, so [`peak_intensity`](Self::peak_intensity) is exactly
    /// `power / solid_angle`.
    ///
    /// # Errors
    /// [`LightError::Parameter`] naming `cone_angle` or `fade_per_angle`, as [`Self::new`].
    pub fn solid_angle_of(cone_angle: f64, fade_per_angle: f64) -> Result<f64, LightError> {
        let (tc, tf) = fade_angles(cone_angle, fade_per_angle)?;
        Ok(profile_solid_angle(tc, tf))
    }

    /// The stated intensity profile relative to the centre at polar angle `theta_deg` degrees:
    /// 1 inside the fade angle, then linear to 0 at the cone.
    pub fn profile(&self, theta_deg: f64) -> f64 {
        let fade = self.cone_angle - 1.0 / self.fade_per_angle;
        if theta_deg <= fade {
            1.0
        } else {
            ((self.cone_angle - theta_deg) * self.fade_per_angle).clamp(0.0, 1.0)
        }
    }

    /// Radiant intensity (W/sr) along the axis.
    pub fn peak_intensity(&self) -> f64 {
        self.peak_intensity
    }

    /// The tabulated polar-angle density (radians) the beams are drawn from.
    pub fn polar_sampler(&self) -> &PiecewiseLinear {
        &self.theta
    }

    /// A beam direction from two uniforms: the polar angle from the tabulated density, the
    /// azimuth uniform.
    fn direction_from(&self, u: [f64; 2]) -> DVec3 {
        let theta = self.theta.sample(clamp_uniform(u[0]));
        let (s, c) = theta.sin_cos();
        self.frame.to_world(spherical_direction_turn(s, c, clamp_uniform(u[1]))).normalize()
    }
}

#[typetag::serde]
impl LightSource for FadingSpotLight {
    fn next_beam(&self, rng: &mut dyn Rng) -> Beam {
        self.next_beam_at(uniform(rng), rng)
    }
    fn next_beam_at(&self, u_lambda: f64, rng: &mut dyn Rng) -> Beam {
        let (lambda, scale) = self.emission.wavelength(u_lambda);
        let direction = self.direction_from([uniform(rng), uniform(rng)]);
        self.emission.count();
        Beam::new(self.position, direction, lambda, scale)
    }
    crate::delegate_to_spd_light!(emission);
    fn flags(&self) -> Option<LightFlags> {
        Some(LightFlags { delta_position: true, delta_direction: false })
    }
    fn light_bounds(&self) -> Option<LightBounds> {
        let phi = 4.0 * PI * self.peak_intensity;
        let cos_cone = self.cone_angle.to_radians().cos();
        Some(LightBounds::spot(self.position, self.direction, cos_cone, phi))
    }
    fn emission_density(&self, _origin: DVec3, direction: DVec3) -> f64 {
        let theta = direction.dot(self.direction).clamp(-1.0, 1.0).acos().to_degrees();
        self.peak_density * self.profile(theta)
    }
    fn sample_towards(&self, receiver: DVec3, _u: [f64; 2]) -> Option<LightSample> {
        point_sample(self.position, self.direction, receiver, |c| {
            self.peak_intensity * self.profile(c.clamp(-1.0, 1.0).acos().to_degrees())
        })
    }
    fn sample_emission(&self, u: [f64; 4]) -> Option<EmissionSample> {
        let direction = self.direction_from([u[0], u[1]]);
        point_emission(self.position, direction, self.emission_density(self.position, direction))
    }
    fn pdf_emission(&self, position: DVec3, direction: DVec3) -> Option<(f64, f64)> {
        Some((1.0, self.emission_density(position, direction)))
    }
}

/// Checks a fading spot's `cone_angle` and `fade_per_angle`; returns the cone and fade angles in
/// radians.
fn fade_angles(cone_angle: f64, fade_per_angle: f64) -> Result<(f64, f64), LightError> {
    const L: &str = "FadingSpotLight";
    let cone_angle = cone(L, cone_angle)?;
    let fade_per_angle = positive(L, "fade_per_angle", fade_per_angle)?;
    let fade_width = 1.0 / fade_per_angle;
    if fade_width > cone_angle {
        return Err(LightError::parameter(
            L,
            "fade_per_angle",
            fade_per_angle,
            "the fade (1 / fade_per_angle degrees) is longer than the cone",
        ));
    }
    Ok((cone_angle.to_radians(), (cone_angle - fade_width).to_radians()))
}

/// The solid angle (sr) of a fading spot's profile (peak 1) with cone angle `tc` and fade angle
/// `tf` (radians): `2 pi` times the integral of `I(theta) sin(theta)` over the cone. The core is
/// `1 - cos tf = 2 sin^2(tf / 2)`; the ring's closed form cancels catastrophically for narrow
/// fades, so it is integrated by 8-point Gauss-Legendre on 8 panels (the integrand is smooth, so
/// this is exact to rounding).
fn profile_solid_angle(tc: f64, tf: f64) -> f64 {
    let ring_integrand = |t: f64| (tc - t) / (tc - tf) * t.sin();
    let panel = (tc - tf) / 8.0;
    let ring: f64 = (0..8)
        .map(|k| {
            gauss_legendre_8(&ring_integrand, tf + panel * k as f64, tf + panel * (k + 1) as f64)
        })
        .sum();
    TAU * (one_minus_cos(tf) + ring)
}

/// Integrates `f` over `[a, b]` with 8-point Gauss-Legendre quadrature (exact to degree 15).
fn gauss_legendre_8(f: &dyn Fn(f64) -> f64, a: f64, b: f64) -> f64 {
    const NODES: [(f64, f64); 4] = [
        (0.183_434_642_495_649_8, 0.362_683_783_378_362),
        (0.525_532_409_916_329, 0.313_706_645_877_887_3),
        (0.796_666_477_413_626_7, 0.222_381_034_453_374_5),
        (0.960_289_856_497_536_3, 0.101_228_536_290_376_26),
    ];
    let (mid, half) = ((a + b) / 2.0, (b - a) / 2.0);
    half * NODES.iter().map(|&(x, w)| w * (f(mid - half * x) + f(mid + half * x))).sum::<f64>()
}

// ---------------------------------------------------------------------------------------------

/// An isotropic point light.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(try_from = "PointRepr", into = "PointRepr")]
pub struct PointLight {
    emission: SpdLight,
    position: DVec3,
}

/// Scene-file form of [`PointLight`].
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct PointRepr {
    position: DVec3,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    power: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    lumens: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    candela: Option<f64>,
    spd: Arc<dyn SpectralPowerDistribution>,
    #[serde(default)]
    wavelength_sampling: WavelengthSampling,
}

impl TryFrom<PointRepr> for PointLight {
    type Error = LightError;
    fn try_from(r: PointRepr) -> Result<Self, LightError> {
        let candela = r.candela.map(|c| (c, 4.0 * PI));
        let power =
            power_from_keys("PointLight", r.power, r.lumens, candela, true, r.spd.as_ref())?;
        Self::new(r.position, power, r.spd, r.wavelength_sampling)
    }
}

impl From<PointLight> for PointRepr {
    fn from(p: PointLight) -> Self {
        Self {
            position: p.position,
            power: Some(p.emission.power()),
            lumens: None,
            candela: None,
            spd: p.emission.spd().clone(),
            wavelength_sampling: p.emission.sampling(),
        }
    }
}

impl PointLight {
    /// An isotropic point light at `position`.
    ///
    /// # Errors
    /// [`LightError::Parameter`] naming `position` or `power`.
    pub fn new(
        position: DVec3,
        power: f64,
        spd: Arc<dyn SpectralPowerDistribution>,
        wavelength_sampling: WavelengthSampling,
    ) -> Result<Self, LightError> {
        const L: &str = "PointLight";
        let position = finite_point(L, "position", position)?;
        let emission = SpdLight::new(L, spd, power, wavelength_sampling)?;
        Ok(Self { emission, position })
    }

    /// Radiant intensity (W/sr): `power / (4 pi)`.
    pub fn intensity(&self) -> f64 {
        self.emission.power() / (4.0 * PI)
    }
}

#[typetag::serde]
impl LightSource for PointLight {
    fn next_beam(&self, rng: &mut dyn Rng) -> Beam {
        self.next_beam_at(uniform(rng), rng)
    }
    fn next_beam_at(&self, u_lambda: f64, rng: &mut dyn Rng) -> Beam {
        let (lambda, scale) = self.emission.wavelength(u_lambda);
        // z = cos(theta) uniform on [-1, 1]: uniform on the sphere.
        let direction = sphere_direction([uniform(rng), uniform(rng)]);
        self.emission.count();
        Beam::new(self.position, direction, lambda, scale)
    }
    crate::delegate_to_spd_light!(emission);
    fn flags(&self) -> Option<LightFlags> {
        Some(LightFlags { delta_position: true, delta_direction: false })
    }
    fn light_bounds(&self) -> Option<LightBounds> {
        Some(LightBounds::point(self.position, self.power()))
    }
    fn emission_density(&self, _origin: DVec3, _direction: DVec3) -> f64 {
        1.0 / (4.0 * PI)
    }
    fn sample_towards(&self, receiver: DVec3, _u: [f64; 2]) -> Option<LightSample> {
        let i = self.intensity();
        point_sample(self.position, DVec3::Z, receiver, |_| i)
    }
    fn sample_emission(&self, u: [f64; 4]) -> Option<EmissionSample> {
        let direction = sphere_direction([u[0], u[1]]);
        point_emission(self.position, direction, self.emission_density(self.position, direction))
    }
    fn pdf_emission(&self, position: DVec3, direction: DVec3) -> Option<(f64, f64)> {
        Some((1.0, self.emission_density(position, direction)))
    }
}

/// A direction uniform on the sphere from two uniforms, as a point light emits them.
fn sphere_direction(u: [f64; 2]) -> DVec3 {
    sample_uniform_sphere(u).normalize()
}
