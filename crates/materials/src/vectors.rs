//! Small vector helpers: turning a normal to face a beam, renormalising. (The orthonormal frame,
//! the cosine-weighted warp and the clamp of uniforms are `spectrace_sampling::Frame`,
//! `spectrace_sampling::sample_cosine_hemisphere` and `spectrace_sampling::clamp_uniform`, shared
//! with the lights.)

use glam::DVec3;

/// `normal` turned to face against `direction` (towards where the beam came from). A beam
/// exactly tangent (`direction . normal == 0`) keeps the normal as given.
#[inline]
pub(crate) fn facing(direction: DVec3, normal: DVec3) -> DVec3 {
    if direction.dot(normal) > 0.0 { -normal } else { normal }
}

/// Renormalises a vector that is unit to within rounding (removes accumulated error).
#[inline]
pub(crate) fn normalise(d: DVec3) -> DVec3 {
    let len2 = d.length_squared();
    if len2 > 0.0 && len2.is_finite() { d / len2.sqrt() } else { d }
}
