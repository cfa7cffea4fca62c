//! BDPT's strategies (pbrt's `ConnectBDPT`), one function each: a camera subpath that hits an
//! emitter (`s = 0`), a light vertex seen by the camera (`t = 1`), next-event estimation
//! (`s = 1`) and two surface vertices joined by a shadow ray (`s, t >= 2`); then the MIS weight.

use spectrace_materials::Transport;

use super::MisVertex;
use super::mis::{Sampled, build_mis_path, mis_weight};
use super::vertex::{
    Lanes, LightEnd, NO_SAMPLES, Vertex, VertexKind, Wavelengths, light_normal, scaled, times,
    useful,
};
use super::{Bdpt, Strategy};
use crate::integrators::common::{
    End, connect_light_to_camera, connect_surface_to_camera, importance_cosine, sample_light,
    unoccluded,
};
use crate::light_sampler::LightSampler;

/// What one strategy gives: the value per wavelength (film units before the colour matching
/// and the wavelengths' film weights), and the pixel for a `t = 1` splat (`None`: the sample's
/// own pixel).
pub(super) struct Contribution {
    pub value: Lanes,
    pub raster: Option<(u32, u32)>,
    /// With one wavelength, the one a `t = 1` splat is recorded at (the light subpath's, which
    /// differs from the sample's beyond a re-emission).
    pub lambda: f64,
    /// The MIS weight applied (included in `value`).
    #[cfg_attr(not(test), allow(dead_code))]
    pub weight: f64,
    /// Whether the path's light cannot be hit by a camera path (for tests of the weights).
    #[cfg_attr(not(test), allow(dead_code))]
    pub light_is_delta: bool,
}

/// A strategy's unweighted value and what its MIS weight needs.
struct Joined {
    value: Lanes,
    raster: Option<(u32, u32)>,
    lambda: f64,
    /// The light the path starts on.
    end: LightEnd,
    /// The vertices the strategy sampled afresh.
    light: Option<Vertex>,
    camera: Option<Vertex>,
}

impl Joined {
    /// A value at the sample's own pixel and wavelength, with no fresh vertex.
    fn at_pixel(value: Lanes, wl: &Wavelengths, end: LightEnd) -> Self {
        Self { value, raster: None, lambda: wl.lambda(), end, light: None, camera: None }
    }
}

impl Bdpt<'_> {
    /// Strategy `strategy` for the sample's subpaths, weighted by [`mis_weight`] (into `mis`);
    /// `None` when it gives nothing.
    pub(super) fn connect(
        &self,
        strategy: Strategy<'_>,
        beam_light: &LightEnd,
        wl: &Wavelengths,
        camera_strategies: bool,
        mis: &mut Vec<MisVertex>,
    ) -> Option<Contribution> {
        let Strategy { light, camera, s, t } = strategy;
        if (s >= 2 && light[s - 1].delta) || (s > 0 && t > 1 && camera[t - 1].delta) {
            return None;
        }
        let joined = match (s, t) {
            (0, _) => self.hit_emitter(strategy, wl)?,
            (_, 1) => self.see_from_camera(strategy, beam_light, wl)?,
            (1, _) => self.sample_light_vertex(strategy, wl)?,
            _ => self.join_surfaces(strategy, beam_light, wl)?,
        };
        if !useful(&joined.value[..wl.n]) {
            return None;
        }
        let fluoresced = s > 0 && light[s - 1].fluoresced;
        let (weight, light_is_delta) = if camera_strategies && !fluoresced {
            let sampled = Sampled { light: joined.light.as_ref(), camera: joined.camera.as_ref() };
            let delta = build_mis_path(self, strategy, sampled, &joined.end, mis);
            (mis_weight(mis, s, delta), delta)
        } else {
            // Without camera strategies, or for a path that fluoresced on its light subpath, the
            // connection to the camera is the only strategy that makes the path.
            (1.0, true)
        };
        Some(Contribution {
            value: scaled(joined.value, weight),
            raster: joined.raster,
            lambda: joined.lambda,
            weight,
            light_is_delta,
        })
    }

    /// `s = 0`: the camera subpath hits an emitter.
    fn hit_emitter(&self, st: Strategy<'_>, wl: &Wavelengths) -> Option<Joined> {
        let pt = &st.camera[st.t - 1];
        let VertexKind::Surface(hit) = pt.kind else { return None };
        let wo = (st.camera[st.t - 2].point - pt.point).normalize();
        let (id, le) = self.scene.emitted(&hit, wo)?;
        self.scene.light_spd(id)?;
        let end = self.light_end(id, wl)?;
        // One wavelength: the density it was drawn with divides; hero wavelengths: their film
        // weights do.
        let spectrum = self.scene.light_spectra(id, hit.point, wo, &wl.lambdas);
        let emitted: Lanes =
            std::array::from_fn(|j| if j < wl.n { le * spectrum[j] / wl.density } else { 0.0 });
        Some(Joined::at_pixel(times(pt.beta, emitted), wl, end))
    }

    /// `t = 1`: a light vertex seen by the camera, through a point of the lens sampled towards
    /// it with the vertex's own lens uniforms (the pinhole for a pinhole camera).
    fn see_from_camera(
        &self,
        st: Strategy<'_>,
        beam_light: &LightEnd,
        wl: &Wavelengths,
    ) -> Option<Joined> {
        let qs = &st.light[st.s - 1];
        let (raster, lens, value, lambda) = match qs.kind {
            VertexKind::Light(id) => {
                if beam_light.flags.delta_direction {
                    return None;
                }
                let (seen, density) = connect_light_to_camera(self.scene, id, qs.point, qs.u)?;
                // A light whose colour varies: its spectrum towards the camera, relative to its
                // SPD (the beam's wavelengths were drawn from the SPD).
                let value: Lanes = std::array::from_fn(|j| {
                    let factor = if self.scene.spectrum_varies(id) && j < wl.n {
                        self.scene.lights.light(id).map_or(0.0, |l| {
                            l.spectral_factor(qs.point, seen.to_camera, wl.lambdas[j])
                        })
                    } else {
                        1.0
                    };
                    qs.beta[j] * density * factor
                });
                ((seen.x, seen.y), seen.lens, value, wl.lambda())
            }
            VertexKind::Surface(hit) => {
                let material = self.lobe(qs, &hit)?;
                let wi = (st.light[st.s - 2].point - qs.point).normalize();
                let mut f = [0.0; crate::HERO];
                let lambdas = wl.at(qs);
                let seen = connect_surface_to_camera(
                    self.scene, &hit, &*material, wi, lambdas, qs.u, &mut f,
                )?;
                ((seen.x, seen.y), seen.lens, times(qs.beta, f), qs.lambda)
            }
            VertexKind::Camera => return None,
        };
        Some(Joined {
            value,
            raster: Some(raster),
            lambda,
            end: *beam_light,
            light: None,
            camera: Some(Vertex::camera(lens, qs.lambda)),
        })
    }

    /// `s = 1`: next-event estimation, a light chosen given the wavelength by the scene's
    /// light sampler and a point on it, with the camera vertex's own light uniforms.
    fn sample_light_vertex(&self, st: Strategy<'_>, wl: &Wavelengths) -> Option<Joined> {
        let scene = self.scene;
        let pt = &st.camera[st.t - 1];
        let VertexKind::Surface(hit) = pt.kind else { return None };
        let chosen = if wl.is_hero() {
            LightSampler::sample(scene.all_lights(), pt.u[0])?
        } else {
            scene.all_lights().sample_given(pt.u[0], wl.lambda())?
        };
        let end = self.light_end(chosen.id, wl)?;
        let sample = sample_light(scene, chosen.id, pt.point, [chosen.u, pt.u[1]])?;
        let pmf = scene.all_lights().pmf(chosen.id);
        if !(pmf > 0.0 && end.pmf > 0.0) {
            return None;
        }
        let wi = -sample.direction;
        let to = st.camera[st.t - 2].point;
        let f = self.bsdf(pt, wl, sample.position, to, Transport::Radiance);
        let cos = wi.dot(hit.shading_normal).abs();
        let visible =
            || unoccluded(scene, End::Surface(&hit), End::Light(chosen.id, sample.position));
        if !(useful(&f[..wl.n]) && cos > 0.0 && visible()) {
            return None;
        }
        let geometry = cos * sample.intensity / (sample.distance * sample.distance * pmf);
        // One wavelength: the light was chosen given it, and its spectrum cancels the density
        // the wavelength was drawn with. Hero wavelengths: chosen by power, times its spectrum.
        let (from, towards) = (sample.position, sample.direction);
        let spectrum = if wl.is_hero() {
            scene.light_spd(chosen.id)?;
            scene.light_spectra(chosen.id, from, towards, &wl.lambdas)
        } else if scene.spectrum_varies(chosen.id) {
            // Its spectrum that way relative to its SPD, which the choice cancelled.
            let light = scene.lights.light(chosen.id)?;
            let mut m = [1.0; crate::HERO];
            m[0] = light.spectral_factor(from, towards, wl.lambda());
            m
        } else {
            [1.0; crate::HERO]
        };
        let value = scaled(times(times(pt.beta, f), spectrum), geometry);
        let (pdf_pos, _) = self.light_pdfs(chosen.id, sample.position, sample.direction);
        let source = scene.lights.light(chosen.id)?;
        let ng = light_normal(source, sample.position);
        let kind = VertexKind::Light(chosen.id);
        let lambda = wl.lambda();
        let mut vertex =
            Vertex::at(kind, sample.position, ng, [0.0; crate::HERO], lambda, NO_SAMPLES);
        vertex.delta = end.first_vertex_delta();
        vertex.pdf_fwd = end.pmf * pdf_pos;
        Some(Joined { light: Some(vertex), ..Joined::at_pixel(value, wl, end) })
    }

    /// `s, t >= 2`: two surface vertices joined by a shadow ray.
    fn join_surfaces(
        &self,
        st: Strategy<'_>,
        beam_light: &LightEnd,
        wl: &Wavelengths,
    ) -> Option<Joined> {
        let (qs, pt) = (&st.light[st.s - 1], &st.camera[st.t - 1]);
        let (VertexKind::Surface(hq), VertexKind::Surface(hp)) = (qs.kind, pt.kind) else {
            return None;
        };
        if qs.fluoresced {
            // Beyond a re-emission the light subpath travels at another wavelength than the
            // camera subpath: only its connection to the camera (`t = 1`) joins them.
            return None;
        }
        let q_prev = st.light[st.s - 2].point;
        let f_light = self.bsdf(qs, wl, q_prev, pt.point, Transport::Importance);
        let p_prev = st.camera[st.t - 2].point;
        let f_camera = self.bsdf(pt, wl, qs.point, p_prev, Transport::Radiance);
        if !(useful(&f_light[..wl.n]) && useful(&f_camera[..wl.n])) {
            return None;
        }
        let d = pt.point - qs.point;
        let d2 = d.length_squared();
        if !(d2 > 0.0) {
            return None;
        }
        let w = d / d2.sqrt();
        // The light side's cosine with the shading-normal correction of importance transport.
        let cos_q = importance_cosine(&hq, (q_prev - qs.point).normalize(), w)?;
        let cos_p = w.dot(hp.shading_normal).abs();
        if !unoccluded(self.scene, End::Surface(&hq), End::Surface(&hp)) {
            return None;
        }
        let light_side = scaled(times(qs.beta, f_light), cos_q * cos_p / d2);
        let value = times(times(light_side, f_camera), pt.beta);
        Some(Joined::at_pixel(value, wl, *beam_light))
    }
}
