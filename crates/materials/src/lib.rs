//! Materials for Spectrace: what a surface does to a beam (the seed's material function, 3.5).
//!
//! A beam arriving at a surface ([`Incoming`]: direction of travel, the outward shading normal,
//! the wavelength) either leaves it as a new beam ([`Scattered`]: a unit direction, a factor for
//! the beam's weight, the kind of lobe and its density) or is absorbed (`None`). That is the
//! [`Material`] trait's [`scatter`](Material::scatter); bidirectional rendering adds
//! [`eval`](Material::eval) (the BSDF, for connecting a surface to the camera) and
//! [`pdf`](Material::pdf), and the effects analysis asks [`is_specular`](Material::is_specular)
//! and [`is_dispersive`](Material::is_dispersive). The trait is typetag-serialisable, so scene
//! files name a material by type and other crates can add their own.
//!
//! | material | what it does | lobes |
//! |---|---|---|
//! | [`Diffuse`] | Lambertian, spectral reflectance, two-sided | one, cosine-sampled |
//! | [`Mirror`] | perfect reflection, spectral reflectance, two-sided | one delta |
//! | [`Dielectric`] | Fresnel reflection + Snell refraction, total internal reflection, dispersion | two deltas |
//! | [`ThinDielectric`] | a thin sheet: both faces' Fresnel reflection with every internal bounce, straight transmission | two deltas |
//! | [`Fluorescent`] | absorbs and re-emits at other wavelengths (bispectral) over a Lambertian base | elastic Lambertian + re-emission ([`Material::fluorescence`]) |
//! | [`RoughDielectric`] | frosted glass: GGX microfacet reflection + refraction (Walter 2007), dispersion, anisotropy | two with densities (roughness 0: `Dielectric`'s deltas) |
//! | [`Plastic`] | a smooth or rough (GGX or Beckmann) dielectric coating over a Lambertian base, two-sided | a delta (smooth) or GGX reflection, plus a cosine-sampled diffuse |
//! | [`Conductor`] | smooth metal: exact Fresnel reflectance of a complex index `eta + i k` per wavelength, two-sided | one delta |
//! | [`RoughConductor`] | rough metal: GGX microfacets, visible-normal sampling, Smith height-correlated shadowing, isotropic or anisotropic; roughness 0 is the [`Conductor`] | one with a density |
//! | [`Textured`] | a `Diffuse` or `Plastic` with a colour [`Texture`], a rough conductor or dielectric with a roughness texture, resolved per hit ([`Material::texel`], [`MaterialAt`]) | the textured material's |
//!
//! Metals come from the [`metals`] catalog of measured `n, k` tables (`"metal": "Au"`; Ag Al Au Cr
//! Cu Ni Pt Ti W, 350-850 nm, sources in `data/metals/README.md`) or from user `eta` / `k` tables
//! ([`ComplexIor`]).
//!
//! The microfacet core is the [`Microfacet`] trait (`d`, `lambda` and `sample_visible`, from
//! which `g1`, `g` and `pdf_visible` follow) with [`Ggx`] (the distribution every rough material
//! uses today) and [`Beckmann`] (Mitsuba 3's default, with the exact Smith `Lambda` and exact
//! visible-normal sampling, chi-square tested; [`RoughConductor`] and [`RoughDielectric`] take it
//! with `"distribution": "beckmann"`, [`Plastic`] is GGX only so far).
//!
//! The key design decision is that every property is a function of wavelength, evaluated per
//! beam: reflectances are [`Reflectance`](spectrace_spectrum::Reflectance) spectra and indices of
//! refraction are [`Ior`] laws (constant, Sellmeier, Cauchy, tabulated, or a named glass from
//! the [`GLASSES`] catalog with its published coefficients), so an object's colour and a prism's
//! spread come out of the light's spectrum rather than out of RGB. Samplers take explicit
//! uniforms and return weights that are already `f |cos| / pdf` (the reflectance for a diffuse
//! or mirror bounce, 1 or the transmittance for a dielectric), which is what the light tracer
//! multiplies a beam's `scale` by. Beams carry flux: refraction applies no `(n_t/n_i)^2`
//! radiance scaling unless asked for with [`Transport::Radiance`]. Every material and index is
//! validated when built and when deserialised; a bad field is a [`MaterialError`] that names it
//! (`Dielectric.ior.sellmeier.c[2] = ...`), never a panic.
//!
//! # Example
//! ```
//! use spectrace_materials::{Dielectric, Incoming, Material, glam::DVec3};
//! let glass = Dielectric::glass("BK7").unwrap();
//! let beam = Incoming { direction: DVec3::new(0.0, -1.0, 0.0), normal: DVec3::Y, lambda: 550.0 };
//! // Normal incidence: 4.2 % is reflected, so u[0] = 0.5 refracts straight through.
//! let out = glass.scatter(&beam, [0.5, 0.0, 0.0]).unwrap();
//! assert_eq!(out.weight, 1.0);
//! assert!((out.direction - DVec3::new(0.0, -1.0, 0.0)).length() < 1e-12);
//! assert!(glass.is_specular() && glass.is_dispersive());
//! ```

mod beckmann;
mod conductor;
mod dielectric;
mod diffuse;
mod error;
mod fluorescent;
mod fresnel;
mod glass;
mod ior;
mod material;
pub mod metals;
mod microfacet;
mod mirror;
mod plastic;
mod rough_dielectric;
pub mod texture;
mod textured;
mod thin_dielectric;
mod vectors;

pub use beckmann::Beckmann;
pub use conductor::{Conductor, RoughConductor};
pub use dielectric::Dielectric;
pub use diffuse::Diffuse;
pub use error::MaterialError;
pub use fluorescent::{ExcitationSampler, Fluorescent, Reemission, reemission_lobe};
pub use fresnel::{Polarised, fresnel_dielectric, fresnel_dielectric_polarised, reflect, refract};
pub use glass::{GLASSES, Glass, find_glass, known_glasses};
pub use ior::{FRAUNHOFER_C_NM, FRAUNHOFER_D_NM, FRAUNHOFER_F_NM, Ior, VALID_MAX_NM, VALID_MIN_NM};
pub use material::{
    BundleScattered, Incoming, Material, ScatterKind, Scattered, Transport, scale_bundle,
    scatter_each,
};
pub use metals::{ComplexIor, Metal, find_metal, known_metals};
pub use microfacet::{Distribution, Ggx, Microfacet, SMOOTH_ALPHA, fresnel_conductor};
pub use mirror::Mirror;
pub use plastic::Plastic;
pub use rough_dielectric::RoughDielectric;
pub use texture::Texture;
pub use textured::{MaterialAt, Texel, Textured};
pub use thin_dielectric::ThinDielectric;

/// Vectors (`DVec3`), re-exported so users need no direct dependency.
pub use glam;
/// Spectra (reflectance, transmittance), re-exported.
pub use spectrace_spectrum as spectrum;
