//! [`Environment`]: light arriving from every direction at infinite distance, read from a
//! latitude-longitude image (an HDR environment map), as the scene file's `environment` key
//! gives it.
//!
//! | field | unit | default | meaning |
//! |---|---|---|---|
//! | `file` | | required | the image: OpenEXR, or PNG, JPEG, TGA (sRGB-decoded unless `raw`); read under the scene folder's path policy |
//! | `raw` | | `false` | read an 8-bit image's values as linear (EXR is always linear) |
//! | `scale` | | `1` | factor on every texel |
//! | `rotation` | | identity | 3 x 3 rotation (rows) from the map's frame to the world: the map's `+y` is its zenith |
//!
//! ```json
//! "environment": {"file": "sky.exr", "scale": 2.0}
//! ```
//!
//! **What a texel means.** A texel's linear sRGB value `(r, g, b)` is a spectral radiance as
//! Mitsuba 3's spectral variants read it: `D65(lambda) / N * f * rho(lambda)`, `N` making D65's
//! luminance 1, `f = 2 max(r, g, b)` and `rho` the smooth reflectance
//! ([`spectrace_spectrum::RgbTable`]) of `(r, g, b) / f`; between texels the reflectances and the
//! factors are each interpolated bilinearly (so a white map of value 1 is D65 of luminance 1 from
//! every direction). The image's column `x` is centred on `u = (x + 1/2) / width` and wraps
//! around; row `y` lies at `v = y / (height - 1)` (the first row is the zenith, the last the
//! nadir). `(u, v)` is the local direction `(sin phi sin theta, cos theta, -cos phi sin theta)`
//! with `phi = 2 pi u`, `theta = pi v`, turned to the world by `rotation`.
//!
//! **How it is made finite.** The renderer places the map on a sphere around the scene's
//! objects, camera and sensors (its centre and radius are the renderer's choice, and do not change the
//! image): every point inside receives `L(omega)` from direction `omega`, exactly an environment
//! at infinite distance. The sphere is part of the scene (it absorbs what reaches it).
//!
//! **Sampling.** Directions are drawn from a piecewise-bilinear density over `(phi, theta)`
//! whose nodes are the texels' whole-spectrum radiance times `sin theta`, so the solid-angle
//! density is that interpolant over `sin theta` (exact, for multiple importance sampling). A
//! beam starts at a uniform point of the sphere (area density `1 / (4 pi R^2)`) along a drawn
//! direction, and weighs `L cos / (p_position p_direction power)`; a direction that would leave
//! the sphere makes a beam of weight 0. Since the weight depends on the direction, the beam's
//! origin alone weighs 1 ([`LightSource::origin_weight`]) and connections from it use
//! [`LightSource::emission_density`] `= L cos 4 pi R^2 / power`. The colour varies with
//! direction: [`LightSource::uniform_spectrum`] is false (one wavelength per path) and
//! [`LightSource::spectral_factor`] gives the ratio to the map's mean spectrum.

use std::f64::consts::PI;
use std::path::PathBuf;
use std::sync::Arc;

use glam::{DMat3, DVec3};
use rand::Rng;
use serde::{Deserialize, Serialize};
use spectrace_lights::{
    Beam, BeamCounter, EmissionSample, LightError, LightFlags, LightSample, LightSource,
    LightSurface, uniform,
};
use spectrace_materials::texture::Bitmap;
use spectrace_sampling::PiecewiseBilinear;
use spectrace_spectrum::rgb::{SigmoidSpectrum, d65_luminance, d65_visible, visible_grid};
use spectrace_spectrum::{RgbTable, SpectralPowerDistribution, Tabulated};

/// Most texels an environment map may have (16.7 million, e.g. 8192 x 2048): about 60 bytes
/// each once read.
pub const MAX_ENVIRONMENT_TEXELS: usize = 1 << 24;

const NAME: &str = "Environment";

/// The scene-file form of an environment (see the module's table).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EnvironmentSpec {
    /// The image file.
    pub file: PathBuf,
    /// Read an 8-bit image's values as linear.
    #[serde(default)]
    pub raw: bool,
    /// Factor on every texel.
    #[serde(default = "one")]
    pub scale: f64,
    /// Rotation (rows) from the map's frame to the world.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rotation: Option<[[f64; 3]; 3]>,
}

fn one() -> f64 {
    1.0
}

/// An [`EnvironmentSpec`] with its image read: what a scene file's `environment` becomes when
/// it is deserialised (the image is read then, under the scene folder's path policy).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(try_from = "EnvironmentSpec", into = "EnvironmentSpec")]
pub struct EnvironmentMap {
    spec: EnvironmentSpec,
    bitmap: Bitmap,
}

impl TryFrom<EnvironmentSpec> for EnvironmentMap {
    type Error = LightError;
    fn try_from(spec: EnvironmentSpec) -> Result<Self, LightError> {
        check_scale(spec.scale)?;
        if let Some(rows) = spec.rotation {
            rotation(rows)?;
        }
        let bitmap = read_bitmap(&spec)?;
        Ok(Self { spec, bitmap })
    }
}

impl From<EnvironmentMap> for EnvironmentSpec {
    fn from(m: EnvironmentMap) -> Self {
        m.spec
    }
}

impl EnvironmentMap {
    /// What the scene file gave.
    pub fn spec(&self) -> &EnvironmentSpec {
        &self.spec
    }
}

/// One node of the map: the smooth reflectance of its normalised colour, its factor
/// (`2 max(r, g, b) scale`) and the integral over wavelength of the reflectance times the
/// normalised D65.
#[derive(Debug, Clone, Copy)]
struct Node {
    rho: SigmoidSpectrum,
    factor: f64,
    integral: f64,
}

/// An environment map as a light (see the module's essay).
#[derive(Debug)]
pub struct Environment {
    spec: EnvironmentSpec,
    center: DVec3,
    radius: f64,
    to_world: DMat3,
    width: usize,
    height: usize,
    nodes: Vec<Node>,
    /// Density over `(phi, theta)`, `phi` from the first column's centre over one turn.
    table: PiecewiseBilinear,
    /// Integral of the whole-spectrum radiance over the sphere of directions (W m^-2).
    radiance_integral: f64,
    spd: Arc<Tabulated>,
    counter: BeamCounter,
}

/// Bilinear corners of a direction: node indices and weights.
type Corners = [(usize, f64); 4];

impl Environment {
    /// Places the map on the sphere `center`, `radius` (which must
    /// enclose everything the scene renders).
    ///
    /// # Errors
    /// [`LightError`] naming the field: an oversized image, fewer than 2 rows, a
    /// scale that is not finite and positive, a `rotation` that is not a rotation, a black map,
    /// a sphere that is not finite.
    pub fn new(map: EnvironmentMap, center: DVec3, radius: f64) -> Result<Self, LightError> {
        let EnvironmentMap { spec, bitmap } = map;
        check_scale(spec.scale)?;
        if !(center.is_finite() && radius > 0.0 && radius.is_finite()) {
            return Err(LightError::parameter(
                NAME,
                "sphere",
                (center, radius),
                "the scene's bounds must be finite",
            ));
        }
        let to_world = match spec.rotation {
            None => DMat3::IDENTITY,
            Some(rows) => rotation(rows)?,
        };
        let (width, height) = bitmap.size();
        if height < 2 || width.saturating_mul(height) > MAX_ENVIRONMENT_TEXELS {
            return Err(LightError::File {
                light: NAME,
                field: "file",
                message: format!(
                    "{}: {width} x {height} texels: an environment map needs at least 2 rows and \
                     at most {MAX_ENVIRONMENT_TEXELS} texels",
                    spec.file.display()
                ),
            });
        }
        let (nodes, mean) = nodes(&bitmap, spec.scale);
        let table = direction_table(&nodes, width, height).map_err(|reason| LightError::File {
            light: NAME,
            field: "file",
            message: format!("{}: {reason}", spec.file.display()),
        })?;
        let mut env = Self {
            spec,
            center,
            radius,
            to_world,
            width,
            height,
            nodes,
            table,
            radiance_integral: 0.0,
            spd: Arc::new(mean),
            counter: BeamCounter::new(),
        };
        env.radiance_integral = env.integrate();
        if !(env.radiance_integral > 0.0 && env.radiance_integral.is_finite()) {
            return Err(LightError::parameter(
                NAME,
                "file",
                env.radiance_integral,
                "the map's radiance must integrate to a finite positive value",
            ));
        }
        Ok(env)
    }

    /// The scene-file form it was read from.
    pub fn spec(&self) -> &EnvironmentSpec {
        &self.spec
    }

    /// The sphere it is placed on: centre and radius.
    pub fn sphere(&self) -> (DVec3, f64) {
        (self.center, self.radius)
    }

    /// The whole-spectrum radiance (W m^-2 sr^-1) arriving from the world direction `omega`
    /// (unit, pointing away from the scene towards the map).
    pub fn radiance(&self, omega: DVec3) -> f64 {
        let c = self.corners(omega);
        let factor: f64 = c.iter().map(|&(i, w)| w * self.nodes[i].factor).sum();
        let integral: f64 = c.iter().map(|&(i, w)| w * self.nodes[i].integral).sum();
        factor * integral
    }

    /// The spectral radiance (W m^-2 sr^-1 nm^-1) arriving from `omega` at `lambda`.
    pub fn spectral_radiance(&self, omega: DVec3, lambda: f64) -> f64 {
        let c = self.corners(omega);
        let factor: f64 = c.iter().map(|&(i, w)| w * self.nodes[i].factor).sum();
        let rho: f64 = c.iter().map(|&(i, w)| w * self.nodes[i].rho.value(lambda)).sum();
        factor * rho * d65_visible(lambda) / d65_luminance()
    }

    /// Solid-angle density of drawing the world direction `omega`.
    pub fn pdf_direction(&self, omega: DVec3) -> f64 {
        let (phi, theta) = self.angles(omega);
        let sin = theta.sin();
        if !(sin > 1e-12) {
            return 0.0;
        }
        self.table.pdf(phi, theta) / sin
    }

    /// Draws a world direction from two uniforms, with its solid-angle density (`None` where the
    /// density is 0).
    pub fn sample_direction(&self, u: [f64; 2]) -> Option<(DVec3, f64)> {
        let (phi, theta) = self.table.sample(u.map(|v| v.clamp(0.0, 1.0)));
        let sin = theta.sin();
        let pdf = if sin > 1e-12 { self.table.pdf(phi, theta) / sin } else { 0.0 };
        if !(pdf > 0.0 && pdf.is_finite()) {
            return None;
        }
        let local = DVec3::new(phi.sin() * sin, theta.cos(), -phi.cos() * sin);
        Some(((self.to_world * local).normalize(), pdf))
    }

    /// `(phi, theta)` of a world direction, `phi` within the table's range.
    fn angles(&self, omega: DVec3) -> (f64, f64) {
        let v = self.to_world.transpose() * omega;
        let mut phi = v.x.atan2(-v.z);
        let first = self.table.xs()[0];
        while phi < first {
            phi += 2.0 * PI;
        }
        while phi >= first + 2.0 * PI {
            phi -= 2.0 * PI;
        }
        let theta = (v.y / v.length()).clamp(-1.0, 1.0).acos();
        (phi, if theta.is_finite() { theta } else { 0.0 })
    }

    /// The four nodes around a world direction and their bilinear weights: texel-centred and
    /// periodic in `phi`, corner-aligned in `theta`.
    fn corners(&self, omega: DVec3) -> Corners {
        let (phi, theta) = self.angles(omega);
        let (w, h) = (self.width, self.height);
        let px = (phi / (2.0 * PI) * w as f64 - 0.5).rem_euclid(w as f64);
        let x0 = (px.floor() as usize).min(w - 1);
        let tx = (px - x0 as f64).clamp(0.0, 1.0);
        let x1 = (x0 + 1) % w;
        let py = (theta / PI * (h - 1) as f64).clamp(0.0, (h - 1) as f64);
        let y0 = (py.floor() as usize).min(h - 2);
        let ty = (py - y0 as f64).clamp(0.0, 1.0);
        let at = |x: usize, y: usize| y * w + x;
        [
            (at(x0, y0), (1.0 - tx) * (1.0 - ty)),
            (at(x1, y0), tx * (1.0 - ty)),
            (at(x0, y0 + 1), (1.0 - tx) * ty),
            (at(x1, y0 + 1), tx * ty),
        ]
    }

    /// Integral of the whole-spectrum radiance over all directions: per cell, Simpson's rule
    /// in `phi` (exact: a product of two linear functions) and 4-point Gauss-Legendre in
    /// `theta` (the product of a quadratic and `sin theta`).
    fn integrate(&self) -> f64 {
        const GAUSS: [(f64, f64); 4] = [
            (-0.861_136_311_594_052_6, 0.347_854_845_137_453_9),
            (-0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
            (0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
            (0.861_136_311_594_052_6, 0.347_854_845_137_453_9),
        ];
        let (w, h) = (self.width, self.height);
        let (dphi, dtheta) = (2.0 * PI / w as f64, PI / (h - 1) as f64);
        let mut total = 0.0;
        for y in 0..h - 1 {
            for &(g, gw) in &GAUSS {
                let t = 0.5 * (g + 1.0);
                let sin = (dtheta * (y as f64 + t)).sin();
                let mut row = 0.0;
                for x in 0..w {
                    let node = |x: usize, y: usize| self.nodes[y * w + x];
                    let blend = |x: usize| {
                        let (a, b) = (node(x, y), node(x, y + 1));
                        (
                            a.factor * (1.0 - t) + b.factor * t,
                            a.integral * (1.0 - t) + b.integral * t,
                        )
                    };
                    let ((f0, s0), (f1, s1)) = (blend(x), blend((x + 1) % w));
                    let mid = (0.5 * (f0 + f1)) * (0.5 * (s0 + s1));
                    row += (f0 * s0 + 4.0 * mid + f1 * s1) / 6.0;
                }
                total += 0.5 * gw * sin * row * dphi * dtheta;
            }
        }
        total
    }

    /// Where the ray from `from` (inside the sphere) along the unit `omega` leaves the sphere,
    /// and how far that is.
    fn exit(&self, from: DVec3, omega: DVec3) -> Option<(DVec3, f64)> {
        let o = from - self.center;
        let b = omega.dot(o);
        let c = o.length_squared() - self.radius * self.radius;
        if !(c < 0.0) {
            return None;
        }
        let t = -b + (b * b - c).sqrt();
        (t > 0.0 && t.is_finite()).then(|| (from + omega * t, t))
    }

    /// The cosine between a direction leaving the sphere's point `position` and its inward
    /// normal (negative when the direction leaves the sphere).
    fn inward_cos(&self, position: DVec3, direction: DVec3) -> f64 {
        direction.dot(self.center - position) / self.radius
    }

    /// A uniform point of the sphere's unit directions from two uniforms.
    fn uniform_sphere(u: [f64; 2]) -> DVec3 {
        let z = 1.0 - 2.0 * u[0].clamp(0.0, 1.0);
        let r = (1.0 - z * z).max(0.0).sqrt();
        let phi = 2.0 * PI * u[1];
        DVec3::new(r * phi.cos(), r * phi.sin(), z)
    }

    /// The emission ray of four uniforms: origin, unit direction of travel, the direction's
    /// density, and the inward cosine there (not positive for a direction that leaves).
    fn emission_ray(&self, u: [f64; 4]) -> Option<(DVec3, DVec3, f64, f64)> {
        let n = Self::uniform_sphere([u[0], u[1]]);
        let origin = self.center + n * self.radius;
        let (omega, pdf) = self.sample_direction([u[2], u[3]])?;
        Some((origin, -omega, pdf, omega.dot(n)))
    }
}

/// The Bitmap the spec names, read under the path policy.
fn read_bitmap(spec: &EnvironmentSpec) -> Result<Bitmap, LightError> {
    let value = serde_json::json!({"file": spec.file, "raw": spec.raw});
    serde_json::from_value(value).map_err(|e| LightError::File {
        light: NAME,
        field: "file",
        message: e.to_string(),
    })
}

/// Checks the factor on the texels.
fn check_scale(scale: f64) -> Result<(), LightError> {
    if scale > 0.0 && scale.is_finite() {
        Ok(())
    } else {
        Err(LightError::parameter(NAME, "scale", scale, "must be finite and > 0"))
    }
}

/// A rotation from its rows, or an error saying why it is not one.
fn rotation(rows: [[f64; 3]; 3]) -> Result<DMat3, LightError> {
    let m = DMat3::from_cols_array_2d(&rows).transpose();
    let orthonormal =
        (m.transpose() * m - DMat3::IDENTITY).to_cols_array().iter().all(|v| v.abs() <= 1e-6);
    if !(m.is_finite() && orthonormal && m.determinant() > 0.0) {
        return Err(LightError::parameter(
            NAME,
            "rotation",
            rows,
            "must be a rotation (orthonormal rows, determinant +1)",
        ));
    }
    Ok(m)
}

/// The map's nodes and its mean spectrum (each node's spectrum weighted by its solid angle),
/// tabulated every 5 nm over 360-830 nm.
fn nodes(bitmap: &Bitmap, scale: f64) -> (Vec<Node>, Tabulated) {
    let (w, h) = bitmap.size();
    let grid = visible_grid();
    let step = grid[1] - grid[0];
    // Trapezoid weights times the normalised D65 at each wavelength of the grid.
    let d65: Vec<f64> = grid
        .iter()
        .enumerate()
        .map(|(k, &l)| {
            let end = k == 0 || k + 1 == grid.len();
            d65_visible(l) / d65_luminance() * if end { 0.5 * step } else { step }
        })
        .collect();
    let mut mean = vec![0.0; grid.len()];
    let mut nodes = Vec::with_capacity(w * h);
    for y in 0..h {
        let solid_angle = (PI * y as f64 / (h - 1) as f64).sin().max(1e-3);
        for x in 0..w {
            let rgb = bitmap.texel(x, y).map(|v| v.max(0.0));
            let max = rgb.iter().copied().fold(0.0, f64::max);
            let factor = 2.0 * max;
            // Greys need no fit (and no table: a grey map never builds it).
            let rho = if !(factor > 0.0) {
                SigmoidSpectrum::constant(0.0)
            } else if rgb[0] == rgb[1] && rgb[1] == rgb[2] {
                SigmoidSpectrum::constant(0.5)
            } else {
                RgbTable::get().spectrum(rgb.map(|v| v / factor))
            };
            let mut integral = 0.0;
            for (k, (&l, &d)) in grid.iter().zip(&d65).enumerate() {
                let v = rho.value(l) * d;
                integral += v;
                mean[k] += solid_angle * factor * v;
            }
            nodes.push(Node { rho, factor: factor * scale, integral });
        }
    }
    // Every node's spectrum is positive wherever D65 is, so a map that is not black has a
    // positive mean; a black one is refused later, by its integral.
    let mean = Tabulated::new(&grid, &mean)
        .or_else(|_| Tabulated::new(&grid, &d65))
        .expect("D65 over the visible grid is a valid spectrum");
    (nodes, mean)
}

/// The piecewise-bilinear density over `(phi, theta)`: whole-spectrum radiance times
/// `sin theta` at the nodes, one more column (the first again) closing the turn.
fn direction_table(nodes: &[Node], w: usize, h: usize) -> Result<PiecewiseBilinear, String> {
    let xs: Vec<f64> = (0..=w).map(|x| 2.0 * PI * (x as f64 + 0.5) / w as f64).collect();
    let ys: Vec<f64> = (0..h).map(|y| PI * y as f64 / (h - 1) as f64).collect();
    let mut values = Vec::with_capacity((w + 1) * h);
    for x in 0..=w {
        for (y, theta) in ys.iter().enumerate() {
            let n = nodes[y * w + x % w];
            values.push(n.factor * n.integral * theta.sin().max(0.0));
        }
    }
    PiecewiseBilinear::new(&xs, &ys, &values).map_err(|e| format!("no light to sample: {e}"))
}

impl Serialize for Environment {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        self.spec.serialize(serializer)
    }
}

impl<'de> Deserialize<'de> for Environment {
    fn deserialize<D: serde::Deserializer<'de>>(_deserializer: D) -> Result<Self, D::Error> {
        Err(serde::de::Error::custom(
            "Environment is not a light type of the `lights` list: give the scene an \
             `environment` ({\"file\": \"map.exr\"})",
        ))
    }
}

impl Environment {
    /// The beam of the four uniforms `u` (its origin and direction) and the wavelength drawn
    /// from `u_lambda`.
    fn beam(&self, u: [f64; 4], u_lambda: f64) -> Beam {
        let lambda = self.spd.sample_lambda(u_lambda);
        self.counter.increment();
        match self.emission_ray(u) {
            Some((origin, direction, pdf, cos)) if cos > 0.0 => {
                let le = self.radiance(-direction);
                let m = self.spectral_factor(origin, direction, lambda);
                let scale =
                    le * cos * 4.0 * PI * self.radius * self.radius * m / (self.power() * pdf);
                Beam::new(origin, direction, lambda, if scale.is_finite() { scale } else { 0.0 })
            }
            Some((origin, direction, ..)) => Beam::new(origin, direction, lambda, 0.0),
            None => Beam::new(self.center + DVec3::Z * self.radius, -DVec3::Z, lambda, 0.0),
        }
    }
}

#[typetag::serde]
impl LightSource for Environment {
    fn next_beam(&self, rng: &mut dyn Rng) -> Beam {
        let u = [uniform(rng), uniform(rng), uniform(rng), uniform(rng)];
        self.beam(u, uniform(rng))
    }

    fn next_beam_at(&self, u_lambda: f64, rng: &mut dyn Rng) -> Beam {
        let u = [uniform(rng), uniform(rng), uniform(rng), uniform(rng)];
        self.beam(u, u_lambda)
    }

    fn number_of_beams(&self) -> u64 {
        self.counter.total()
    }

    /// `pi R^2` times the radiance's integral over directions: the power crossing the sphere
    /// inwards.
    fn power(&self) -> f64 {
        PI * self.radius * self.radius * self.radiance_integral
    }

    fn spd(&self) -> Arc<dyn SpectralPowerDistribution> {
        self.spd.clone()
    }

    fn reset_count(&self) {
        self.counter.reset();
    }

    fn flags(&self) -> Option<LightFlags> {
        Some(LightFlags::default())
    }

    fn uniform_spectrum(&self) -> bool {
        false
    }

    fn spectral_factor(&self, position: DVec3, direction: DVec3, lambda: f64) -> f64 {
        let mut m = [0.0];
        self.spectral_factors(position, direction, &[lambda], &mut m);
        m[0]
    }

    fn spectral_factors(
        &self,
        _position: DVec3,
        direction: DVec3,
        lambdas: &[f64],
        out: &mut [f64],
    ) {
        // One lookup of the map for every wavelength.
        let c = self.corners(-direction);
        let integral: f64 = c.iter().map(|&(i, w)| w * self.nodes[i].integral).sum();
        let norm = 1.0 / (d65_luminance() * integral);
        for (o, &lambda) in out.iter_mut().zip(lambdas) {
            let rho: f64 = c.iter().map(|&(i, w)| w * self.nodes[i].rho.value(lambda)).sum();
            let m = rho * d65_visible(lambda) * norm / self.spd.value(lambda);
            *o = if m.is_finite() { m } else { 0.0 };
        }
    }

    fn origin_weight(&self, _beam: &Beam) -> f64 {
        1.0
    }

    fn emission_density(&self, origin: DVec3, direction: DVec3) -> f64 {
        let cos = self.inward_cos(origin, direction);
        if !(cos > 0.0) {
            return 0.0;
        }
        let d =
            self.radiance(-direction) * cos * 4.0 * PI * self.radius * self.radius / self.power();
        if d.is_finite() { d } else { 0.0 }
    }

    fn sample_towards(&self, receiver: DVec3, u: [f64; 2]) -> Option<LightSample> {
        let (omega, pdf) = self.sample_direction(u)?;
        let (position, distance) = self.exit(receiver, omega)?;
        let intensity = self.radiance(omega) * distance * distance / pdf;
        intensity.is_finite().then_some(LightSample {
            position,
            direction: -omega,
            distance,
            intensity,
            pdf,
            delta: false,
        })
    }

    fn pdf_towards(&self, receiver: DVec3, position: DVec3) -> f64 {
        let omega = (position - receiver).normalize_or_zero();
        if omega == DVec3::ZERO { 0.0 } else { self.pdf_direction(omega) }
    }

    fn emitted_radiance(&self, position: DVec3, direction: DVec3) -> f64 {
        if self.inward_cos(position, direction) > 0.0 { self.radiance(-direction) } else { 0.0 }
    }

    fn sample_emission(&self, u: [f64; 4]) -> Option<EmissionSample> {
        let (position, direction, pdf, cos) = self.emission_ray(u)?;
        (cos > 0.0).then(|| EmissionSample {
            position,
            normal: (self.center - position) / self.radius,
            direction,
            pdf_position: 1.0 / (4.0 * PI * self.radius * self.radius),
            pdf_direction: pdf,
        })
    }

    fn pdf_emission(&self, position: DVec3, direction: DVec3) -> Option<(f64, f64)> {
        let pdf_position = 1.0 / (4.0 * PI * self.radius * self.radius);
        let pdf_direction = if self.inward_cos(position, direction) > 0.0 {
            self.pdf_direction(-direction)
        } else {
            0.0
        };
        Some((pdf_position, pdf_direction))
    }

    fn normal_at(&self, position: DVec3) -> Option<DVec3> {
        Some((self.center - position).normalize_or_zero())
    }

    fn surface(&self) -> Option<LightSurface> {
        Some(LightSurface::Sphere { center: self.center, radius: self.radius })
    }
}
