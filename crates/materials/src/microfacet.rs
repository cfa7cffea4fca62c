//! The shared core of every rough material: the [`Microfacet`] trait (what a material needs of a
//! distribution of normals: `D`, Smith's `Lambda`, visible-normal sampling, and the masking,
//! shadowing and density that follow from them), the scene-file choice [`Distribution`], and the
//! GGX (Trowbridge-Reitz) distribution; Beckmann's is in `beckmann.rs` ([`Beckmann`]).
//!
//! All vectors here are in the *local* shading frame: the macro-surface normal is `+z`, the first
//! tangent `+x` (the direction `alpha_x` acts along), all unit. Following the conventions of
//! Heitz, "Understanding the masking-shadowing function in microfacet-based BRDFs" (JCGT 2014)
//! and "Sampling the GGX distribution of visible normals" (JCGT 2018):
//!
//! | function | formula |
//! |---|---|
//! | [`Ggx::d`] | `D(m) = 1 / (pi ax ay (mx^2/ax^2 + my^2/ay^2 + mz^2)^2)` for `mz > 0`, else 0 |
//! | [`Ggx::lambda`] | `Lambda(w) = (sqrt(1 + (ax^2 wx^2 + ay^2 wy^2) / wz^2) - 1) / 2` |
//! | [`Ggx::g1`] | `G1(w) = 1 / (1 + Lambda(w))` (Smith masking) |
//! | [`Ggx::g`] | `G(wo, wi) = 1 / (1 + Lambda(wo) + Lambda(wi))` (height-correlated masking-shadowing) |
//! | [`Ggx::pdf_visible`] | `D_w(m) = G1(w) max(0, w.m) D(m) / |wz|` (normalised over `m`) |
//! | [`Ggx::sample_visible`] | draws `m` with density `D_w(m)` (Heitz 2018, exact) |
//!
//! `alpha` is the GGX roughness itself, with no remapping (`alpha` of Mitsuba 3, the unremapped
//! roughness of pbrt-v4). A distribution with both alphas below [`SMOOTH_ALPHA`] is *effectively
//! smooth*: materials then use their delta (smooth) lobes instead, so roughness 0 is the smooth
//! material and never a division by zero.

use std::f64::consts::PI;

use glam::DVec3;

use serde::{Deserialize, Serialize};

use crate::{Beckmann, MaterialError};

/// Below this alpha (in both directions) a surface is rendered as perfectly smooth: the GGX
/// lobe is then narrower than `1e-3` rad, where its `D` would overflow towards a delta.
pub const SMOOTH_ALPHA: f64 = 1e-3;

/// A microfacet distribution of normals with Smith shadowing: what a rough material needs of
/// it. Implementors give `D`, `Lambda` and a visible-normal sampler; masking, shadowing and the
/// sampler's density follow from them.
pub trait Microfacet {
    /// The distribution of normals `D(m)` (sr^-1, projected so that `integral D(m) m.z dm = 1`).
    fn d(&self, m: DVec3) -> f64;

    /// Smith's `Lambda(w)`; 0 at normal incidence, `f64::INFINITY` at grazing.
    fn lambda(&self, w: DVec3) -> f64;

    /// A normal visible from `w` (`w.z > 0`, unit), drawn with density
    /// [`pdf_visible`](Self::pdf_visible) from two uniforms; `m.z >= 0`.
    fn sample_visible(&self, w: DVec3, u: [f64; 2]) -> DVec3;

    /// Smith masking `G1(w) = 1 / (1 + Lambda(w))`, in `[0, 1]`.
    fn g1(&self, w: DVec3) -> f64 {
        1.0 / (1.0 + self.lambda(w))
    }

    /// Height-correlated masking-shadowing `G(wo, wi) = 1 / (1 + Lambda(wo) + Lambda(wi))`.
    fn g(&self, wo: DVec3, wi: DVec3) -> f64 {
        1.0 / (1.0 + self.lambda(wo) + self.lambda(wi))
    }

    /// Density of [`sample_visible`](Self::sample_visible) drawing the normal `m` as seen from
    /// `w` (`w.z > 0`): `D_w(m) = G1(w) max(0, w.m) D(m) / w.z` (sr^-1).
    fn pdf_visible(&self, w: DVec3, m: DVec3) -> f64 {
        if !(w.z > 0.0) {
            return 0.0;
        }
        let p = self.g1(w) * w.dot(m).max(0.0) * self.d(m) / w.z;
        if p.is_finite() { p } else { 0.0 }
    }
}

/// Which microfacet distribution a rough material uses: `"distribution"` in a scene file,
/// `"ggx"` (the default) or `"beckmann"` (Mitsuba 3's default), with the same `alpha`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Distribution {
    /// Trowbridge-Reitz ([`Ggx`]).
    #[default]
    Ggx,
    /// Beckmann ([`Beckmann`]).
    Beckmann,
}

/// A distribution of either kind with its alphas: what a rough material holds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Facets {
    Ggx(Ggx),
    Beckmann(Beckmann),
}

impl Facets {
    /// The `kind` of distribution with roughness `alpha_x` along `+x` and `alpha_y` along `+y`.
    pub(crate) fn new(kind: Distribution, alpha_x: f64, alpha_y: f64) -> Self {
        match kind {
            Distribution::Ggx => Facets::Ggx(Ggx::new(alpha_x, alpha_y)),
            Distribution::Beckmann => Facets::Beckmann(Beckmann::new(alpha_x, alpha_y)),
        }
    }

    /// Its alphas along `+x` and `+y`.
    pub(crate) fn alphas(&self) -> (f64, f64) {
        match self {
            Facets::Ggx(g) => (g.alpha_x(), g.alpha_y()),
            Facets::Beckmann(b) => (b.alpha_x(), b.alpha_y()),
        }
    }

    /// Which kind it is.
    pub(crate) fn kind(&self) -> Distribution {
        match self {
            Facets::Ggx(_) => Distribution::Ggx,
            Facets::Beckmann(_) => Distribution::Beckmann,
        }
    }
}

impl Microfacet for Facets {
    fn d(&self, m: DVec3) -> f64 {
        match self {
            Facets::Ggx(f) => f.d(m),
            Facets::Beckmann(f) => f.d(m),
        }
    }

    fn lambda(&self, w: DVec3) -> f64 {
        match self {
            Facets::Ggx(f) => f.lambda(w),
            Facets::Beckmann(f) => f.lambda(w),
        }
    }

    fn sample_visible(&self, w: DVec3, u: [f64; 2]) -> DVec3 {
        match self {
            Facets::Ggx(f) => f.sample_visible(w, u),
            Facets::Beckmann(f) => f.sample_visible(w, u),
        }
    }
}

/// Trowbridge-Reitz (GGX) microfacet distribution, anisotropic along the local axes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ggx {
    alpha_x: f64,
    alpha_y: f64,
}

impl Ggx {
    /// A distribution with roughness `alpha_x` along the first tangent (`+x`) and `alpha_y`
    /// along the second (`+y`). Alphas below [`SMOOTH_ALPHA`] are raised to it, so every
    /// function stays finite; callers check [`Ggx::is_smooth_alphas`] first to use a delta lobe.
    pub fn new(alpha_x: f64, alpha_y: f64) -> Self {
        Self { alpha_x: alpha_x.max(SMOOTH_ALPHA), alpha_y: alpha_y.max(SMOOTH_ALPHA) }
    }

    /// `true` when both alphas were below [`SMOOTH_ALPHA`] (the smooth limit).
    pub fn is_smooth_alphas(alpha_x: f64, alpha_y: f64) -> bool {
        alpha_x.max(alpha_y) < SMOOTH_ALPHA
    }

    /// The roughness along `+x`.
    pub fn alpha_x(&self) -> f64 {
        self.alpha_x
    }

    /// The roughness along `+y`.
    pub fn alpha_y(&self) -> f64 {
        self.alpha_y
    }
}

impl Microfacet for Ggx {
    /// The distribution of normals `D(m)` (sr^-1, projected so that `integral D(m) m.z dm = 1`).
    fn d(&self, m: DVec3) -> f64 {
        if !(m.z > 0.0) {
            return 0.0;
        }
        let (x, y) = (m.x / self.alpha_x, m.y / self.alpha_y);
        let s = x * x + y * y + m.z * m.z;
        let d = 1.0 / (PI * self.alpha_x * self.alpha_y * s * s);
        if d.is_finite() { d } else { 0.0 }
    }

    /// Smith's `Lambda(w)` for the GGX distribution; 0 at normal incidence, infinite at grazing
    /// (returned as `f64::INFINITY`, which makes `G1` and `G` exactly 0).
    fn lambda(&self, w: DVec3) -> f64 {
        let z2 = w.z * w.z;
        let t = self.alpha_x * self.alpha_x * w.x * w.x + self.alpha_y * self.alpha_y * w.y * w.y;
        if z2 == 0.0 {
            return if t > 0.0 { f64::INFINITY } else { 0.0 };
        }
        let a2_tan2 = t / z2;
        // sqrt(1 + x) - 1 = x / (sqrt(1 + x) + 1): no cancellation for smooth surfaces.
        0.5 * a2_tan2 / ((1.0 + a2_tan2).sqrt() + 1.0)
    }

    /// A microfacet normal visible from `w` (`w.z > 0`, unit), drawn with density
    /// [`pdf_visible`](Self::pdf_visible) from two uniforms (Heitz 2018: the visible
    /// hemisphere of the stretched configuration, sampled as a projected disk). The result has
    /// `m.z >= 0` and `w.m >= 0`.
    fn sample_visible(&self, w: DVec3, u: [f64; 2]) -> DVec3 {
        // Stretch to the configuration where the distribution is the unit hemisphere.
        let wh = DVec3::new(self.alpha_x * w.x, self.alpha_y * w.y, w.z).normalize();
        let len2 = wh.x * wh.x + wh.y * wh.y;
        let t1 = if len2 > 0.0 { DVec3::new(-wh.y, wh.x, 0.0) / len2.sqrt() } else { DVec3::X };
        let t2 = wh.cross(t1);
        // A uniform point of the disk, its lower half squeezed onto the visible projected area.
        let r = u[0].clamp(0.0, 1.0).sqrt();
        let phi = 2.0 * PI * u[1];
        let p1 = r * phi.cos();
        let mut p2 = r * phi.sin();
        let s = 0.5 * (1.0 + wh.z);
        p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * p2;
        let nh = t1 * p1 + t2 * p2 + wh * (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt();
        // Unstretch back to the distribution's normals.
        let m = DVec3::new(self.alpha_x * nh.x, self.alpha_y * nh.y, nh.z.max(1e-12));
        m.normalize()
    }
}

/// Checks one GGX alpha of `material`'s `field`: finite and `>= 0` (the scene-file rule of
/// every rough material).
pub(crate) fn check_alpha(
    material: &'static str,
    field: &'static str,
    alpha: f64,
) -> Result<(), MaterialError> {
    if alpha.is_finite() && alpha >= 0.0 {
        Ok(())
    } else {
        Err(MaterialError::parameter(
            material,
            field,
            alpha,
            format!(
                "a roughness (GGX alpha) must be finite and >= 0 (below {SMOOTH_ALPHA} the surface is smooth)"
            ),
        ))
    }
}

/// The `(alpha_u, alpha_v)` pair of `material` from the scene-file keys `roughness` or
/// `roughness_u` + `roughness_v` (exactly one of the two forms, each alpha checked);
/// `smooth` says what roughness 0 means for this material, for the message of a missing key.
pub(crate) fn alphas_from_keys(
    material: &'static str,
    roughness: Option<f64>,
    u: Option<f64>,
    v: Option<f64>,
    smooth: &str,
) -> Result<(f64, f64), MaterialError> {
    match (roughness, u, v) {
        (Some(a), None, None) => {
            check_alpha(material, "roughness", a)?;
            Ok((a, a))
        }
        (None, Some(a), Some(b)) => {
            check_alpha(material, "roughness_u", a)?;
            check_alpha(material, "roughness_v", b)?;
            Ok((a, b))
        }
        (Some(a), _, _) => Err(MaterialError::parameter(
            material,
            "roughness",
            a,
            "give either `roughness` or `roughness_u` and `roughness_v`, not both",
        )),
        (None, Some(_), None) => Err(missing(
            material,
            "roughness_v",
            "`roughness_u` needs `roughness_v` (the GGX alpha along the second tangent)",
        )),
        (None, None, Some(_)) => Err(missing(
            material,
            "roughness_u",
            "`roughness_v` needs `roughness_u` (the GGX alpha along the first tangent)",
        )),
        (None, None, None) => Err(missing(
            material,
            "roughness",
            format!(
                "give `roughness` (the GGX alpha, {smooth}) or `roughness_u` and `roughness_v`"
            ),
        )),
    }
}

/// A required key of `material` that the scene file left out.
fn missing(material: &'static str, field: &str, reason: impl Into<String>) -> MaterialError {
    MaterialError::Parameter {
        material,
        field: field.to_owned(),
        value: "missing".to_owned(),
        reason: reason.into(),
    }
}

/// The scene-file keys `(roughness, roughness_u, roughness_v)` of an alpha pair: `roughness`
/// alone when isotropic.
pub(crate) fn alphas_to_keys(u: f64, v: f64) -> (Option<f64>, Option<f64>, Option<f64>) {
    if u == v { (Some(u), None, None) } else { (None, Some(u), Some(v)) }
}

/// Unpolarised Fresnel reflectance of a conductor with complex index `eta + i k` (relative to
/// the medium the light arrives from, here vacuum), for light arriving at `cos_i = cos theta`
/// (`|cos_i|` is used; grazing gives 1). Exact for any `eta > 0`, `k >= 0`: the average of the
/// s- and p-polarised reflectances, computed in real arithmetic. At normal incidence it is
/// `((eta - 1)^2 + k^2) / ((eta + 1)^2 + k^2)`.
pub fn fresnel_conductor(cos_i: f64, eta: f64, k: f64) -> f64 {
    let cos = cos_i.abs().min(1.0);
    let cos2 = cos * cos;
    let sin2 = (1.0 - cos2).max(0.0);
    let (eta2, k2) = (eta * eta, k * k);
    let t0 = eta2 - k2 - sin2;
    let a2pb2 = (t0 * t0 + 4.0 * eta2 * k2).sqrt();
    let a = (0.5 * (a2pb2 + t0)).max(0.0).sqrt();
    let t1 = a2pb2 + cos2;
    let t2 = 2.0 * a * cos;
    let rs = (t1 - t2) / (t1 + t2);
    let t3 = cos2 * a2pb2 + sin2 * sin2;
    let t4 = t2 * sin2;
    let rp = rs * (t3 - t4) / (t3 + t4);
    let r = 0.5 * (rs + rp);
    if r.is_finite() { r.clamp(0.0, 1.0) } else { 1.0 }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn conductor_fresnel_matches_the_normal_incidence_closed_form_and_grazing_limit() {
        for &(n, k) in &[(0.2, 3.0), (1.5, 0.0), (0.05, 4.2), (2.5, 1.0)] {
            let closed = ((n - 1.0) * (n - 1.0) + k * k) / ((n + 1.0) * (n + 1.0) + k * k);
            assert!((fresnel_conductor(1.0, n, k) - closed).abs() < 1e-12, "{n} {k}");
            assert!((fresnel_conductor(0.0, n, k) - 1.0).abs() < 1e-12);
        }
        // With k = 0 it is the dielectric Fresnel reflectance.
        for i in 1..20 {
            let c = i as f64 / 20.0;
            let d = crate::fresnel_dielectric(c, 1.5);
            assert!((fresnel_conductor(c, 1.5, 0.0) - d).abs() < 1e-9, "{c}");
        }
    }

    #[test]
    fn ggx_projected_normals_integrate_to_one() {
        // Midpoint quadrature of integral D(m) cos(theta_m) dm over the hemisphere.
        for &(ax, ay) in &[(0.3, 0.3), (0.1, 0.5), (0.8, 0.8)] {
            let g = Ggx::new(ax, ay);
            let (nt, np) = (2000, 400);
            let mut sum = 0.0;
            for i in 0..nt {
                let theta = (i as f64 + 0.5) / nt as f64 * 0.5 * PI;
                for j in 0..np {
                    let phi = (j as f64 + 0.5) / np as f64 * 2.0 * PI;
                    let m =
                        DVec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos());
                    sum += g.d(m) * m.z * theta.sin();
                }
            }
            sum *= (0.5 * PI / nt as f64) * (2.0 * PI / np as f64);
            assert!((sum - 1.0).abs() < 2e-3, "{ax} {ay}: {sum}");
        }
    }

    #[test]
    fn visible_normals_face_the_viewer() {
        let g = Ggx::new(0.5, 0.2);
        let w = DVec3::new(0.6, -0.3, 0.2).normalize();
        for i in 0..100 {
            let m =
                g.sample_visible(w, [(i as f64 + 0.5) / 100.0, ((i * 37) % 100) as f64 / 100.0]);
            assert!(m.z >= 0.0 && w.dot(m) >= -1e-12 && (m.length() - 1.0).abs() < 1e-12);
        }
    }
}
