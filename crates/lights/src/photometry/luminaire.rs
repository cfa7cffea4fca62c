//! Measured luminaires as beam generators: [`CandelaDistribution`] (a type C candela table over
//! the whole sphere, sampled exactly), and [`IesLight`] and [`EulumdatLight`], point lights whose
//! intensity follows an IES LM-63 or a EULUMDAT file. Both take the same keys.
//!
//! | field | unit | default | meaning |
//! |---|---|---|---|
//! | `file` | path | required | the photometric file, relative to the scene file's folder |
//! | `position` | m | required | the luminaire's photometric centre |
//! | `nadir` | | `[0, -1, 0]` | direction of vertical angle 0 (straight down from the luminaire); for an IES type B file, the photometric axis; for type A, straight down (`V = -90`) |
//! | `c0` | | `[1, 0, 0]` | direction of C-plane 0 (made perpendicular to `nadir`; must not be parallel to it); for an IES type B file, the `H = +90` end of the polar axis; for type A, the photometric horizontal (`H = 0, V = 0`) |
//! | `spd` | SPD | see below | spectrum of the light |
//! | `cct` | K | | instead of `spd`: a blackbody at this colour temperature |
//! | `multiplier` | | 1 | scales every candela value (and so the flux) |
//! | `lumens` | lm | | instead of `multiplier`: scales the table so the luminaire emits this flux |
//! | `wavelength_sampling` | | `"importance"` | as for every light |
//! | `lamp_set` | | `1` | `EulumdatLight` only: which of the file's lamp sets (alternatives) is fitted, from 1 |
//!
//! ```json
//! {"type": "IesLight", "file": "downlight.ies", "position": [0, 2.8, 0],
//!  "nadir": [0, -1, 0], "c0": [1, 0, 0], "cct": 4000, "multiplier": 1}
//! {"type": "EulumdatLight", "file": "linear.ldt", "position": [0, 2.8, 0]}
//! ```
//!
//! # Angles and handedness
//! A direction `d` has the vertical angle `gamma` from `nadir` (`cos gamma = d . nadir`; 0 is
//! straight down the nadir, 180 straight up) and the horizontal angle `C` measured from `c0`
//! *counter-clockwise when seen from above* (from the side opposite the nadir, looking down it),
//! as LM-63 and EULUMDAT define: C-plane 90 points along `c90 = c0 x nadir` (`= up x c0`). With
//! the defaults (y up, nadir -y, c0 +x), C90 is -z:
//! `d = cos(gamma) nadir + sin(gamma) (cos(C) c0 + sin(C) c90)`.
//!
//! # Between the measured angles
//! The formats give candela values on a grid of angles and leave interpolation to the reader.
//! Spectrace interpolates bilinearly in `(C, cos gamma)` (linear in `cos gamma` rather than in
//! `gamma`): solid angle is `dC d(cos gamma)`, so the intensity is then a bilinear *density* on the
//! grid and [`PiecewiseBilinear`] samples it exactly, with no table of its own; the luminous
//! flux is the exact integral of that interpolant. On the 1-5 degree grids of real files the two
//! interpolations differ by a fraction of a percent inside a cell, and not at all at the
//! measured angles. Outside the measured vertical range the intensity is 0. The horizontal
//! range declares the symmetry (LM-63): `[0]` rotational, `0..90` quadrant, `0..180` bilateral
//! about the C0-C180 plane, `90..270` bilateral about the C90-C270 plane, `0..360` (or less,
//! wrapping to 0) none; the table is unfolded over the whole circle by those mirrors.
//!
//! # Power and spectrum
//! The luminous flux is the integral of the interpolated intensity over the sphere (in lumens:
//! candela x steradian) times `multiplier` (and, for IES files, the file's ballast factor). For
//! relative photometry the file's candela values are those of its rated lamps, so this is the
//! luminaire's output, the lamp lumens times its light output ratio; for absolute photometry
//! (lumens `-1`) it is the measured output. The radiant power is that flux divided by the
//! spectrum's luminous efficacy (683 lm/W x the photopic curve, see
//! [`spectrace_spectrum::luminous_efficacy`]). The spectrum is `spd`, or a blackbody at `cct`;
//! without either it is CIE illuminant A (a 2856 K lamp, the reference of photometry), or for
//! EULUMDAT files the blackbody at the first lamp set's colour temperature when that is a
//! number of kelvin. The colour does not change with direction.
//!
//! # Lamps, light output ratio and glare
//! [`IesLight::lumens_summary`] and [`EulumdatLight::lumens_summary`] (and, through a
//! `dyn LightSource`, [`LightSource::photometric_summary`]) compare the table's flux with the
//! lamps' rated flux: [`LuminaireLumens`] defines each number. [`LightSource::glare_view`] gives
//! what an eye sees of the luminaire for CIE 117's Unified Glare Rating: the luminous
//! intensity towards the eye over the projected area of the file's luminous opening
//! ([`crate::GlareView`], [`LuminousOpening`], [`IesFile::luminous_opening`],
//! [`LdtFile::luminous_opening`]). A file of opening `0 0 0` (a point) gives no view. The
//! horizontal face of a flat or box-shaped opening counts on the side(s) the table sends light
//! to: seen from below when some measured value below the horizontal is positive, from above
//! when some value above it is (an uplight); a type B table's opening faces its photometric
//! axis, a type A table's its photometric horizontal.
//!
//! # What is not modelled
//! The luminaire emits from a point (far-field photometry): its luminous opening serves the
//! glare view only, so illuminance closer than about five opening sizes is that of the point.
//! `TILT=INCLUDE` data are read but not applied (the luminaire is taken at its measured tilt).

use std::f64::consts::TAU;
use std::path::PathBuf;
use std::sync::Arc;

use glam::DVec3;
use rand::Rng;
use serde::{Deserialize, Serialize};
use spectrace_sampling::PiecewiseBilinear;
use spectrace_spectrum::{Blackbody, CieIlluminant, SpectralPowerDistribution, watts_from_lumens};

use super::LuminaireLumens;
use crate::geometry::{finite_point, unit_direction};
use crate::glare::{LuminousOpening, PlacedOpening, lit_faces};
use crate::source::uniform;
use crate::spot::{point_emission, point_sample};
use crate::{
    Beam, EmissionSample, LightError, LightFlags, LightSample, LightSource, SpdLight,
    WavelengthSampling,
};

use super::{CandelaPlanes, IesFile, LdtFile};

/// Largest photometric file read (4 MiB; a 1-degree table over the whole sphere is under 1 MiB).
pub const MAX_PHOTOMETRIC_BYTES: u64 = 4 << 20;

/// How the stored horizontal angles of a type C table extend to the whole circle.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Symmetry {
    /// One C-plane: the same in every direction around the nadir.
    Rotational,
    /// C 0..90 stored: mirrored about both the C0-C180 and the C90-C270 planes.
    Quadrant,
    /// C 0..180 stored: mirrored about the C0-C180 plane.
    C0C180,
    /// C 90..270 stored: mirrored about the C90-C270 plane.
    C90C270,
    /// C 0..last stored (last <= 360), wrapping from `last` to 360 = 0.
    None,
}

/// A type C candela distribution over the whole sphere, with exact sampling of directions in
/// proportion to intensity. Coordinates are `C` in radians (`[0, 2 pi]`) and `-cos gamma`
/// (`[-1, 1]`, increasing with gamma), in which solid angle is `dC d(-cos gamma)`.
#[derive(Debug, Clone, PartialEq)]
pub struct CandelaDistribution {
    table: PiecewiseBilinear,
    peak: f64,
    /// One C-plane: the intensity does not depend on `C`.
    rotational: bool,
}

impl CandelaDistribution {
    /// The distribution of a table of `candela[h][v]` (cd) at the horizontal angles
    /// `horizontal[h]` (degrees, a range that declares the symmetry as LM-63 does, see the module
    /// documentation) and vertical angles `vertical[v]` (degrees from nadir, within [0, 180]).
    ///
    /// # Errors
    /// Why, as text: fewer than two vertical angles, angles out of range or not increasing, a
    /// horizontal range that declares no symmetry, counts that disagree, candela values that are
    /// negative or not finite, or a table that is zero everywhere.
    pub fn new(horizontal: &[f64], vertical: &[f64], candela: &[Vec<f64>]) -> Result<Self, String> {
        if vertical.len() < 2 {
            return Err(format!(
                "{} vertical angle(s): at least two are needed to describe a distribution",
                vertical.len()
            ));
        }
        let increasing = vertical.windows(2).all(|w| w[0] < w[1]);
        if !(increasing && vertical[0] >= 0.0 && vertical[vertical.len() - 1] <= 180.0) {
            return Err("vertical angles must increase strictly within [0, 180] degrees".into());
        }
        if horizontal.is_empty() || !horizontal.windows(2).all(|w| w[0] < w[1]) {
            return Err("horizontal angles must be given and increase strictly".into());
        }
        if candela.len() != horizontal.len() || candela.iter().any(|c| c.len() != vertical.len()) {
            return Err("the candela table's size does not match the angles".into());
        }
        if let Some(bad) = candela.iter().flatten().find(|c| !(c.is_finite() && **c >= 0.0)) {
            return Err(format!("candela value {bad}: must be finite and >= 0"));
        }
        let (first, last) = (horizontal[0], horizontal[horizontal.len() - 1]);
        let symmetry = match (horizontal.len(), first, last) {
            (1, _, _) => Symmetry::Rotational,
            (_, 0.0, 90.0) => Symmetry::Quadrant,
            (_, 0.0, 180.0) => Symmetry::C0C180,
            (_, 90.0, 270.0) => Symmetry::C90C270,
            (_, 0.0, l) if l > 180.0 && l <= 360.0 => Symmetry::None,
            _ => {
                return Err(format!(
                    "horizontal angles {first}..{last} declare no symmetry the formats define \
                     ([0], 0..90, 0..180, 90..270, or 0 to more than 180 up to 360)"
                ));
            }
        };
        // Every node of the whole circle, with the stored column it copies.
        let mut nodes: Vec<(f64, usize)> = Vec::new();
        for (h, &a) in horizontal.iter().enumerate() {
            let images: &[f64] = match symmetry {
                Symmetry::Rotational => &[0.0, 360.0],
                Symmetry::Quadrant => &[a, 180.0 - a, 180.0 + a, 360.0 - a],
                Symmetry::C0C180 => &[a, 360.0 - a],
                Symmetry::C90C270 => &[a, (180.0 - a).rem_euclid(360.0)],
                Symmetry::None => &[a],
            };
            nodes.extend(images.iter().map(|&c| (c, h)));
        }
        nodes.sort_by(|a, b| a.0.total_cmp(&b.0));
        nodes.dedup_by(|b, a| (b.0 - a.0).abs() < 1e-9);
        // Close the circle: 0 and 360 are the same plane.
        if let Some(&(c, h)) = nodes.first()
            && c == 0.0
            && nodes.last().is_some_and(|n| n.0 < 360.0 - 1e-9)
        {
            nodes.push((360.0, h));
        }
        if let Some(&(c, h)) = nodes.last()
            && (c - 360.0).abs() < 1e-9
            && nodes.first().is_some_and(|n| n.0 > 1e-9)
        {
            nodes.insert(0, (0.0, h));
        }
        let xs: Vec<f64> = nodes.iter().map(|n| n.0.to_radians()).collect();
        let ys: Vec<f64> = vertical.iter().map(|g| -g.to_radians().cos()).collect();
        if !ys.windows(2).all(|w| w[0] < w[1]) {
            return Err("two vertical angles are too close to tell apart".into());
        }
        let values: Vec<f64> =
            nodes.iter().flat_map(|&(_, h)| candela[h].iter().copied()).collect();
        let peak = values.iter().copied().fold(0.0, f64::max);
        let table = PiecewiseBilinear::new(&xs, &ys, &values).map_err(|e| match e {
            spectrace_sampling::SamplingError::ZeroTotal { .. } => {
                "every candela value is 0: the luminaire emits nothing".to_owned()
            }
            other => format!("the candela table cannot be sampled: {other}"),
        })?;
        Ok(Self { table, peak, rotational: symmetry == Symmetry::Rotational })
    }

    /// The luminous intensity (cd) at horizontal angle `c` (radians, any value: taken modulo
    /// 2 pi) and `cos_gamma` (the cosine of the angle from nadir).
    pub fn candela(&self, c: f64, cos_gamma: f64) -> f64 {
        // One C-plane: its column, exactly (interpolating between its two copies at 0 and
        // 2 pi could round). `rem_euclid` is a library call (fmod); angles in range skip it.
        let c = if self.rotational {
            0.0
        } else if (0.0..TAU).contains(&c) {
            c
        } else {
            c.rem_euclid(TAU)
        };
        self.table.value(c, -cos_gamma)
    }

    /// `true` if the intensity depends on the horizontal angle `C` (the table has more than one
    /// C-plane).
    pub fn depends_on_c(&self) -> bool {
        !self.rotational
    }

    /// The luminous flux (lm): the integral of the intensity over the sphere.
    pub fn lumens(&self) -> f64 {
        self.table.integral()
    }

    /// The largest candela value of the table.
    pub fn peak_candela(&self) -> f64 {
        self.peak
    }

    /// Draws `(C, cos gamma)` with density proportional to the intensity per solid angle.
    pub fn sample(&self, u: [f64; 2]) -> (f64, f64) {
        let (c, y) = self.table.sample(u);
        (c, -y)
    }

    /// The solid-angle density (sr^-1) of [`sample`](Self::sample) at `(C, cos gamma)`:
    /// `candela / lumens`.
    pub fn pdf(&self, c: f64, cos_gamma: f64) -> f64 {
        self.candela(c, cos_gamma) / self.lumens()
    }
}

/// Where a luminaire points: its nadir, its C0 direction and the C90 direction they define.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Orientation {
    nadir: DVec3,
    c0: DVec3,
    c90: DVec3,
}

impl Orientation {
    /// Checks and orthonormalises `nadir` and `c0` (see the module documentation).
    pub(crate) fn new(light: &'static str, nadir: DVec3, c0: DVec3) -> Result<Self, LightError> {
        let nadir = unit_direction(light, "nadir", nadir)?;
        let c0 = unit_direction(light, "c0", c0)?;
        let along = c0 - nadir * c0.dot(nadir);
        if !(along.length() > 1e-6) {
            return Err(LightError::parameter(
                light,
                "c0",
                c0.to_array(),
                "must not be parallel to nadir (it gives the direction of C-plane 0)",
            ));
        }
        let c0 = along.normalize();
        Ok(Self { nadir, c0, c90: c0.cross(nadir) })
    }

    /// The world directions of C0, C90 and the nadir: the frame of a type C opening.
    pub(crate) fn axes(&self) -> [DVec3; 3] {
        [self.c0, self.c90, self.nadir]
    }

    /// The world direction of `(C, cos gamma)`.
    fn direction(&self, c: f64, cos_gamma: f64) -> DVec3 {
        let sin_gamma = (1.0 - cos_gamma * cos_gamma).max(0.0).sqrt();
        let (s, co) = c.sin_cos();
        (self.nadir * cos_gamma + (self.c0 * co + self.c90 * s) * sin_gamma).normalize()
    }

    /// `(C, cos gamma)` of a unit world direction; `C` is 0 unless `with_c` (a rotationally
    /// symmetric distribution does not depend on it, and its `atan2` is a tenth of the cost of
    /// a light connection in a room of luminaires).
    fn angles(&self, d: DVec3, with_c: bool) -> (f64, f64) {
        let cos_gamma = d.dot(self.nadir).clamp(-1.0, 1.0);
        if !with_c {
            return (0.0, cos_gamma);
        }
        // `atan2` lies in [-pi, pi], where `rem_euclid(TAU)` is exactly this one addition.
        let c = d.dot(self.c90).atan2(d.dot(self.c0));
        (if c < 0.0 { c + TAU } else { c }, cos_gamma)
    }
}

/// The shared core of the measured-luminaire lights: a point with a candela distribution.
#[derive(Debug, Clone)]
pub(crate) struct Luminaire {
    pub(crate) emission: SpdLight,
    pub(crate) position: DVec3,
    pub(crate) orientation: Orientation,
    pub(crate) distribution: Arc<CandelaDistribution>,
    /// Flux (lm) of the file's table at its own scale (see [`LuminaireLumens::file_lumens`]).
    pub(crate) file_lumens: f64,
}

impl Luminaire {
    /// A luminaire of the given distribution (candela already scaled), spectrum and placement;
    /// its power is the distribution's flux over the spectrum's luminous efficacy.
    pub(crate) fn new(
        light: &'static str,
        position: DVec3,
        orientation: Orientation,
        distribution: CandelaDistribution,
        spd: Arc<dyn SpectralPowerDistribution>,
        sampling: WavelengthSampling,
    ) -> Result<Self, LightError> {
        let position = finite_point(light, "position", position)?;
        let lumens = distribution.lumens();
        let power = watts_from_lumens(lumens, spd.as_ref()).ok_or_else(|| {
            LightError::parameter(
                light,
                "spd",
                lumens,
                "has no visible light, so no radiant power gives the file's lumens",
            )
        })?;
        let emission = SpdLight::new(light, spd, power, sampling)?;
        let distribution = Arc::new(distribution);
        Ok(Self { emission, position, orientation, distribution, file_lumens: lumens })
    }

    /// A luminaire of the stored table `planes.0` with every value times `planes.1` (a file's
    /// own factor), scaled by `scale`, placed at `(position, nadir, c0)`, and its scene-file
    /// form.
    pub(crate) fn placed(
        light: &'static str,
        planes: (&CandelaPlanes, f64),
        (position, nadir, c0): (DVec3, DVec3, DVec3),
        spd: Arc<dyn SpectralPowerDistribution>,
        scale: Scale,
        sampling: WavelengthSampling,
    ) -> Result<(Self, LuminaireRepr), LightError> {
        let multiplier = check_multiplier(light, scale.multiplier)?;
        let orientation = Orientation::new(light, nadir, c0)?;
        let mut distribution = distribution_of(light, planes.0, multiplier * planes.1)?;
        // Flux is linear in the table, and the factor is > 0 (a zero one leaves no table).
        let file_lumens = distribution.lumens() / (multiplier * planes.1);
        if let Some(lumens) = scale.lumens {
            if multiplier != 1.0 {
                return Err(LightError::parameter(
                    light,
                    "lumens",
                    lumens,
                    "give `lumens` (the luminaire's flux) or `multiplier`, not both",
                ));
            }
            if !(lumens > 0.0 && lumens.is_finite()) {
                return Err(LightError::parameter(
                    light,
                    "lumens",
                    lumens,
                    "must be finite and > 0",
                ));
            }
            // Flux is linear in the table: rescale the one at factor `planes.1`.
            let factor = planes.1 * lumens / distribution.lumens();
            distribution = distribution_of(light, planes.0, factor)?;
        }
        let mut luminaire =
            Self::new(light, position, orientation, distribution, spd.clone(), sampling)?;
        luminaire.file_lumens = file_lumens;
        let repr = LuminaireRepr {
            file: PathBuf::new(),
            position,
            nadir,
            c0,
            spd: Some(spd),
            cct: None,
            multiplier,
            lumens: scale.lumens,
            wavelength_sampling: sampling,
            lamp_set: None,
        };
        Ok((luminaire, repr))
    }

    /// The spectrum a luminaire gets from its scene-file keys: `spd`, or a blackbody at `cct`,
    /// or `default_cct`'s blackbody, or CIE illuminant A.
    pub(crate) fn spectrum(
        light: &'static str,
        spd: Option<Arc<dyn SpectralPowerDistribution>>,
        cct: Option<f64>,
        default_cct: Option<f64>,
    ) -> Result<Arc<dyn SpectralPowerDistribution>, LightError> {
        match (spd, cct) {
            (Some(_), Some(k)) => {
                Err(LightError::parameter(light, "cct", k, "give either `spd` or `cct`, not both"))
            }
            (Some(spd), None) => Ok(spd),
            (None, Some(k)) if !(k > 0.0 && k.is_finite()) => Err(LightError::parameter(
                light,
                "cct",
                k,
                "must be a positive, finite colour temperature in kelvin",
            )),
            (None, Some(k)) => Blackbody::new(k)
                .map(|b| Arc::new(b) as Arc<dyn SpectralPowerDistribution>)
                .map_err(|source| LightError::Spectrum { light, source }),
            (None, None) => match default_cct.and_then(|k| Blackbody::new(k).ok()) {
                Some(b) => Ok(Arc::new(b)),
                None => CieIlluminant::new("A")
                    .map(|a| Arc::new(a) as Arc<dyn SpectralPowerDistribution>)
                    .map_err(|source| LightError::Spectrum { light, source }),
            },
        }
    }

    /// Radiant intensity (W/sr, whole spectrum) along the unit world direction `d`.
    pub(crate) fn intensity(&self, d: DVec3) -> f64 {
        self.emission.power() * self.pdf_direction(d)
    }

    /// Solid-angle density of the beams' directions along the unit world direction `d`.
    pub(crate) fn pdf_direction(&self, d: DVec3) -> f64 {
        let (c, cos_gamma) = self.angles(d);
        self.distribution.pdf(c, cos_gamma)
    }

    /// `(C, cos gamma)` of the unit world direction `d` (`C` is 0 if the distribution does not
    /// depend on it).
    pub(crate) fn angles(&self, d: DVec3) -> (f64, f64) {
        self.orientation.angles(d, self.distribution.depends_on_c())
    }

    /// A direction drawn in proportion to intensity.
    pub(crate) fn sample_direction(&self, u: [f64; 2]) -> DVec3 {
        let (c, cos_gamma) = self.distribution.sample(u);
        self.orientation.direction(c, cos_gamma)
    }

    /// The next beam, its wavelength from `u_lambda` (see [`LightSource::next_beam_at`]).
    pub(crate) fn next_beam_at(&self, u_lambda: f64, rng: &mut dyn Rng) -> Beam {
        let (lambda, scale) = self.emission.wavelength(u_lambda);
        let direction = self.sample_direction([uniform(rng), uniform(rng)]);
        self.emission.count();
        Beam::new(self.position, direction, lambda, scale)
    }

    pub(crate) fn sample_towards(&self, receiver: DVec3) -> Option<LightSample> {
        let mut s = point_sample(self.position, DVec3::Z, receiver, |_| 0.0)?;
        s.intensity = self.intensity(s.direction);
        Some(s)
    }

    pub(crate) fn sample_emission(&self, u: [f64; 4]) -> Option<EmissionSample> {
        let direction = self.sample_direction([u[0], u[1]]);
        point_emission(self.position, direction, self.pdf_direction(direction))
    }
}

/// The inherent accessors of a type holding a [`Luminaire`] in the field `luminaire` and a
/// [`PlacedOpening`] in the field `opening`.
macro_rules! luminaire_accessors {
    () => {
        /// The luminous opening the file describes (metres, in the luminaire's frame: see
        /// [`LuminousOpening`]); `None` for a point source or a shape the file does not
        /// define. Only [`LightSource::glare_view`] uses it: the light emits from its centre.
        pub fn luminous_opening(&self) -> Option<LuminousOpening> {
            self.opening.opening()
        }

        /// The candela distribution (absolute, every multiplier applied).
        pub fn distribution(&self) -> &CandelaDistribution {
            &self.luminaire.distribution
        }

        /// The luminous flux (lm) the light emits.
        pub fn lumens(&self) -> f64 {
            self.luminaire.distribution.lumens()
        }

        /// Luminous intensity (cd) along the unit world direction `d`.
        pub fn candela_towards(&self, d: DVec3) -> f64 {
            let (c, cos_gamma) = self.luminaire.angles(d);
            self.luminaire.distribution.candela(c, cos_gamma)
        }
    };
}

/// Implements the beam, density, summary and glare methods of [`LightSource`] for a type
/// holding a [`Luminaire`] in the field `luminaire`, a [`PlacedOpening`] in `opening` and an
/// inherent `lumens_summary`.
macro_rules! luminaire_light_source {
    () => {
        fn next_beam(&self, rng: &mut dyn Rng) -> Beam {
            self.luminaire.next_beam_at(uniform(rng), rng)
        }
        fn next_beam_at(&self, u_lambda: f64, rng: &mut dyn Rng) -> Beam {
            self.luminaire.next_beam_at(u_lambda, rng)
        }
        fn number_of_beams(&self) -> u64 {
            self.luminaire.emission.number_of_beams()
        }
        fn power(&self) -> f64 {
            self.luminaire.emission.power()
        }
        fn spd(&self) -> Arc<dyn SpectralPowerDistribution> {
            self.luminaire.emission.spd().clone()
        }
        fn reset_count(&self) {
            self.luminaire.emission.reset_count();
        }
        fn sample_wavelength(&self, u: f64) -> (f64, f64) {
            self.luminaire.emission.companion_wavelength(u)
        }
        fn set_wavelength_sampling(
            &mut self,
            sampling: WavelengthSampling,
        ) -> Result<(), LightError> {
            self.luminaire.emission.set_sampling(sampling)
        }
        fn map_spd(&mut self, f: &crate::SpdMap<'_>) -> Result<bool, LightError> {
            self.luminaire.emission.map_spd(f)
        }
        fn notes(&self) -> Vec<String> {
            self.notes.to_vec()
        }
        fn flags(&self) -> Option<LightFlags> {
            Some(LightFlags { delta_position: true, delta_direction: false })
        }
        fn light_bounds(&self) -> Option<crate::LightBounds> {
            // 4 pi times the peak intensity, in watts per steradian.
            let lumens = self.luminaire.distribution.lumens();
            let watts_per_candela = if lumens > 0.0 { self.power() / lumens } else { 0.0 };
            let phi = 2.0 * TAU * self.luminaire.distribution.peak_candela() * watts_per_candela;
            Some(crate::LightBounds::point(self.luminaire.position, phi))
        }
        fn emission_density(&self, _origin: DVec3, direction: DVec3) -> f64 {
            self.luminaire.pdf_direction(direction)
        }
        fn sample_towards(&self, receiver: DVec3, _u: [f64; 2]) -> Option<LightSample> {
            self.luminaire.sample_towards(receiver)
        }
        fn sample_emission(&self, u: [f64; 4]) -> Option<EmissionSample> {
            self.luminaire.sample_emission(u)
        }
        fn pdf_emission(&self, _position: DVec3, direction: DVec3) -> Option<(f64, f64)> {
            Some((1.0, self.luminaire.pdf_direction(direction)))
        }
        fn photometric_summary(&self) -> Option<LuminaireLumens> {
            Some(self.lumens_summary())
        }
        fn glare_view(&self, eye: DVec3) -> Option<crate::GlareView> {
            self.opening.view(self.luminaire.position, eye, |d| self.candela_towards(d))
        }
    };
}

// ---------------------------------------------------------------------------------------------

/// A luminaire whose intensity follows an IES LM-63 file (type C photometry).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(try_from = "LuminaireRepr", into = "LuminaireRepr")]
pub struct IesLight {
    luminaire: Luminaire,
    repr: Arc<LuminaireRepr>,
    file: Arc<IesFile>,
    notes: Arc<[String]>,
    opening: PlacedOpening,
}

/// Scene-file form of [`IesLight`] and [`EulumdatLight`].
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct LuminaireRepr {
    file: PathBuf,
    position: DVec3,
    #[serde(default = "default_nadir")]
    nadir: DVec3,
    #[serde(default = "default_c0")]
    c0: DVec3,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    spd: Option<Arc<dyn SpectralPowerDistribution>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    cct: Option<f64>,
    #[serde(default = "one")]
    multiplier: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    lumens: Option<f64>,
    #[serde(default)]
    wavelength_sampling: WavelengthSampling,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    lamp_set: Option<usize>,
}

impl LuminaireRepr {
    /// The scene file's `multiplier` and `lumens`.
    fn scale(&self) -> Scale {
        Scale { multiplier: self.multiplier, lumens: self.lumens }
    }
}

/// How a luminaire's table is scaled: by `multiplier`, or (with `lumens`) to that flux.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Scale {
    multiplier: f64,
    lumens: Option<f64>,
}

impl Scale {
    /// Scaled by `multiplier` alone.
    fn by(multiplier: f64) -> Self {
        Self { multiplier, lumens: None }
    }
}

pub(crate) fn default_nadir() -> DVec3 {
    DVec3::NEG_Y
}

pub(crate) fn default_c0() -> DVec3 {
    DVec3::X
}

pub(crate) fn one() -> f64 {
    1.0
}

/// Checks a candela multiplier: finite and > 0.
pub(crate) fn check_multiplier(light: &'static str, m: f64) -> Result<f64, LightError> {
    if m > 0.0 && m.is_finite() {
        Ok(m)
    } else {
        Err(LightError::parameter(light, "multiplier", m, "must be finite and > 0"))
    }
}

/// Reads a photometric file named in a scene file (relative to its folder) as makers ship it
/// ([`super::decode_text`]): its path, its text and what reading it took, if anything.
pub(crate) fn read_photometric_file(
    light: &'static str,
    file: &std::path::Path,
    what: &str,
) -> Result<(PathBuf, String, Option<String>), LightError> {
    let (path, bytes) =
        spectrace_sampling::files::read_scene_input_bytes(file, MAX_PHOTOMETRIC_BYTES, what)
            .map_err(|message| LightError::File { light, field: "file", message })?;
    let (text, note) = super::decode_text(&bytes);
    Ok((path, text, note))
}

impl TryFrom<LuminaireRepr> for IesLight {
    type Error = LightError;
    fn try_from(r: LuminaireRepr) -> Result<Self, LightError> {
        const LIGHT: &str = "IesLight";
        if let Some(set) = r.lamp_set {
            return Err(LightError::parameter(
                LIGHT,
                "lamp_set",
                set,
                "is a EULUMDAT key: an IES file has one set of lamps",
            ));
        }
        let (path, text, note) = read_photometric_file(LIGHT, &r.file, "IES file")?;
        let name = path.display().to_string();
        let ies = IesFile::parse(&text, &name).map_err(|e| LightError::File {
            light: LIGHT,
            field: "file",
            message: e.to_string(),
        })?;
        let spd = Luminaire::spectrum(LIGHT, r.spd.clone(), r.cct, None)?;
        let light =
            Self::build(ies, (r.position, r.nadir, r.c0), spd, r.scale(), r.wavelength_sampling)?;
        let notes = note.map(|n| format!("{name}: {n}")).into_iter().collect();
        Ok(Self { repr: Arc::new(r), notes, ..light })
    }
}

impl From<IesLight> for LuminaireRepr {
    fn from(l: IesLight) -> Self {
        Arc::unwrap_or_clone(l.repr)
    }
}

impl IesLight {
    /// A luminaire with the candela table of `ies` (its multiplier and ballast factor applied,
    /// times `multiplier`) at `position`, oriented by `nadir` and `c0` (see the module
    /// documentation), emitting the spectrum `spd`.
    ///
    /// # Errors
    /// [`LightError`] naming `position`, `nadir`, `c0`, `multiplier`, `spd` (an invisible
    /// spectrum) or `file` (a table that cannot describe a distribution).
    pub fn new(
        ies: IesFile,
        position: DVec3,
        nadir: DVec3,
        c0: DVec3,
        spd: Arc<dyn SpectralPowerDistribution>,
        multiplier: f64,
        sampling: WavelengthSampling,
    ) -> Result<Self, LightError> {
        Self::build(ies, (position, nadir, c0), spd, Scale::by(multiplier), sampling)
    }

    fn build(
        ies: IesFile,
        placement: (DVec3, DVec3, DVec3),
        spd: Arc<dyn SpectralPowerDistribution>,
        scale: Scale,
        sampling: WavelengthSampling,
    ) -> Result<Self, LightError> {
        let planes = ies.candela_planes();
        // A type B table's planes turn about its horizontal polar axis, `c0`; its photometric
        // axis, where a type C table's nadir is, is `nadir`.
        // A type A table's planes turn about the vertical axis pointing up: `-nadir`.
        let placement = match ies.photometry {
            super::Photometry::C => placement,
            super::Photometry::B => (placement.0, placement.2, placement.1),
            super::Photometry::A => (placement.0, -placement.1, placement.2),
        };
        let (luminaire, mut repr) = Luminaire::placed(
            "IesLight",
            (&planes, ies.ballast_factor),
            placement,
            spd,
            scale,
            sampling,
        )?;
        // The opening's frame: C0, C90, nadir for type C; for type B the photometric
        // horizontal, the polar axis and the photometric axis (see `IesFile::luminous_opening`):
        // the orientation's C90, nadir and C0 (its nadir is the polar axis, its C0 the
        // photometric axis). A type B table is dark behind its photometric axis.
        let [c0, c90, nadir] = luminaire.orientation.axes();
        // The scene-file form keeps the keys as given (the placement above exchanged or turned
        // them for types B and A).
        match ies.photometry {
            super::Photometry::C => {}
            super::Photometry::B => std::mem::swap(&mut repr.nadir, &mut repr.c0),
            super::Photometry::A => repr.nadir = -repr.nadir,
        }
        let opening = match ies.photometry {
            super::Photometry::C => {
                let (lower, upper) = lit_faces(&ies.vertical, &ies.candela);
                PlacedOpening::new(ies.luminous_opening(), [c0, c90, nadir], lower, upper)
            }
            // Facing the photometric axis (type B) or horizontal (type A), the orientation's
            // C0, as a floodlight's or a lamp's lens.
            super::Photometry::B | super::Photometry::A => {
                PlacedOpening::new(ies.luminous_opening(), [c90, nadir, c0], true, false)
            }
        };
        Ok(Self {
            luminaire,
            repr: Arc::new(repr),
            file: Arc::new(ies),
            notes: Arc::new([]),
            opening,
        })
    }

    /// The parsed file.
    pub fn file(&self) -> &IesFile {
        &self.file
    }

    /// The luminaire's flux against its lamps' (see [`LuminaireLumens`]): lamp lumens
    /// `lamps x lumens per lamp`, no stated light output ratio.
    pub fn lumens_summary(&self) -> LuminaireLumens {
        let lamp_lumens = self.file.lumens_per_lamp.map(|l| l * f64::from(self.file.lamps));
        let file_lumens = self.luminaire.file_lumens;
        LuminaireLumens {
            table_lumens: self.lumens(),
            file_lumens,
            lamp_count: self.file.lamps,
            lamp_lumens,
            light_output_ratio: lamp_lumens.map(|l| file_lumens / l),
            stated_light_output_ratio: None,
        }
    }

    luminaire_accessors!();
}

#[typetag::serde]
impl LightSource for IesLight {
    luminaire_light_source!();
}

/// The distribution of a stored table with every value times `factor`.
fn distribution_of(
    light: &'static str,
    planes: &CandelaPlanes,
    factor: f64,
) -> Result<CandelaDistribution, LightError> {
    let candela: Vec<Vec<f64>> =
        planes.candela.iter().map(|row| row.iter().map(|c| c * factor).collect()).collect();
    CandelaDistribution::new(&planes.horizontal, &planes.vertical, &candela)
        .map_err(|message| LightError::File { light, field: "file", message })
}

// ---------------------------------------------------------------------------------------------

/// A luminaire whose intensity follows a EULUMDAT (`.ldt`) file: its cd/klm table times the
/// lamps' total flux over 1000.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(try_from = "LuminaireRepr", into = "LuminaireRepr")]
pub struct EulumdatLight {
    luminaire: Luminaire,
    repr: Arc<LuminaireRepr>,
    file: Arc<LdtFile>,
    notes: Arc<[String]>,
    opening: PlacedOpening,
    /// The fitted lamp set, 0-based.
    lamp_set: usize,
}

/// The colour temperature (K) of a EULUMDAT lamp set, when its text is a number of kelvin
/// between 1000 and 25000 (`"3000"`, `"3000K"`, `"3000 K"`); `None` for anything else
/// (`"830"`, `"ww"`, empty).
fn lamp_cct(text: &str) -> Option<f64> {
    let t = text.trim();
    let t = t.strip_suffix(['K', 'k']).unwrap_or(t).trim();
    t.replace(',', ".").parse::<f64>().ok().filter(|k| (1000.0..=25000.0).contains(k))
}

impl TryFrom<LuminaireRepr> for EulumdatLight {
    type Error = LightError;
    fn try_from(r: LuminaireRepr) -> Result<Self, LightError> {
        const LIGHT: &str = "EulumdatLight";
        let (path, text, note) = read_photometric_file(LIGHT, &r.file, "EULUMDAT file")?;
        let name = path.display().to_string();
        let ldt = LdtFile::parse(&text, &name).map_err(|e| LightError::File {
            light: LIGHT,
            field: "file",
            message: e.to_string(),
        })?;
        let sets = ldt.lamp_sets.len();
        let set = r.lamp_set.unwrap_or(1);
        if !(1..=sets).contains(&set) {
            return Err(LightError::parameter(
                LIGHT,
                "lamp_set",
                set,
                "must name one of the file's lamp sets, counting from 1",
            ));
        }
        let mut notes: Vec<String> = note.map(|n| format!("{name}: {n}")).into_iter().collect();
        if sets > 1 {
            let fluxes: Vec<String> =
                ldt.lamp_sets.iter().map(|l| format!("{} lm", l.flux)).collect();
            notes.push(format!(
                "{name}: {sets} lamp sets ({}), alternatives as DIALux and Relux read them: set \
                 {set} used (`lamp_set` chooses another)",
                fluxes.join(", ")
            ));
        }
        let default_cct =
            ldt.lamp_sets[set - 1..].first().and_then(|l| lamp_cct(&l.colour_temperature));
        let spd = Luminaire::spectrum(LIGHT, r.spd.clone(), r.cct, default_cct)?;
        let light = Self::build_with(
            ldt,
            set - 1,
            (r.position, r.nadir, r.c0),
            spd,
            r.scale(),
            r.wavelength_sampling,
        )?;
        Ok(Self { repr: Arc::new(r), notes: notes.into(), ..light })
    }
}

impl From<EulumdatLight> for LuminaireRepr {
    fn from(l: EulumdatLight) -> Self {
        Arc::unwrap_or_clone(l.repr)
    }
}

impl EulumdatLight {
    /// A luminaire with the table of `ldt` (absolute: cd/klm times the flux of its first lamp
    /// set / 1000, times `multiplier`) at `position`, oriented by `nadir` and `c0`, emitting
    /// `spd`.
    ///
    /// # Errors
    /// As [`IesLight::new`].
    pub fn new(
        ldt: LdtFile,
        position: DVec3,
        nadir: DVec3,
        c0: DVec3,
        spd: Arc<dyn SpectralPowerDistribution>,
        multiplier: f64,
        sampling: WavelengthSampling,
    ) -> Result<Self, LightError> {
        Self::build_with(ldt, 0, (position, nadir, c0), spd, Scale::by(multiplier), sampling)
    }

    /// With lamp set `set` (0-based) fitted.
    fn build_with(
        ldt: LdtFile,
        set: usize,
        placement: (DVec3, DVec3, DVec3),
        spd: Arc<dyn SpectralPowerDistribution>,
        scale: Scale,
        sampling: WavelengthSampling,
    ) -> Result<Self, LightError> {
        let planes = ldt.candela_planes(set).ok_or_else(|| {
            LightError::parameter("EulumdatLight", "lamp_set", set + 1, "the file has no such set")
        })?;
        let (luminaire, repr) =
            Luminaire::placed("EulumdatLight", (&planes, 1.0), placement, spd, scale, sampling)?;
        let (lower, upper) = lit_faces(&ldt.gamma_angles, &ldt.intensities);
        let opening =
            PlacedOpening::new(ldt.luminous_opening(), luminaire.orientation.axes(), lower, upper);
        let file = Arc::new(ldt);
        Ok(Self {
            luminaire,
            repr: Arc::new(repr),
            file,
            notes: Arc::new([]),
            opening,
            lamp_set: set,
        })
    }

    /// The parsed file.
    pub fn file(&self) -> &LdtFile {
        &self.file
    }

    /// The fitted lamp set (0-based: the scene file's `lamp_set` minus 1).
    pub fn lamp_set(&self) -> usize {
        self.lamp_set
    }

    /// The luminaire's flux against its lamps' (see [`LuminaireLumens`]): lamp lumens the
    /// fitted set's flux, and the file's stated LORL.
    pub fn lumens_summary(&self) -> LuminaireLumens {
        let set = self.file.lamp_sets.get(self.lamp_set);
        let lamp_lumens = set.map(|s| s.flux).filter(|_| !self.file.is_absolute());
        let file_lumens = self.luminaire.file_lumens;
        LuminaireLumens {
            table_lumens: self.lumens(),
            file_lumens,
            lamp_count: set.map_or(0, |s| s.lamps.unsigned_abs()),
            lamp_lumens,
            light_output_ratio: lamp_lumens.map(|l| file_lumens / l),
            stated_light_output_ratio: Some(self.file.light_output_ratio / 100.0),
        }
    }

    luminaire_accessors!();
}

#[typetag::serde]
impl LightSource for EulumdatLight {
    luminaire_light_source!();
}

#[cfg(test)]
mod tests {
    use super::lamp_cct;

    #[test]
    fn lamp_colour_temperatures_are_read_only_when_they_are_kelvin() {
        assert_eq!(lamp_cct("3000"), Some(3000.0));
        assert_eq!(lamp_cct(" 4000 K"), Some(4000.0));
        assert_eq!(lamp_cct("2700k"), Some(2700.0));
        assert_eq!(lamp_cct("830"), None);
        assert_eq!(lamp_cct("warm white"), None);
        assert_eq!(lamp_cct(""), None);
    }
}
