//! The scene every estimator traces, [`LightTracerScene`]: geometry, one material per shape,
//! the lights with the samplers that choose among them, what each shape emits ([`Emitter`]),
//! the camera and the sensors. It answers the questions estimators share: what a hit emits and
//! with what density next-event estimation would have picked it, the first hit of a ray leaving
//! a light's own surface, and what the scene contains (for the effects analysis).

use std::sync::Arc;

use glam::DVec3;
use spectrace_geometry::{Hit, Ray, World};
use spectrace_lights::{LightId, LightSet, LightSource};
use spectrace_materials::{Material, MaterialAt};
use spectrace_spectrum::SpectralPowerDistribution;

use crate::light_sampler::PowerLightSampler;
use crate::next_event::{LightSamplerKind, NextEventLights};
use crate::{PinholeCamera, SamplerKind, SceneFeatures, SensorSet};

/// What a light tracer traces: geometry, one material per shape, the lights and the camera.
#[derive(Debug, Clone)]
pub struct LightTracerScene<'a> {
    /// All shapes, in one BVH.
    pub world: &'a World,
    /// The material of each shape, indexed like the shapes given to the world.
    pub materials: &'a [Arc<dyn Material>],
    /// Per material: whether it varies over its surface ([`Material::texel`]), so that the
    /// others are fetched without asking.
    textured: Vec<bool>,
    /// The lights the beams come from.
    pub lights: &'a LightSet,
    /// The camera that receives the connections.
    pub camera: &'a PinholeCamera,
    /// The spectrum of each light of the set, cached (bundled wavelengths are drawn from the
    /// spectrum of the beam's own light).
    spds: Vec<Arc<dyn SpectralPowerDistribution>>,
    /// The CIE XYZ of each light's spectrum (normalised), cached: a point light seen directly
    /// splats it once per pass.
    xyz: Vec<spectrace_spectrum::Xyz>,
    /// Whether each light's colour varies over its beams ([`LightSource::spectral_factor`]).
    varying: Vec<bool>,
    /// What each shape emits, indexed like `materials` (empty: nothing emits).
    emitters: Vec<Option<Emitter>>,
    /// Some shape emits (so a ray may find light by hitting a surface).
    surfaces_emit: bool,
    /// The shape that is the surface of each light of the set, if any.
    light_shapes: Vec<Option<u32>>,
    /// How many of the shapes are the scene's objects (the first ones); the rest are the
    /// surfaces of area lights, which the effects analysis does not count.
    object_shapes: usize,
    /// Where the integrators' random numbers come from.
    sampler: SamplerKind,
    /// The illuminance sensors the light paths fill (see [`crate::IrradianceSensor`]).
    sensors: Option<&'a SensorSet>,
    /// Fill only the sensors: no connections to the camera (a sensor pass beside a camera
    /// integrator's image).
    sensors_only: bool,
    /// How next-event estimation chooses lights (`auto` until set).
    light_sampler: LightSamplerKind,
    /// Next-event estimation's lights: which it samples at a vertex, and the probability of
    /// an area light's choice; built when first asked for (a light tree over thousands of
    /// lights is not free, and many uses of a scene never ask).
    next_event: std::sync::OnceLock<NextEventLights>,
    /// Every light, by power: the choice of a light vertex given a wavelength (BDPT).
    all_lights: PowerLightSampler,
    /// The delta lights a point can sample: a delta position and a spread of directions (points,
    /// spots), or parallel beams (`parallel_sampled`); sampled one by one, never chosen, since
    /// no ray can hit them.
    delta_lights: Vec<LightId>,
    /// Per light (by id): whether it sends parallel beams (a delta direction) that a point can
    /// sample ([`sampled_towards_its_beams`]): skies and lasers of finite width.
    parallel_sampled: Vec<bool>,
}

/// Light leaving a shape's surface: which light of the set it belongs to, so that camera paths
/// that hit the shape see it and weigh it against next-event estimation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Emitter {
    /// The surface of an area light of the set (see [`spectrace_lights::LightSource::surface`]):
    /// its radiance is the light's [`spectrace_lights::LightSource::emitted_radiance`].
    Light(LightId),
    /// An object made to glow (`objects[i].emission`): a Lambertian emitter of `radiance`
    /// (W m^-2 sr^-1, whole spectrum: times the light's SPD) on the outward side of its
    /// geometric normal (both sides when `two_sided`), sampled uniformly over its `area` (m^2)
    /// by light `light` of the set.
    Object {
        /// The light of the set that emits beams from this shape.
        light: LightId,
        /// Radiance (whole spectrum).
        radiance: f64,
        /// Whether both sides emit.
        two_sided: bool,
        /// Area (m^2).
        area: f64,
    },
}

impl Emitter {
    /// The light of the set this emitter belongs to.
    pub fn light(&self) -> LightId {
        match *self {
            Emitter::Light(id) | Emitter::Object { light: id, .. } => id,
        }
    }
}

impl<'a> LightTracerScene<'a> {
    /// Assembles a scene.
    pub fn new(
        world: &'a World,
        materials: &'a [Arc<dyn Material>],
        lights: &'a LightSet,
        camera: &'a PinholeCamera,
    ) -> Self {
        let spds: Vec<_> = lights.lights().iter().map(|l| l.spd()).collect();
        let xyz = per_spectrum(&spds, spectrace_spectrum::xyz_of);
        let varying = lights.lights().iter().map(|l| !l.uniform_spectrum()).collect();
        let parallel_sampled: Vec<bool> = lights
            .lights()
            .iter()
            .map(|l| {
                l.flags().is_some_and(|f| f.delta_direction)
                    && sampled_towards_its_beams(l.as_ref())
            })
            .collect();
        let delta_lights: Vec<LightId> = lights
            .lights()
            .iter()
            .zip(&parallel_sampled)
            .enumerate()
            .filter(|(_, (l, parallel))| {
                **parallel || l.flags().is_some_and(|f| f.delta_position && !f.delta_direction)
            })
            .map(|(i, _)| LightId(i as u32))
            .collect();
        Self {
            world,
            materials,
            textured: materials.iter().map(|m| m.texel(glam::DVec2::ZERO).is_some()).collect(),
            lights,
            camera,
            spds,
            xyz,
            varying,
            emitters: Vec::new(),
            surfaces_emit: false,
            light_shapes: Vec::new(),
            object_shapes: materials.len(),
            sampler: SamplerKind::Auto,
            sensors: None,
            sensors_only: false,
            light_sampler: LightSamplerKind::Auto,
            next_event: std::sync::OnceLock::new(),
            all_lights: PowerLightSampler::new(lights, |_, _| true),
            delta_lights,
            parallel_sampled,
        }
    }

    /// The same scene with illuminance sensors, which the light tracer fills (through
    /// [`crate::Splat::splat_sensor`], into cells after the film's pixels: see
    /// [`crate::Film::with_sensor_cells`]).
    pub fn with_sensors(mut self, sensors: &'a SensorSet) -> Self {
        self.sensors = (!sensors.is_empty()).then_some(sensors);
        self
    }

    /// The same scene traced for its sensors only: beams are not connected to the camera, so
    /// the image stays black and the sensors fill at less cost.
    pub fn sensors_only(mut self) -> Self {
        self.sensors_only = true;
        self
    }

    /// Whether only the sensors are filled (no connections to the camera).
    pub fn is_sensors_only(&self) -> bool {
        self.sensors_only
    }

    /// Next-event estimation's lights (see [`NextEventLights`]).
    pub fn next_event(&self) -> &NextEventLights {
        self.next_event.get_or_init(|| {
            NextEventLights::new(
                self.light_sampler,
                self.lights,
                &self.delta_lights,
                sampled_by_area,
            )
        })
    }

    /// How next-event estimation chooses lights here: the scene's setting with `auto` resolved
    /// by the count of lights it can sample (without building the light tree).
    pub fn light_sampler_kind(&self) -> LightSamplerKind {
        if let Some(next_event) = self.next_event.get() {
            return next_event.kind();
        }
        // Delta lights and lights sampled by area are disjoint (their flags differ).
        let area = self.lights.lights().iter().filter(|l| sampled_by_area(l.as_ref())).count();
        let count = self.delta_lights.len() + area;
        self.light_sampler.resolve(count)
    }

    /// The same scene with next-event estimation choosing lights as `kind` says.
    pub fn with_light_sampler(mut self, kind: LightSamplerKind) -> Self {
        if kind != self.light_sampler {
            self.light_sampler = kind;
            self.next_event = std::sync::OnceLock::new();
        }
        self
    }

    /// Every light by power, for choices given a wavelength
    /// ([`PowerLightSampler::sample_given`]).
    pub fn all_lights(&self) -> &PowerLightSampler {
        &self.all_lights
    }

    /// The delta lights that a point can sample: those with a delta position (points, spots,
    /// measured luminaires) and the parallel lights whose one beam through a point it can find
    /// (skies, lasers of finite width; `sampled_towards_its_beams`). Next-event estimation
    /// samples each of them at every vertex when it chooses lights by `each`.
    pub fn delta_lights(&self) -> &[LightId] {
        &self.delta_lights
    }

    /// Whether light `id` sends parallel beams that a point can sample (a sky, a laser of
    /// finite width): next-event estimation reaches it along the one beam through the point.
    pub fn parallel_sampled(&self, id: LightId) -> bool {
        self.parallel_sampled.get(id.0 as usize).copied().unwrap_or(false)
    }

    /// The scene's sensors (none if it has none).
    pub fn sensors(&self) -> Option<&'a SensorSet> {
        self.sensors
    }

    /// The same scene, rendered with random numbers from `sampler`.
    pub fn with_sampler(mut self, sampler: SamplerKind) -> Self {
        self.sampler = sampler;
        self
    }

    /// Where the integrators' random numbers come from.
    pub fn sampler(&self) -> SamplerKind {
        self.sampler
    }

    /// The same scene where shape `i` emits `emitters[i]` (missing entries emit nothing), and
    /// only the first `object_shapes` shapes are the scene's objects (the rest are the surfaces
    /// of area lights).
    pub fn with_emitters(mut self, emitters: Vec<Option<Emitter>>, object_shapes: usize) -> Self {
        let mut light_shapes = vec![None; self.lights.lights().len()];
        for (shape, e) in emitters.iter().enumerate() {
            if let Some(e) = e
                && let Some(slot) = light_shapes.get_mut(e.light().0 as usize)
            {
                *slot = Some(shape as u32);
            }
        }
        self.light_shapes = light_shapes;
        self.surfaces_emit = emitters.iter().any(Option::is_some);
        self.emitters = emitters;
        self.object_shapes = object_shapes.min(self.materials.len());
        self
    }

    /// The first hit of a ray that starts on the surface of light `light` (a beam's emission
    /// point): a hit of the light's own surface within rounding distance of the start is the
    /// start itself, and is skipped by continuing from it with the geometry's robust offset.
    pub fn intersect_from_light(&self, ray: &Ray, light: LightId, t_max: f64) -> Option<Hit> {
        let hit = self.world.intersect(ray, t_max)?;
        let own = self.light_shapes.get(light.0 as usize).copied().flatten();
        let scale = 1.0 + ray.origin.abs().max_element();
        if own == Some(hit.primitive) && hit.t <= 1e-9 * scale {
            let next = hit.spawn_ray(ray.direction);
            let travelled = (next.origin - ray.origin).length();
            return self.world.intersect(&next, t_max - travelled);
        }
        Some(hit)
    }

    /// Whether any shape emits (an area light's surface or a glowing object): when none does,
    /// a ray traced only for the emission it may hit finds nothing.
    #[inline]
    pub fn surfaces_emit(&self) -> bool {
        self.surfaces_emit
    }

    /// What shape `primitive` emits.
    #[inline]
    pub fn emitter(&self, primitive: u32) -> Option<&Emitter> {
        self.emitters.get(primitive as usize).and_then(Option::as_ref)
    }

    /// Whether light `id`'s colour varies over its beams, so that its spectral values need
    /// [`Self::light_spectra`] rather than its SPD alone.
    #[inline]
    pub fn spectrum_varies(&self, id: LightId) -> bool {
        self.varying.get(id.0 as usize).copied().unwrap_or(false)
    }

    /// Light `id`'s spectrum at each of the [`crate::HERO`] wavelengths `lambdas` for light
    /// leaving `position` along `direction`: its SPD times its
    /// [`LightSource::spectral_factors`] (the SPD alone for a light whose colour does not vary;
    /// one lookup of a varying light's colour for all the wavelengths); 0 for an unknown light.
    #[inline]
    pub fn light_spectra(
        &self,
        id: LightId,
        position: DVec3,
        direction: DVec3,
        lambdas: &[f64; crate::HERO],
    ) -> [f64; crate::HERO] {
        let Some(spd) = self.spds.get(id.0 as usize) else { return [0.0; crate::HERO] };
        let mut values = lambdas.map(|l| spd.value(l));
        if self.spectrum_varies(id) {
            let mut factors = [0.0; crate::HERO];
            if let Some(l) = self.lights.light(id) {
                l.spectral_factors(position, direction, lambdas, &mut factors);
            }
            for (v, f) in values.iter_mut().zip(factors) {
                *v *= f;
            }
        }
        values
    }

    /// The CIE XYZ of light `id`'s spectrum (its colour when seen directly); zero for an
    /// unknown light.
    #[inline]
    pub fn light_xyz(&self, id: LightId) -> spectrace_spectrum::Xyz {
        self.xyz.get(id.0 as usize).copied().unwrap_or_default()
    }

    /// The spectrum of light `id` of the set.
    #[inline]
    pub fn light_spd(&self, id: LightId) -> Option<&Arc<dyn SpectralPowerDistribution>> {
        self.spds.get(id.0 as usize)
    }

    /// The material at `hit`, resolved at its `uv` when textured; `None` for a shape without
    /// one.
    #[inline]
    pub fn material_at(&self, hit: &Hit) -> Option<MaterialAt<'a>> {
        let i = hit.primitive as usize;
        let m = self.materials.get(i)?.as_ref();
        Some(if self.textured[i] { MaterialAt::new(m, hit.uv) } else { MaterialAt::Shared(m) })
    }

    /// Radiance (whole spectrum; times the light's SPD) leaving `hit` towards the unit
    /// `direction`, with the light it belongs to; `None` where the shape does not emit.
    pub fn emitted(&self, hit: &Hit, direction: DVec3) -> Option<(LightId, f64)> {
        let emitter = self.emitter(hit.primitive)?;
        let radiance = match *emitter {
            Emitter::Light(id) => self.lights.light(id)?.emitted_radiance(hit.point, direction),
            Emitter::Object { radiance, two_sided, .. } => {
                let c = direction.dot(hit.geometric_normal);
                if c > 0.0 || (two_sided && c < 0.0) { radiance } else { 0.0 }
            }
        };
        (radiance > 0.0).then_some((emitter.light(), radiance))
    }

    /// Solid-angle density (at `receiver`, a point and its shading normal) with which
    /// next-event estimation (a light chosen by [`Self::next_event`], then a point by its
    /// `sample_towards`) picks the emitting point `hit`; 0 where the shape does not emit or the
    /// light is not among those it samples.
    pub fn emitter_pdf(&self, (receiver, normal): (DVec3, DVec3), hit: &Hit) -> f64 {
        let Some(emitter) = self.emitter(hit.primitive) else { return 0.0 };
        let pmf = self.next_event().pmf((receiver, normal), emitter.light());
        if !(pmf > 0.0) {
            return 0.0;
        }
        match *emitter {
            Emitter::Light(id) => {
                self.lights.light(id).map_or(0.0, |l| pmf * l.pdf_towards(receiver, hit.point))
            }
            Emitter::Object { area, .. } => {
                let to = receiver - hit.point;
                let d2 = to.length_squared();
                let cos = (to.dot(hit.geometric_normal) / d2.sqrt()).abs();
                if cos > 0.0 && area > 0.0 { pmf * d2 / (area * cos) } else { 0.0 }
            }
        }
    }

    /// What the scene contains, for the effects analysis. A light with a delta direction counts
    /// as reachable from camera paths when it can be sampled towards a point on one of its own
    /// beams (`sampled_towards_its_beams`).
    pub fn features(&self, shapes_non_convex: &[bool]) -> SceneFeatures {
        let mut f = SceneFeatures {
            light_spectra_vary: self.lights.lights().iter().any(|l| !l.uniform_spectrum()),
            ..SceneFeatures::default()
        };
        let has_lines = per_spectrum(&self.spds, |spd| {
            let (lo, hi) = spd.range();
            !(hi > lo)
                || (spectrace_spectrum::integrate_panels(
                    &|l| spd.value(l),
                    lo,
                    hi,
                    &spd.breakpoints(),
                ) - 1.0)
                    .abs()
                    > 1e-6
        });
        for ((i, light), lines) in self.lights.lights().iter().enumerate().zip(has_lines) {
            match light.flags() {
                None => f.beam_only_lights += 1,
                Some(flags) if flags.delta_direction => {
                    f.delta_direction_lights += 1;
                    f.unreachable_lights += usize::from(!self.parallel_sampled(LightId(i as u32)));
                }
                Some(flags) if flags.delta_position => f.delta_position_lights += 1,
                Some(_) => f.area_lights += 1,
            }
            f.line_spectra |= lines;
        }
        for (i, m) in self.materials.iter().enumerate().take(self.object_shapes) {
            f.dispersive |= m.is_dispersive();
            f.fluorescent |= m.fluorescence().is_some();
            if m.is_specular() {
                f.specular = true;
            } else {
                f.non_specular_shapes += 1;
                f.non_convex_non_specular |= shapes_non_convex.get(i).copied().unwrap_or(true);
            }
        }
        f
    }
}

/// `f` of each spectrum of `spds`, computed once per spectrum object (lights with equal
/// spectra share one: see the renderer's scene assembly).
fn per_spectrum<T: Copy>(
    spds: &[Arc<dyn SpectralPowerDistribution>],
    f: impl Fn(&dyn SpectralPowerDistribution) -> T,
) -> Vec<T> {
    let mut seen: std::collections::HashMap<*const (), T> = std::collections::HashMap::new();
    spds.iter()
        .map(|spd| *seen.entry(Arc::as_ptr(spd) as *const ()).or_insert_with(|| f(spd.as_ref())))
        .collect()
}

/// Whether next-event estimation samples `light` by area: neither its position nor its
/// direction is a delta.
fn sampled_by_area(light: &dyn LightSource) -> bool {
    light.flags().is_some_and(|f| !f.delta_position && !f.delta_direction)
}

/// Whether `light` gives a next-event sample ([`LightSource::sample_towards`]) to a point that
/// one of its own beams passes through: the middle emission ray
/// ([`LightSource::sample_emission`] of uniforms 1/2), a distance of `1 + |origin|` along it
/// (far enough to leave the origin in floating point). False for lights that draw no emission
/// ray or return no sample there (a laser of zero width, a plugin that only generates beams).
fn sampled_towards_its_beams(light: &dyn LightSource) -> bool {
    light.sample_emission([0.5; 4]).is_some_and(|e| {
        let receiver = e.position + e.direction * (1.0 + e.position.length());
        light.sample_towards(receiver, [0.5; 2]).is_some()
    })
}
