//! Fresnel reflectance of a dielectric interface and the laws of reflection and refraction.
//!
//! Conventions (pbrt's): `cos_theta_i` is the cosine between the direction the light comes from
//! and the normal, and `eta = n_t / n_i` is the index on the far side over the index on the near
//! side. A negative `cos_theta_i` means the light is on the other side: the functions then swap
//! the media (`eta -> 1 / eta`) themselves.

use glam::DVec3;

use crate::vectors::normalise;

/// Fresnel reflectances of the two linear polarisations (see
/// [`fresnel_dielectric_polarised`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Polarised {
    /// Reflectance of the s (perpendicular, TE) polarisation, in `[0, 1]`.
    pub s: f64,
    /// Reflectance of the p (parallel, TM) polarisation, in `[0, 1]`; 0 at Brewster's angle.
    pub p: f64,
}

/// Fresnel reflectances `R_s`, `R_p` of light arriving at angle `acos(cos_theta_i)` at an
/// interface with relative index `eta = n_t / n_i`; both 1 under total internal reflection.
///
/// Written for accuracy at both ends: `sin^2 theta_i` is formed as `(1 - cos)(1 + cos)` (no
/// cancellation at normal incidence), grazing incidence gives exactly 1 with no division by 0,
/// and at or beyond the critical angle the result is exactly 1.
#[inline]
pub fn fresnel_dielectric_polarised(cos_theta_i: f64, eta: f64) -> Polarised {
    let mut cos_i = cos_theta_i.clamp(-1.0, 1.0);
    let mut eta = eta;
    if cos_i < 0.0 {
        eta = 1.0 / eta;
        cos_i = -cos_i;
    }
    let sin2_i = ((1.0 - cos_i) * (1.0 + cos_i)).max(0.0);
    let sin2_t = sin2_i / (eta * eta);
    if !(sin2_t < 1.0) {
        return Polarised { s: 1.0, p: 1.0 };
    }
    let cos_t = ((1.0 - sin2_t).max(0.0)).sqrt();
    // cos_t > 0 here (sin2_t < 1), so neither denominator can vanish.
    let r_s = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    let r_p = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    Polarised { s: (r_s * r_s).min(1.0), p: (r_p * r_p).min(1.0) }
}

/// Unpolarised Fresnel reflectance `(R_s + R_p) / 2` of a dielectric interface (pbrt's
/// `FrDielectric`): `cos_theta_i` as in [`fresnel_dielectric_polarised`], `eta = n_t / n_i`.
/// The transmitted fraction is `1 - F`. At normal incidence `((eta - 1) / (eta + 1))^2`.
#[inline]
pub fn fresnel_dielectric(cos_theta_i: f64, eta: f64) -> f64 {
    let r = fresnel_dielectric_polarised(cos_theta_i, eta);
    0.5 * (r.s + r.p)
}

/// Mirror reflection of a beam travelling along `direction` (towards the surface) about the
/// unit `normal` (either side): the outgoing unit direction, away from the surface.
#[inline]
pub fn reflect(direction: DVec3, normal: DVec3) -> DVec3 {
    normalise(direction - 2.0 * direction.dot(normal) * normal)
}

/// Refraction by Snell's law of a beam travelling along unit `direction` (towards the surface)
/// through a boundary with unit `normal` (either side) into a medium with relative index
/// `eta = n_t / n_i` (far side over the side the beam comes from). Returns the unit
/// transmitted direction, on the far side, or `None` under total internal reflection.
///
/// `n_i sin(theta_i) = n_t sin(theta_t)` holds to rounding.
#[inline]
pub fn refract(direction: DVec3, normal: DVec3, eta: f64) -> Option<DVec3> {
    // Normal facing the beam's side.
    let n = if direction.dot(normal) > 0.0 { -normal } else { normal };
    let cos_i = (-direction.dot(n)).clamp(0.0, 1.0);
    let inv_eta = 1.0 / eta;
    let sin2_i = ((1.0 - cos_i) * (1.0 + cos_i)).max(0.0);
    let sin2_t = sin2_i * inv_eta * inv_eta;
    if !(sin2_t < 1.0) {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let t = direction * inv_eta + (cos_i * inv_eta - cos_t) * n;
    Some(normalise(t))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn glass_at_normal_incidence_and_beyond_critical() {
        assert!((fresnel_dielectric(1.0, 1.5) - 0.04).abs() < 1e-16);
        assert_eq!(fresnel_dielectric(-0.5, 1.5), 1.0); // inside, 60 degrees > 41.8
        assert!(fresnel_dielectric(-0.8, 1.5) < 1.0); // inside, 36.9 degrees
        assert_eq!(refract(DVec3::new(0.866, 0.5, 0.0).normalize(), DVec3::Y, 1.0 / 1.5), None);
    }

    #[test]
    fn refraction_at_normal_incidence_goes_straight() {
        let t = refract(DVec3::NEG_Y, DVec3::Y, 1.5);
        assert_eq!(t, Some(DVec3::NEG_Y));
        // The normal may be given on either side.
        assert_eq!(refract(DVec3::NEG_Y, DVec3::NEG_Y, 1.5), Some(DVec3::NEG_Y));
    }
}
