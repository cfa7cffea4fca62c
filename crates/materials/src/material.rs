//! The [`Material`] trait (the seed's material function, section 3.5) and the records it takes
//! and returns: [`Incoming`], [`Scattered`], [`ScatterKind`], [`Transport`].

use std::fmt::Debug;

use glam::DVec3;

use crate::Fluorescent;

/// A beam arriving at a surface, as the material sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Incoming {
    /// Unit direction of travel of the beam, *towards* the surface.
    pub direction: DVec3,
    /// Unit shading normal, on the side the geometry defines as outside (for a [`Dielectric`]
    /// the side where the index is 1; the beam is entering when `direction . normal < 0`).
    ///
    /// [`Dielectric`]: crate::Dielectric
    pub normal: DVec3,
    /// Wavelength of the beam (nm).
    pub lambda: f64,
}

/// Which kind of lobe produced a [`Scattered`] beam.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ScatterKind {
    /// A lobe with a density: the direction was importance-sampled, `pdf > 0`.
    Diffuse,
    /// A Dirac delta lobe (mirror reflection, Fresnel reflection or refraction): `pdf` is 0 and
    /// [`Material::eval`] is 0 for every pair of directions.
    Specular,
}

/// What a path carries, which decides how refraction scales the weight (see
/// [`Material::scatter_with`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Transport {
    /// Flux (power) from a light, or importance: the light tracer. Refraction does not rescale
    /// the weight. The default, and what [`Material::scatter`] does.
    #[default]
    Importance,
    /// Radiance, on a path traced from the camera: refraction from index `n_i` into `n_t`
    /// (as the *path* travels) multiplies the weight by `(n_i / n_t)^2`, the change of radiance
    /// across the boundary (radiance over n^2 is what is conserved).
    Radiance,
}

/// A beam leaving a surface: the outgoing half of the seed's material function.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scattered {
    /// Unit direction of the outgoing beam, away from the surface.
    pub direction: DVec3,
    /// Multiply the beam's `scale` by this: `f |cos| / pdf` of the sampled direction (the
    /// reflectance for a Lambertian or a mirror; 1 for the chosen branch of a dielectric, times
    /// its transmittance on refraction). Finite and >= 0.
    pub weight: f64,
    /// Which kind of lobe was sampled.
    pub kind: ScatterKind,
    /// Solid-angle density of `direction` (sr^-1); 0 for a delta lobe.
    pub pdf: f64,
    /// Relative index of refraction across the boundary as the path crossed it, `n_t / n_i`
    /// (after over before); 1 for a reflection.
    pub eta: f64,
    /// `true` if the beam went through the surface (refraction), `false` if it was reflected.
    pub transmission: bool,
}

/// What a bundle of wavelengths sharing one path did at a surface
/// ([`Material::scatter_bundle`]): the one outgoing direction and the lobe it came from; the
/// per-wavelength weights are updated in place.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BundleScattered {
    /// Unit direction of the outgoing path, away from the surface.
    pub direction: DVec3,
    /// Which kind of lobe was sampled.
    pub kind: ScatterKind,
    /// Solid-angle density of `direction` (sr^-1) for the first live wavelength; 0 for a delta
    /// lobe.
    pub pdf: f64,
    /// `n_t / n_i` across the boundary for the first live wavelength (1 for a reflection).
    pub eta: f64,
    /// `true` if the path went through the surface.
    pub transmission: bool,
}

/// What a surface does to a beam (seed 3.5): scatter it into a new direction with an updated
/// weight, or absorb it.
///
/// # Conventions
/// * [`scatter`](Self::scatter) follows the beam: [`Incoming::direction`] travels *towards* the
///   surface, [`Scattered::direction`] *away* from it.
/// * [`eval`](Self::eval) and [`pdf`](Self::pdf) use pbrt's convention: both directions point
///   *away* from the surface, `wi` towards where the light came from, `wo` towards where it goes
///   (the viewer). A beam that arrived along `d` has `wi = -d`. All vectors are unit.
/// * Uniforms `u` are in `[0, 1)`; values outside (or NaN) are clamped, never a panic.
/// * Nothing here applies Russian roulette: an absorbing surface returns its weight, and `None`
///   only when the weight would be exactly 0.
///
/// The trait is typetag-serialisable: a scene file names a material by its type,
/// `{"type": "Diffuse", "reflectance": 0.8}`, and another crate can add material types.
#[typetag::serde(tag = "type")]
pub trait Material: Send + Sync + Debug {
    /// The seed's material function for a path that carries flux from a light
    /// ([`Transport::Importance`]): the outgoing beam, or `None` if the beam is absorbed.
    /// `u` are three uniforms in `[0, 1)` (lobe choice first, then two for the direction).
    fn scatter(&self, incoming: &Incoming, u: [f64; 3]) -> Option<Scattered>;

    /// [`scatter`](Self::scatter) for a path carrying `transport`. Only refraction differs
    /// (see [`Transport::Radiance`]); the default ignores `transport`, which is right for every
    /// material that does not refract.
    fn scatter_with(
        &self,
        incoming: &Incoming,
        u: [f64; 3],
        transport: Transport,
    ) -> Option<Scattered> {
        let _ = transport;
        self.scatter(incoming, u)
    }

    /// The BSDF `f(wi, wo)` (sr^-1) for light arriving from `wi` and leaving towards `wo` (both
    /// unit, pointing away from the surface), at wavelength `lambda` (nm); 0 for delta lobes.
    /// A light tracer that connects a hit to the camera adds `weight * f * |wo . normal|`
    /// times the camera's importance.
    fn eval(&self, wi: DVec3, wo: DVec3, normal: DVec3, lambda: f64) -> f64;

    /// [`eval`](Self::eval) for a path carrying `transport`. Because `eval` always takes its
    /// directions in the order light flows (`wi` towards the light, `wo` towards the viewer),
    /// the value is the radiance BSDF `f(wi -> wo)` for both transports: the adjoint a light
    /// path needs is this same value, read with the light's order rather than the path's (for
    /// transmission `f(wi -> wo) / n_o^2 = f(wo -> wi) / n_i^2`, so swapping the arguments is
    /// what would change it). Every material here returns `eval`; the parameter is kept for
    /// materials whose value depends on what the path carries.
    fn eval_with(
        &self,
        wi: DVec3,
        wo: DVec3,
        normal: DVec3,
        lambda: f64,
        transport: Transport,
    ) -> f64 {
        let _ = transport;
        self.eval(wi, wo, normal, lambda)
    }

    /// Scatters a *bundle*: several wavelengths `lambdas` travelling along one path (towards the
    /// surface along `direction`), with weights `weights` (same length), using the same uniforms
    /// `u` for all. Live wavelengths (weight `> 0`) that follow the returned direction have their
    /// weight multiplied by their own [`Scattered::weight`]; a wavelength the surface absorbs, or
    /// one that would leave in another direction (dispersion), gets weight 0; dead wavelengths
    /// are left alone. `None` when no live wavelength scatters.
    ///
    /// The first live wavelength chooses the lobe and the direction. The default calls
    /// [`scatter_with`](Self::scatter_with) once per live wavelength; materials whose direction
    /// does not depend on the wavelength override it to sample once per bounce (same result,
    /// bit for bit).
    fn scatter_bundle(
        &self,
        direction: DVec3,
        normal: DVec3,
        lambdas: &[f64],
        weights: &mut [f64],
        u: [f64; 3],
        transport: Transport,
    ) -> Option<BundleScattered> {
        scatter_each(self, direction, normal, lambdas, weights, u, transport)
    }

    /// [`eval_with`](Self::eval_with) at every wavelength of `lambdas`, written to `out` (same
    /// length): one evaluation per connection for a bundle. The default loops; materials with a
    /// wavelength-independent lobe shape override it to compute the geometry once.
    fn eval_bundle(
        &self,
        wi: DVec3,
        wo: DVec3,
        normal: DVec3,
        lambdas: &[f64],
        transport: Transport,
        out: &mut [f64],
    ) {
        for (o, &lambda) in out.iter_mut().zip(lambdas) {
            *o = self.eval_with(wi, wo, normal, lambda, transport);
        }
    }

    /// Solid-angle density (sr^-1) with which [`scatter`](Self::scatter), given a beam arriving
    /// from `wi` (`Incoming::direction = -wi`), returns `wo`; 0 for delta lobes. The density of
    /// the reverse choice is `pdf(wo, wi, ...)`.
    fn pdf(&self, wi: DVec3, wo: DVec3, normal: DVec3, lambda: f64) -> f64;

    /// `true` if every lobe is a Dirac delta (mirror, dielectric): [`eval`](Self::eval) and
    /// [`pdf`](Self::pdf) are then 0 everywhere and a connection through the surface is useless.
    fn is_specular(&self) -> bool;

    /// `true` if the directions this material scatters into depend on the wavelength (a
    /// dispersive index of refraction): paths through it cannot be shared between wavelengths.
    fn is_dispersive(&self) -> bool;

    /// The material's re-emission at other wavelengths (fluorescence), or `None` (the default)
    /// for a material that keeps every wavelength. When `Some`, [`scatter`](Self::scatter),
    /// [`eval`](Self::eval) and [`pdf`](Self::pdf) describe only the *elastic* part, and an
    /// integrator first chooses between it and re-emission with
    /// [`Fluorescent::choose_forward`] or [`Fluorescent::choose_adjoint`]; the effects
    /// analysis asks this to know whether a scene fluoresces.
    fn fluorescence(&self) -> Option<&Fluorescent> {
        None
    }

    /// The material at the surface point with texture coordinates `uv`, for a material that
    /// varies over its surface (a [`crate::Textured`] one); `None` (the default) for one that is
    /// the same everywhere. Renderers resolve it once per hit with [`crate::MaterialAt::new`].
    fn texel(&self, uv: glam::DVec2) -> Option<crate::Texel> {
        let _ = uv;
        None
    }
}

/// [`Material::scatter_bundle`] done the general way: [`Material::scatter_with`] once per live
/// wavelength, keeping those that leave along the first one's direction (the trait's default;
/// exposed so materials that override it for some parameters can fall back to it).
pub fn scatter_each<M: Material + ?Sized>(
    material: &M,
    direction: DVec3,
    normal: DVec3,
    lambdas: &[f64],
    weights: &mut [f64],
    u: [f64; 3],
    transport: Transport,
) -> Option<BundleScattered> {
    let mut out: Option<BundleScattered> = None;
    for (w, &lambda) in weights.iter_mut().zip(lambdas) {
        if !(*w > 0.0) {
            continue;
        }
        let incoming = Incoming { direction, normal, lambda };
        match material.scatter_with(&incoming, u, transport) {
            Some(s) => match out {
                None => {
                    out = Some(BundleScattered {
                        direction: s.direction,
                        kind: s.kind,
                        pdf: s.pdf,
                        eta: s.eta,
                        transmission: s.transmission,
                    });
                    *w *= s.weight;
                }
                Some(b) if (s.direction - b.direction).length_squared() < 1e-20 => {
                    *w *= s.weight;
                }
                Some(_) => *w = 0.0,
            },
            None => *w = 0.0,
        }
    }
    out
}

/// Multiplies each live weight (`> 0`) of a bundle by `factor(lambda)`, setting it to 0 where the
/// factor is not positive (the wavelength is absorbed); dead weights are left alone. Returns
/// whether any wavelength is still live: the shared step of every `scatter_bundle` whose
/// direction does not depend on the wavelength.
pub fn scale_bundle(lambdas: &[f64], weights: &mut [f64], factor: impl Fn(f64) -> f64) -> bool {
    let mut any = false;
    for (w, &lambda) in weights.iter_mut().zip(lambdas) {
        if *w > 0.0 {
            let f = factor(lambda);
            if f > 0.0 {
                *w *= f;
                any = true;
            } else {
                *w = 0.0;
            }
        }
    }
    any
}
