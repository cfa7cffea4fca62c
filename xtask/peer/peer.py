"""The race of Spectrace against Mitsuba 3 (`cargo xtask peer`; method in docs/peer.md).

Run by the xtask inside the virtual environment it builds (target/peer-venv), with
DRJIT_LIBLLVM_PATH set. Translates the Spectrace scenes of xtask/peer/scenes into Mitsuba
dictionaries, renders a shared reference per scene, then every integrator of both renderers at
doubling effort (2 threads each), then the samples per second of Spectrace's path and light
tracers beside Mitsuba's path and ptracer in its llvm_ad_spectral and scalar_spectral variants
at one equal effort (throughput.py), and writes docs/peer.md, docs/peer.svg and the README table.
With --throughput-only, only the samples per second (about a minute): no reference, no ladders;
it rewrites only the throughput sections of docs/peer.md and of the README's race block.
"""

import argparse
import hashlib
import json
import math
import os
import platform
import subprocess
import sys
import time

import numpy as np

try:
    import drjit as dr
    import mitsuba as mi
except ImportError as e:  # pragma: no cover - the xtask installs both
    sys.exit(f"peer: cannot import Mitsuba 3 ({e}); run through `cargo xtask peer`")

VARIANT = "llvm_ad_spectral"
THREADS = 2
TARGETS = (0.10, 0.05)
SCENES = ("spot_plane", "cornell", "glass_sphere")
# The shared reference of each scene: the Spectrace integrator that converges fastest on all of
# it (the path tracer where next-event estimation reaches every light; the light tracer for the
# caustic of parallel light, which only light paths carry), and the seconds of each of its halves.
REFERENCE = {"spot_plane": ("path", 25.0), "cornell": ("path", 75.0), "glass_sphere": ("light", 90.0)}
INTEGRATORS = (
    ("spectrace", "light"),
    ("spectrace", "path"),
    ("spectrace", "bdpt"),
    ("mitsuba", "ptracer"),
    ("mitsuba", "path"),
)


class SceneError(Exception):
    """A scene the translator does not support, naming the field."""


# ---------------------------------------------------------------------------------------------
# Spectra


def trapezoid(nm, values):
    """Integral of the piecewise-linear function through (nm, values)."""
    return float(sum((nm[i + 1] - nm[i]) * (values[i] + values[i + 1]) / 2 for i in range(len(nm) - 1)))


def normalised_spd(spd, field):
    """The Spectrace SPD `spd` as (nm, values per nm) with integral 1, exactly as Spectrace's
    `Tabulated` normalises it (linear between nodes, zero outside). Only `Tabulated` SPDs spanning
    360-830 nm are translated: both renderers then hold the same piecewise-linear function."""
    if spd.get("type") != "Tabulated":
        raise SceneError(f"{field}.type: only Tabulated spectra are translated, not {spd.get('type')}")
    nm, values = [float(x) for x in spd["nm"]], [float(x) for x in spd["values"]]
    if nm[0] > 360 or nm[-1] < 830:
        raise SceneError(f"{field}.nm: the table must cover 360-830 nm (Mitsuba's range)")
    total = trapezoid(nm, values)
    return nm, [v / total for v in values]


def mi_irregular(nm, values):
    """A Mitsuba `irregular` spectrum: the same piecewise-linear table."""
    return {
        "type": "irregular",
        "wavelengths": ", ".join(repr(float(x)) for x in nm),
        "values": ", ".join(repr(float(x)) for x in values),
    }


def mi_reflectance(value, field):
    """A Spectrace reflectance (number, or table constant beyond its ends) as a Mitsuba spectrum
    with the same values on 360-830 nm."""
    if isinstance(value, (int, float)):
        return {"type": "uniform", "value": float(value)}
    nm, values = [float(x) for x in value["nm"]], [float(x) for x in value["values"]]
    if nm[0] > 360:
        nm, values = [360.0] + nm, [values[0]] + values
    if nm[-1] < 830:
        nm, values = nm + [830.0], values + [values[-1]]
    if len(nm) < 2:
        raise SceneError(f"{field}: a table needs two points")
    return mi_irregular(nm, values)


# ---------------------------------------------------------------------------------------------
# Geometry


def vec(v):
    return np.array([float(x) for x in v])


def rectangle_to_world(corner, u, v):
    """Mitsuba's rectangle is [-1, 1]^2 in z = 0 with normal +z: map it onto
    `corner + s u + t v`, normal `u x v` (u, v orthogonal in every race scene)."""
    corner, u, v = vec(corner), vec(u), vec(v)
    n = np.cross(u, v)
    n /= np.linalg.norm(n)
    m = np.identity(4)
    m[:3, 0], m[:3, 1], m[:3, 2] = u / 2, v / 2, n
    m[:3, 3] = corner + u / 2 + v / 2
    return mi.ScalarTransform4f(m.tolist())


def rectangle_area(u, v):
    return float(np.linalg.norm(np.cross(vec(u), vec(v))))


def look_at(origin, target, up):
    return mi.ScalarTransform4f().look_at(
        origin=[float(x) for x in origin], target=[float(x) for x in target], up=[float(x) for x in up]
    )


def any_up(direction):
    d = vec(direction)
    d /= np.linalg.norm(d)
    return [0, 0, 1] if abs(d[1]) > 0.9 else [0, 1, 0]


# ---------------------------------------------------------------------------------------------
# The translator


def translate(scene, integrator):
    """The Mitsuba dictionary of a Spectrace scene (the subset the race scenes use)."""
    cam = scene["camera"]
    if cam.get("aperture_radius", 0) != 0:
        raise SceneError("camera.aperture_radius: only pinhole cameras are translated")
    axis = {"horizontal": "x", "vertical": "y", "diagonal": "diagonal"}[cam.get("fov_axis", "horizontal")]
    d = {
        "type": "scene",
        "sensor": {
            "type": "perspective",
            "fov": float(cam["fov"]),
            "fov_axis": axis,
            "to_world": look_at(cam["position"], cam["look_at"], cam.get("up", [0, 1, 0])),
            "near_clip": 1e-4,
            "far_clip": 1e4,
            "sampler": {"type": "independent"},
            "film": {
                "type": "hdrfilm",
                "width": int(cam["width"]),
                "height": int(cam["height"]),
                "pixel_format": "xyz",
                "component_format": "float32",
                "rfilter": {"type": "box"},
                "sample_border": False,
            },
        },
        "integrator": integrator,
    }
    for i, obj in enumerate(scene["objects"]):
        field = f"objects[{i}]"
        if "emission" in obj or "transform" in obj:
            raise SceneError(f"{field}: emission and transform are not translated")
        d[f"object{i}"] = translate_shape(obj["shape"], f"{field}.shape")
        d[f"object{i}"]["bsdf"] = translate_material(obj["material"], f"{field}.material")
    for i, light in enumerate(scene.get("lights", [])):
        d[f"light{i}"] = translate_light(light, f"lights[{i}]")
    return d


def translate_shape(shape, field):
    kind = shape.get("type")
    if "transform" in shape:
        raise SceneError(f"{field}.transform: not translated")
    if kind == "Sphere":
        return {"type": "sphere", "center": [float(x) for x in shape["center"]], "radius": float(shape["radius"])}
    if kind == "Rectangle":
        return {"type": "rectangle", "to_world": rectangle_to_world(shape["corner"], shape["edge_u"], shape["edge_v"])}
    raise SceneError(f"{field}.type: {kind} is not translated (Sphere, Rectangle)")


def translate_material(material, field):
    kind = material.get("type")
    if kind == "Diffuse":
        # Spectrace's Lambertian is two-sided; Mitsuba's `diffuse` is black from behind.
        refl = mi_reflectance(material["reflectance"], f"{field}.reflectance")
        return {"type": "twosided", "bsdf": {"type": "diffuse", "reflectance": refl}}
    if kind == "Dielectric":
        if not isinstance(material["ior"], (int, float)) or material.get("transmittance", 1) != 1:
            raise SceneError(f"{field}.ior: only a constant ior with transmittance 1 is translated")
        # Spectrace's outside is vacuum; Mitsuba's default ext_ior is air (1.000277).
        return {"type": "dielectric", "int_ior": float(material["ior"]), "ext_ior": 1.0}
    raise SceneError(f"{field}.type: {kind} is not translated (Diffuse, Dielectric)")


def translate_light(light, field):
    kind = light.get("type")
    if light.get("wavelength_sampling", "importance") != "importance":
        raise SceneError(f"{field}.wavelength_sampling: only importance is translated")
    power = float(light["power"])
    nm, s = normalised_spd(light["spd"], f"{field}.spd")
    if kind == "UniformSpotLight":
        # P W spread uniformly over a cone of half-angle c: intensity P / (2 pi (1 - cos c)) W/sr,
        # times the normalised SPD (nm^-1). Mitsuba's `spot` is full intensity up to beam_width
        # and falls linearly in angle to 0 at cutoff_angle: beam_width = cutoff_angle is a hard cone.
        cone = float(light["cone_angle"])
        scale = power / (2 * math.pi * (1 - math.cos(math.radians(cone))))
        pos, direction = vec(light["position"]), vec(light["direction"])
        return {
            "type": "spot",
            "to_world": look_at(pos, pos + direction, any_up(direction)),
            "cutoff_angle": cone,
            "beam_width": cone,
            "intensity": mi_irregular(nm, [scale * x for x in s]),
        }
    if kind == "RectangleLight":
        if light.get("two_sided", False):
            raise SceneError(f"{field}.two_sided: only one-sided area lights are translated")
        # A one-sided Lambertian emitter of area A radiates L = P / (pi A) W m^-2 sr^-1.
        area = rectangle_area(light["edge_u"], light["edge_v"])
        scale = power / (math.pi * area)
        return {
            "type": "rectangle",
            "to_world": rectangle_to_world(light["corner"], light["edge_u"], light["edge_v"]),
            # Spectrace's area light reflects nothing.
            "bsdf": {"type": "diffuse", "reflectance": {"type": "uniform", "value": 0.0}},
            "emitter": {"type": "area", "radiance": mi_irregular(nm, [scale * x for x in s])},
        }
    if kind == "Sky":
        # P W in parallel beams from a rectangle of area A whose normal makes an angle a with the
        # beams: the irradiance across the beams is E = P / (A |cos a|) W m^-2. Mitsuba's
        # `directional` lights the whole scene; the race's Sky rectangles cover everything.
        u, v, direction = vec(light["edge_u"]), vec(light["edge_v"]), vec(light["direction"])
        n = np.cross(u, v)
        cos_a = abs(float(np.dot(n, direction) / (np.linalg.norm(n) * np.linalg.norm(direction))))
        scale = power / (rectangle_area(u, v) * cos_a)
        return {
            "type": "directional",
            "direction": [float(x) for x in direction],
            "irradiance": mi_irregular(nm, [scale * x for x in s]),
        }
    raise SceneError(f"{field}.type: {kind} is not translated (UniformSpotLight, RectangleLight, Sky)")


# ---------------------------------------------------------------------------------------------
# Images


def srgb_to_xyz_matrix():
    """Spectrace's linear sRGB -> XYZ matrix (crates/spectrum/src/cie.rs: from the primaries and
    the D65 white point, white at Y = 1)."""

    def col(xy):
        x, y = xy
        return np.array([x / y, 1.0, (1.0 - x - y) / y])

    primaries = np.stack([col(p) for p in [(0.64, 0.33), (0.30, 0.60), (0.15, 0.06)]], axis=1)
    s = np.linalg.solve(primaries, col((0.3127, 0.3290)))
    return primaries * s


SRGB_TO_XYZ = srgb_to_xyz_matrix()


def read_spectrace(out_dir, name):
    """The XYZ image (h, w, 3, float64) and the sidecar of a Spectrace render."""
    with open(os.path.join(out_dir, name + ".json")) as f:
        sidecar = json.load(f)
    rgb = np.array(mi.Bitmap(os.path.join(out_dir, name + ".exr")), dtype=np.float64)[:, :, :3]
    rgb *= 2.0 ** -int(sidecar.get("exr_scale_log2", 0))
    return rgb @ SRGB_TO_XYZ.T, sidecar


def relative_rmse(image, reference, mask):
    """The accuracy report's definition (crates/lab, relative_rmse), sqrt(sum |xyz - ref|^2 / sum |ref|^2), over the pixels of mask."""
    diff = ((image - reference) ** 2).sum(axis=2)[mask].sum()
    norm = (reference**2).sum(axis=2)[mask].sum()
    return float(math.sqrt(diff / norm))


def mean_ratio(image, reference, mask):
    return float(image[:, :, 1][mask].sum() / reference[:, :, 1][mask].sum())


# ---------------------------------------------------------------------------------------------
# Masks: what each integrator can render


def camera_rays(cam, sub=4):
    """Directions of sub x sub rays per pixel (h, w, sub*sub, 3), Spectrace's pinhole."""
    w, h = int(cam["width"]), int(cam["height"])
    pos, target = vec(cam["position"]), vec(cam["look_at"])
    fwd = target - pos
    fwd /= np.linalg.norm(fwd)
    right = np.cross(fwd, vec(cam.get("up", [0, 1, 0])))
    right /= np.linalg.norm(right)
    up = np.cross(right, fwd)
    half = math.tan(math.radians(float(cam["fov"])) / 2)
    axis = cam.get("fov_axis", "horizontal")
    scale = {"horizontal": w, "vertical": h, "diagonal": math.hypot(w, h)}[axis] / 2
    offs = (np.arange(sub) + 0.5) / sub
    px = (np.arange(w)[:, None] + offs[None, :]).reshape(-1)
    py = (np.arange(h)[:, None] + offs[None, :]).reshape(-1)
    x = (px - w / 2) / scale * half
    y = (h / 2 - py) / scale * half
    X, Y = np.meshgrid(x, y)
    d = fwd[None, None, :] + X[:, :, None] * right + Y[:, :, None] * up
    d /= np.linalg.norm(d, axis=2, keepdims=True)
    return pos, d.reshape(h, sub, w, sub, 3).transpose(0, 2, 1, 3, 4).reshape(h, w, sub * sub, 3)


def hits_sphere(origin, dirs, center, radius):
    oc = origin - center
    b = (dirs * oc).sum(axis=-1)
    c = float(oc @ oc) - radius * radius
    disc = b * b - c
    return (disc > 0) & (-b + np.sqrt(np.maximum(disc, 0)) > 0)


def glass_masks(scene):
    """For a scene with one glass sphere over a floor at y = 0 under straight-down parallel light:
    `glass` (pixels that see the sphere: no light tracer can render them, the camera must see the
    glass) and `caustic` (floor within 3 radii of the sphere's axis: its caustic and shadow, and
    the strongest of its reflections, which a path tracer cannot render from a delta light)."""
    sphere = next(o for o in scene["objects"] if o["material"]["type"] == "Dielectric")["shape"]
    center, radius = vec(sphere["center"]), float(sphere["radius"])
    pos, dirs = camera_rays(scene["camera"])
    glass = hits_sphere(pos, dirs, center, radius).any(axis=2)
    t = -pos[1] / np.where(dirs[..., 1] < 0, dirs[..., 1], -1e-30)
    floor = pos[None, None, None, :] + t[..., None] * dirs
    near = np.hypot(floor[..., 0] - center[0], floor[..., 2] - center[2]) < 3 * radius
    caustic = (near & (dirs[..., 1] < 0)).any(axis=2) & ~glass
    return glass, caustic


def masks_for(name, scene):
    """name -> {integrator key: (mask, what it cannot render)}."""
    h, w = int(scene["camera"]["height"]), int(scene["camera"]["width"])
    everything = np.ones((h, w), dtype=bool)
    if name != "glass_sphere":
        return {key: (everything, "") for key in INTEGRATORS}, everything
    glass, caustic = glass_masks(scene)
    no_glass = ~glass
    return {
        ("spectrace", "light"): (no_glass, "the glass seen by the camera (black)"),
        ("spectrace", "bdpt"): (no_glass, "the glass seen by the camera (left out of the shared reference)"),
        ("spectrace", "path"): (no_glass & ~caustic, "the caustic and reflections of the sphere on the floor"),
        ("mitsuba", "ptracer"): (no_glass, "the glass seen by the camera (black)"),
        ("mitsuba", "path"): (no_glass & ~caustic, "the caustic and reflections of the sphere on the floor"),
    }, no_glass


# ---------------------------------------------------------------------------------------------
# Renderers


class Spectrace:
    def __init__(self, binary, work):
        self.binary, self.work = binary, work
        self.out = os.path.join(work, "spectrace")
        # The wall time of the last render's whole process (start, scene load, probe, render,
        # outputs written), beside the sidecar's render-only `wall_seconds`.
        self.process_seconds = None

    def cached(self, tag, meta):
        """The image, time and work of an earlier render `tag` made with `meta`, or None."""
        try:
            with open(os.path.join(self.out, tag + ".meta.json")) as f:
                if json.load(f) != meta:
                    return None
            xyz, sidecar = read_spectrace(self.out, tag)
            return xyz, float(sidecar["wall_seconds"]), int(sidecar["beams"])
        except (OSError, ValueError, KeyError, RuntimeError):
            return None

    def remember(self, tag, meta):
        with open(os.path.join(self.out, tag + ".meta.json"), "w") as f:
            json.dump(meta, f)

    def render(self, scene_path, integrator, effort, seed, tag, seconds=None):
        """Renders with `effort` beams (light) or samples per pixel, or for `seconds` if given;
        the XYZ image, the render's wall time and the work done (beams or camera samples)."""
        out = os.path.join(self.work, "spectrace")
        name = f"{tag}"
        cmd = [self.binary, "render", scene_path, "--integrator", integrator, "--threads", str(THREADS)]
        cmd += ["--seed", str(seed), "--out", out, "--quiet"]
        if seconds is not None:
            cmd += ["--time", str(seconds)]
        else:
            cmd += ["--beams", str(effort)] if integrator == "light" else ["--spp", str(effort)]
        # The output name comes from the scene: write a copy named after the tag.
        with open(scene_path) as f:
            scene = json.load(f)
        scene.setdefault("output", {})["name"] = name
        scene["output"]["png"] = False
        copy = os.path.join(self.work, "scenes", os.path.basename(scene_path))
        os.makedirs(os.path.dirname(copy), exist_ok=True)
        with open(copy, "w") as f:
            json.dump(scene, f)
        cmd[2] = copy
        started = time.perf_counter()
        done = subprocess.run(cmd, capture_output=True, text=True)
        self.process_seconds = time.perf_counter() - started
        if done.returncode != 0:
            raise RuntimeError(f"spectrace failed: {' '.join(cmd)}\n{done.stderr}")
        xyz, sidecar = read_spectrace(out, name)
        return xyz, float(sidecar["wall_seconds"]), int(sidecar["beams"])


class Mitsuba:
    """Mitsuba renders in one variant: the race's JIT-compiled `llvm_ad_spectral` by default, or
    another (the throughput's `scalar_spectral`), switched to before each render (Mitsuba 3 keeps
    every variant loaded in one process). Only JIT variants are warmed up: scalar ones compile
    nothing."""

    def __init__(self, variant=VARIANT):
        self.variant = variant
        self.jit = variant.startswith(("llvm", "cuda"))
        self.scenes = {}
        self.warm = set()
        self.compile_seconds = 0.0

    def render(self, scene, name, integrator, spp, seed):
        """The XYZ image of `spp` samples per pixel and the seconds of the timed render."""
        if mi.variant() != self.variant:
            mi.set_variant(self.variant)
        key = (name, integrator)
        if key not in self.scenes:
            self.scenes[key] = mi.load_dict(translate(scene, {"type": integrator, "max_depth": 65}))
            if self.jit:
                # Warm-up: trace and compile the kernels once (Dr.Jit caches them) so the timed
                # renders measure rendering, not the LLVM compiler. Sample counts only ever grow:
                # a render asking for fewer samples than the one before it was seen to render the
                # earlier count (a 2-spp render after a 4-spp one had the 4-spp image and time).
                t = time.perf_counter()
                self._go(self.scenes[key], 1, 0)
                self.warm.add((key, 1))
                self.compile_seconds = time.perf_counter() - t
        sc = self.scenes[key]
        if (key, spp) not in self.warm and self.jit:
            # Mitsuba's ptracer compiles a kernel per sample count: warm it up untimed too.
            self._go(sc, spp, seed + 100_000)
            self.warm.add((key, spp))
        t = time.perf_counter()
        xyz = self._go(sc, max(spp, 1), seed)
        return xyz, time.perf_counter() - t

    @staticmethod
    def _go(sc, spp, seed):
        img = mi.render(sc, spp=spp, seed=seed)
        return np.array(img, dtype=np.float64)[:, :, :3]


# ---------------------------------------------------------------------------------------------
# The race


def log(msg):
    print(msg, file=sys.stderr, flush=True)


def race_scene(args, name, spectrace, mitsuba):
    path = os.path.join(args.scenes_dir, name + ".json")
    with open(path) as f:
        scene = json.load(f)
    w, h = int(scene["camera"]["width"]), int(scene["camera"]["height"])
    pixels = w * h
    masks, ref_mask = masks_for(name, scene)

    # The shared reference: two halves with different seeds.
    ref_integrator, ref_seconds = REFERENCE[name]
    ref_seconds *= args.reference_scale
    log(f"[{name}] reference: Spectrace {ref_integrator}, 2 x {ref_seconds} s")
    halves = []
    beams = 0
    reused = False
    with open(path, "rb") as f:
        fingerprint = hashlib.sha256(f.read()).hexdigest()
    for seed in (1001, 1002):
        tag = f"{name}-ref-{seed}"
        # A reference half is kept (target/peer/spectrace) and reused while the scene file, the
        # integrator and the time are the same.
        meta = {"scene_sha256": fingerprint, "integrator": ref_integrator, "seconds": ref_seconds, "seed": seed}
        cached = spectrace.cached(tag, meta)
        if cached is None:
            cached = spectrace.render(path, ref_integrator, None, seed, tag, ref_seconds)
            spectrace.remember(tag, meta)
        else:
            log(f"[{name}] reference half {seed}: reused from target/peer/spectrace/{tag}.exr")
            reused = True
        xyz, secs, done = cached
        halves.append((xyz, secs))
        beams += done
    reference = (halves[0][0] + halves[1][0]) / 2
    ref_noise = relative_rmse(halves[0][0], halves[1][0], ref_mask) / 2
    ref_seconds = halves[0][1] + halves[1][1]
    log(f"[{name}] reference noise {ref_noise:.4f} ({ref_seconds:.1f} s)")

    results = []
    for renderer, integrator in INTEGRATORS:
        mask, cannot = masks[(renderer, integrator)]
        entry = {"renderer": renderer, "integrator": integrator, "cannot": cannot, "points": []}
        results.append(entry)
        if mask is None:
            log(f"[{name}] {renderer} {integrator}: cannot render this scene ({cannot})")
            continue
        entry["mask_fraction"] = float(mask.mean())
        k = 0
        while True:
            seed = 10 + k
            if renderer == "spectrace" and integrator == "light":
                effort = pixels * (1 << k) // 4
                xyz, secs, _ = spectrace.render(path, integrator, effort, seed, f"{name}-{integrator}-{k}")
                unit = "beams"
            elif renderer == "spectrace":
                effort = 1 << k
                xyz, secs, _ = spectrace.render(path, integrator, effort, seed, f"{name}-{integrator}-{k}")
                unit = "spp"
            else:
                effort = 1 << k
                xyz, secs = mitsuba.render(scene, name, integrator, effort, seed)
                unit = "spp"
            err = relative_rmse(xyz, reference, mask)
            ratio = mean_ratio(xyz, reference, mask)
            entry["points"].append({"effort": effort, "unit": unit, "seconds": secs, "rmse": err, "mean_ratio": ratio})
            log(f"[{name}] {renderer} {integrator} {effort} {unit}: {secs:.3f} s, rmse {err:.4f}, mean ratio {ratio:.4f}")
            k += 1
            reached = err <= TARGETS[1] * args.overshoot
            if (reached and len(entry["points"]) >= 3) or secs > args.max_seconds or k > 16:
                break
        if renderer == "mitsuba":
            entry["compile_seconds"] = mitsuba.compile_seconds
        entry["final_xyz_mean"] = float(xyz[:, :, 1][mask].mean())
        if name == "glass_sphere":
            # Mean Y of the last image over the pixels that see the sphere, which the shared
            # reference (a light tracer's) cannot judge: the path tracers are compared there.
            entry["glass_mean"] = float(xyz[:, :, 1][~ref_mask].mean())
        np.save(os.path.join(args.work, f"{name}-{renderer}-{integrator}.npy"), xyz.astype(np.float32))
    np.save(os.path.join(args.work, f"{name}-reference.npy"), reference.astype(np.float32))
    return {
        "scene": name,
        "width": w,
        "height": h,
        "reference": {
            "integrator": f"Spectrace {ref_integrator}",
            "work": beams,
            "unit": "beams" if ref_integrator == "light" else "camera samples", "seconds": ref_seconds, "noise": ref_noise, "reused": reused},
        "results": results,
    }


def arguments():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--spectrace", required=True, help="the release `spectrace` binary")
    p.add_argument("--root", required=True, help="the workspace root")
    p.add_argument("--work", required=True, help="scratch directory (target/peer)")
    p.add_argument("--scenes", default=",".join(SCENES), help="the race scenes, comma-separated")
    p.add_argument("--reference-scale", type=float, default=1.0, help="multiplies the references' times")
    p.add_argument("--max-seconds", type=float, default=30.0, help="stop a ladder after a render this long")
    p.add_argument("--overshoot", type=float, default=0.9, help="stop a ladder below overshoot x 5%%")
    p.add_argument(
        "--throughput-only",
        action="store_true",
        help="measure only the samples per second at equal spp (no reference, no ladders; about a "
        "minute); writes target/peer/throughput.json and only the throughput sections of the docs",
    )
    p.add_argument(
        "--throughput-spp",
        type=int,
        default=64,
        help="the equal effort of the throughput: samples per pixel, and spp x pixels light paths",
    )
    p.add_argument("--throughput-reps", type=int, default=3, help="repetitions of the throughput (best kept)")
    p.add_argument("--no-docs", action="store_true", help="do not write docs/peer.md and the README")
    args = p.parse_args()
    args.scenes_dir = os.path.join(args.root, "xtask", "peer", "scenes")
    return args


def main():
    args = arguments()
    os.makedirs(args.work, exist_ok=True)
    mi.set_variant(VARIANT)
    dr.set_thread_count(THREADS)
    spectrace = Spectrace(args.spectrace, args.work)
    started = time.time()
    report = {
        "mitsuba": mi.__version__,
        "drjit": dr.__version__,
        "variant": VARIANT,
        "threads": THREADS,
        "machine": machine(),
        "date": time.strftime("%Y-%m-%d"),
        "scenes": [],
    }
    names = args.scenes.split(",")
    import throughput

    if args.throughput_only:
        throughput.alone(args, report, spectrace, names, started)
        return
    mitsuba = Mitsuba()
    for name in names:
        report["scenes"].append(race_scene(args, name, spectrace, mitsuba))
    report["throughput"] = throughput.run(args, spectrace, names, race=report, rmse=True)
    report["total_seconds"] = time.time() - started
    with open(os.path.join(args.work, "results.json"), "w") as f:
        json.dump(report, f, indent=1)
    log(f"results: {os.path.join(args.work, 'results.json')} ({report['total_seconds']:.0f} s)")
    if not args.no_docs:
        import peer_docs

        peer_docs.write(report, args.root)


def machine():
    cpu = platform.processor() or "unknown CPU"
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return {"cpu": cpu, "nproc": os.cpu_count(), "system": platform.platform()}


if __name__ == "__main__":
    # throughput.py imports this script as `peer`: let it find this module, not load a second copy.
    sys.modules.setdefault("peer", sys.modules[__name__])
    try:
        main()
    except SceneError as e:
        sys.exit(f"peer: {e}")
