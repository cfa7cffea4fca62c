"""The materials cross-check against Mitsuba 3 (`cargo xtask peer --materials`).

Run by the xtask inside the race's virtual environment (target/peer-venv), with
DRJIT_LIBLLVM_PATH set. Renders small scenes of Spectrace's rough and coated materials in both
renderers with their path tracers at high sample counts, compares the image means (X, Y, Z) and
an 8 x 8 grid of blocks, and writes docs/materials-peer.md. Not a race: nothing is timed.

Every scene is built here as a Spectrace scene (written to the work folder and rendered by the
`spectrace` binary) and as the Mitsuba dictionary of the same scene (the light, camera and
diffuse translations are the race's, `peer.py`). Noise: each side is rendered with `--seeds`
independent seeds; the standard error of a mean (or of a block) is the spread of the seeds'
values over sqrt(seeds).
"""

import argparse
import json
import math
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import peer  # noqa: E402  (the race's translator, image reader and renderers' helpers)
from peer import dr, mi  # noqa: E402

GRID = 8  # the image is compared as GRID x GRID blocks
SIZE = 64  # image width and height (pixels): 8 x 8 pixels per block
ETA, K = 0.2, 3.0  # the conductor's constant complex index
IOR = 1.5

# The light's spectrum (a smooth ramp over 360-830 nm) and the shared geometry.
LIGHT_SPD = {"type": "Tabulated", "nm": [360, 500, 600, 830], "values": [0.6, 0.9, 1.0, 0.8]}
CAMERA = {"position": [0, 1.2, 2.0], "look_at": [0, 0, -0.1], "fov": 45, "fov_axis": "horizontal", "width": SIZE, "height": SIZE}
# Floor: normal edge_u x edge_v = +y, first tangent +x in both renderers (checked at run time).
FLOOR = {"type": "Rectangle", "corner": [-1, 0, 1], "edge_u": [2, 0, 0], "edge_v": [0, 0, -2]}
# A small light facing down, placed so that the camera sees its mirror image on the floor.
SMALL_LIGHT = {"type": "RectangleLight", "corner": [-0.15, 1.2, -1.35], "edge_u": [0.3, 0, 0], "edge_v": [0, 0, 0.3], "power": 5, "spd": LIGHT_SPD}
# A larger light over the glass sphere (its caustic through the rough glass is otherwise noisy).
BIG_LIGHT = {"type": "RectangleLight", "corner": [-0.4, 1.5, -0.6], "edge_u": [0.8, 0, 0], "edge_v": [0, 0, 0.8], "power": 20, "spd": LIGHT_SPD}
BACK_WALL = {"type": "Rectangle", "corner": [-1, 0, -1], "edge_u": [2, 0, 0], "edge_v": [0, 1.5, 0]}
SPHERE = {"type": "Sphere", "center": [0, 0.35, 0.1], "radius": 0.3}


def table(value):
    """A constant Spectrace eta / k table."""
    return {"nm": [360, 830], "values": [value, value]}


def mi_conductor(alpha_u=None, alpha_v=None):
    if alpha_u is None:
        return {"type": "conductor", "eta": ETA, "k": K}
    d = {"type": "roughconductor", "distribution": "ggx", "eta": ETA, "k": K, "sample_visible": True}
    if alpha_u == alpha_v:
        d["alpha"] = alpha_u
    else:
        d["alpha_u"], d["alpha_v"] = alpha_u, alpha_v
    return d


def mi_plastic(alpha, nonlinear):
    d = {"int_ior": IOR, "ext_ior": 1.0, "diffuse_reflectance": {"type": "uniform", "value": 0.5}, "nonlinear": nonlinear}
    if alpha is None:
        d["type"] = "plastic"
    else:
        d.update({"type": "roughplastic", "distribution": "ggx", "alpha": alpha, "sample_visible": True})
    return d


def cases():
    """(name, title, Spectrace material of the floor or sphere, [(label, Mitsuba BSDF)], kind)."""
    out = [("diffuse", "Diffuse 0.5 floor (control: translation of light and camera)",
            {"type": "Diffuse", "reflectance": 0.5},
            [("diffuse", {"type": "twosided", "bsdf": {"type": "diffuse", "reflectance": {"type": "uniform", "value": 0.5}}})], "plane"),
           ("conductor", f"Conductor eta {ETA}, k {K}, smooth",
            {"type": "Conductor", "eta": table(ETA), "k": table(K)}, [("conductor", mi_conductor())], "plane")]
    for a in (0.05, 0.3, 0.7):
        out.append((f"rough_conductor_{a}", f"RoughConductor eta {ETA}, k {K}, alpha {a}",
                    {"type": "RoughConductor", "eta": table(ETA), "k": table(K), "roughness": a},
                    [("roughconductor", mi_conductor(a, a))], "plane"))
    out.append(("rough_conductor_aniso", f"RoughConductor eta {ETA}, k {K}, alpha_u 0.1 (along +x), alpha_v 0.5",
                {"type": "RoughConductor", "eta": table(ETA), "k": table(K), "roughness_u": 0.1, "roughness_v": 0.5},
                [("alpha_u 0.1, alpha_v 0.5 (same frame)", mi_conductor(0.1, 0.5)),
                 ("control: alphas swapped", mi_conductor(0.5, 0.1))], "plane"))
    for a in (0.1, 0.5):
        out.append((f"rough_dielectric_{a}", f"RoughDielectric sphere, ior {IOR}, alpha {a}, before a diffuse floor and wall",
                    {"type": "RoughDielectric", "ior": IOR, "roughness": a},
                    [("roughdielectric", {"type": "roughdielectric", "distribution": "ggx", "alpha": a, "int_ior": IOR, "ext_ior": 1.0, "sample_visible": True})],
                    "sphere"))
    out.append(("plastic_smooth", f"Plastic reflectance 0.5, ior {IOR}, smooth",
                {"type": "Plastic", "reflectance": 0.5, "ior": IOR, "roughness": 0},
                [("plastic, nonlinear true", mi_plastic(None, True)), ("plastic, nonlinear false", mi_plastic(None, False))], "plane"))
    # The coatings alone (a black base): the specular lobes without the diffuse part (and, smooth,
    # without the noise of choosing between them: both renderers then always pick the specular).
    out.append(("plastic_smooth_black", f"Plastic reflectance 0 (coating only), ior {IOR}, smooth",
                {"type": "Plastic", "reflectance": 0.0, "ior": IOR, "roughness": 0},
                [("plastic, diffuse_reflectance 0", dict(mi_plastic(None, True), diffuse_reflectance={"type": "uniform", "value": 0.0}))], "plane"))
    out.append(("plastic_rough_black", f"Plastic reflectance 0 (coating only), ior {IOR}, alpha 0.2",
                {"type": "Plastic", "reflectance": 0.0, "ior": IOR, "roughness": 0.2},
                [("roughplastic, diffuse_reflectance 0", dict(mi_plastic(0.2, True), diffuse_reflectance={"type": "uniform", "value": 0.0}))], "plane"))
    out.append(("plastic_rough", f"Plastic reflectance 0.5, ior {IOR}, alpha 0.2",
                {"type": "Plastic", "reflectance": 0.5, "ior": IOR, "roughness": 0.2},
                [("roughplastic, nonlinear true", mi_plastic(0.2, True)), ("roughplastic, nonlinear false", mi_plastic(0.2, False))], "plane"))
    return out


def spectrace_scene(material, kind):
    if kind == "plane":
        objects = [{"name": "floor", "shape": FLOOR, "material": material}]
        lights = [SMALL_LIGHT]
    else:
        diffuse = {"type": "Diffuse", "reflectance": 0.6}
        objects = [{"name": "floor", "shape": FLOOR, "material": diffuse},
                   {"name": "wall", "shape": BACK_WALL, "material": diffuse},
                   {"name": "sphere", "shape": SPHERE, "material": material}]
        lights = [BIG_LIGHT]
    return {"camera": CAMERA, "objects": objects, "lights": lights, "settings": {"integrator": "path"}}


def mitsuba_scene(scene, bsdf):
    """The race's translation of `scene` with the Mitsuba `bsdf` on the object of interest (the
    floor of a plane scene, the sphere of a sphere scene)."""
    plain = json.loads(json.dumps(scene))
    target = len(plain["objects"]) - 1
    plain["objects"][target]["material"] = {"type": "Diffuse", "reflectance": 0.5}
    d = peer.translate(plain, {"type": "path", "max_depth": 65})
    d[f"object{target}"]["bsdf"] = bsdf
    return d


def check_frames():
    """Mitsuba's shading frame on the floor: its first tangent must be +x and its normal +y, as
    Spectrace's `Frame::from_normal(+y)` (t = +x, b = -z). Returns the frame as text."""
    sc = mi.load_dict({"type": "scene", "floor": {"type": "rectangle", "to_world": peer.rectangle_to_world(FLOOR["corner"], FLOOR["edge_u"], FLOOR["edge_v"])}})
    si = sc.ray_intersect(mi.Ray3f(mi.Point3f(0.1, 1.0, 0.2), mi.Vector3f(0, -1, 0)))
    s, t, n = (np.array(v, dtype=np.float64).reshape(-1)[:3] for v in (si.sh_frame.s, si.sh_frame.t, si.sh_frame.n))
    ok = np.allclose(s, [1, 0, 0], atol=1e-6) and np.allclose(t, [0, 0, -1], atol=1e-6) and np.allclose(n, [0, 1, 0], atol=1e-6)
    return ok, f"s = {fmt_vec(s)}, t = {fmt_vec(t)}, n = {fmt_vec(n)}"


def fmt_vec(v):
    return "(" + ", ".join(f"{x:+.0f}" if abs(x - round(x)) < 1e-9 else f"{x:+.3f}" for x in v) + ")"


# ---------------------------------------------------------------------------------------------
# The expected ratio of separable to height-correlated Smith G (RoughConductor on the floor)


def ggx_lambda(w, ax, ay):
    t = (ax * w[..., 0]) ** 2 + (ay * w[..., 1]) ** 2
    z2 = w[..., 2] ** 2
    return 0.5 * (np.sqrt(1 + t / z2) - 1)


def predicted_ratio(ax, ay, sub=2, n=32, fresnel=None):
    """Quadrature of the floor's image under the small light with the separable G1(wi) G1(wo)
    (Mitsuba) over the height-correlated G (Spectrace); everything else (D, exact conductor F,
    geometry, the constant-index spectrum) is the same and cancels only per path. `sub`^2 rays
    per pixel, `n` x `n` points on the light. `fresnel` (of cos) defaults to the conductor's.
    Returns the ratio of the whole images and the (GRID, GRID) ratios of the blocks."""
    fresnel = fresnel or conductor_fresnel
    pos, dirs = peer.camera_rays(CAMERA, sub)
    t = -pos[1] / np.where(dirs[..., 1] < 0, dirs[..., 1], -1e-30)
    p = pos + t[..., None] * dirs
    inside = (dirs[..., 1] < 0) & (np.abs(p[..., 0]) < 1) & (np.abs(p[..., 2]) < 1)
    rows, cols, _ = np.nonzero(inside)
    block = (rows // (SIZE // GRID)) * GRID + cols // (SIZE // GRID)
    p = p[inside]
    wo = pos - p
    wo /= np.linalg.norm(wo, axis=1, keepdims=True)
    c, u, v = (np.array(SMALL_LIGHT[k], dtype=np.float64) for k in ("corner", "edge_u", "edge_v"))
    g = (np.arange(n) + 0.5) / n
    lp = (c + g[:, None, None] * u + g[None, :, None] * v).reshape(-1, 3)
    local = lambda w: np.stack([w[..., 0], -w[..., 2], w[..., 1]], axis=-1)  # (t, b, n) = (x, -z, y)
    corr, sep = np.zeros(GRID * GRID), np.zeros(GRID * GRID)
    for start in range(0, len(p), 1024):
        q, lo = p[start : start + 1024], local(wo[start : start + 1024])[:, None, :]
        d = lp[None, :, :] - q[:, None, :]
        r2 = (d**2).sum(axis=2)
        wi = d / np.sqrt(r2)[..., None]
        li = local(wi)
        cos_l = np.maximum(wi[..., 1], 0)  # the light faces -y
        h = li + lo
        h /= np.linalg.norm(h, axis=2, keepdims=True)
        s = (h[..., 0] / ax) ** 2 + (h[..., 1] / ay) ** 2 + h[..., 2] ** 2
        dist = 1 / (math.pi * ax * ay * s * s)
        fres = fresnel((li * h).sum(axis=2))
        lam_i, lam_o = ggx_lambda(li, ax, ay), ggx_lambda(lo, ax, ay)
        # f cos_i dA cos_l / r^2, with f = F D G / (4 cos_i cos_o)
        base = fres * dist / (4 * lo[..., 2]) * cos_l / r2
        np.add.at(corr, block[start : start + 1024], (base / (1 + lam_i + lam_o)).sum(axis=1))
        np.add.at(sep, block[start : start + 1024], (base / ((1 + lam_i) * (1 + lam_o))).sum(axis=1))
    per_block = np.where(corr > 0, sep / np.where(corr > 0, corr, 1), 1.0).reshape(GRID, GRID)
    return float(sep.sum() / corr.sum()), per_block


def conductor_fresnel(cos_i):
    """Exact unpolarised conductor Fresnel for eta + i k (the usual real-arithmetic form)."""
    c2 = cos_i**2
    s2 = 1 - c2
    e2, k2 = ETA**2, K**2
    t0 = e2 - k2 - s2
    a2b2 = np.sqrt(t0**2 + 4 * e2 * k2)
    a = np.sqrt(np.maximum(0.5 * (a2b2 + t0), 0))
    t1, t2 = a2b2 + c2, 2 * a * cos_i
    rs = (t1 - t2) / (t1 + t2)
    t3, t4 = c2 * a2b2 + s2 * s2, t2 * s2
    rp = rs * (t3 - t4) / (t3 + t4)
    return 0.5 * (rs + rp)


# ---------------------------------------------------------------------------------------------
# The rough plastic's diffuse term, Mitsuba's against Spectrace's model


def fresnel_dielectric(c, eta):
    c = np.clip(c, 0, 1)
    ct = np.sqrt(np.maximum(1 - (1 - c * c) / eta**2, 0))
    rs = (c - eta * ct) / (c + eta * ct)
    rp = (eta * c - ct) / (eta * c + ct)
    return 0.5 * (rs * rs + rp * rp)


def rough_albedo(mu, alpha, eta, n=128):
    """Spectrace's `S(mu)` (crates/materials/src/plastic.rs, as documented there): the albedo of
    the rough coating's specular lobe, F (wi.m) G(wi, wo) / G1(wi) averaged over the visible
    normals seen from wi (an n x n grid of the Heitz 2018 sampler), G the height-correlated form,
    reflections below the surface lost."""
    w = np.array([math.sqrt(max(1 - mu * mu, 0)), 0.0, mu])
    u1, u2 = np.meshgrid((np.arange(n) + 0.5) / n, (np.arange(n) + 0.5) / n)
    wh = np.array([alpha * w[0], 0.0, w[2]])
    wh /= np.linalg.norm(wh)
    # Heitz's t1 = (-wh.y, wh.x, 0) / |.|, with wh in the xz plane: +y (or +x at normal incidence).
    t1 = np.array([0.0, 1.0, 0.0]) if wh[0] > 0 else np.array([1.0, 0.0, 0.0])
    t2 = np.cross(wh, t1)
    r, phi = np.sqrt(u1), 2 * math.pi * u2
    p1, p2 = r * np.cos(phi), r * np.sin(phi)
    sw = 0.5 * (1 + wh[2])
    p2 = (1 - sw) * np.sqrt(np.maximum(1 - p1 * p1, 0)) + sw * p2
    nh = p1[..., None] * t1 + p2[..., None] * t2 + np.sqrt(np.maximum(1 - p1 * p1 - p2 * p2, 0))[..., None] * wh
    m = np.stack([alpha * nh[..., 0], alpha * nh[..., 1], np.maximum(nh[..., 2], 1e-12)], axis=-1)
    m /= np.linalg.norm(m, axis=-1, keepdims=True)
    d = (m * w).sum(axis=-1)
    wo = 2 * d[..., None] * m - w
    up = wo[..., 2] > 0
    wo = np.where(up[..., None], wo, np.array([0.0, 0.0, 1.0]))
    lam_i, lam_o = ggx_lambda(w, alpha, alpha), ggx_lambda(wo, alpha, alpha)
    return float(np.where(up, fresnel_dielectric(d, eta) * (1 + lam_i) / (1 + lam_i + lam_o), 0).mean())


def roughplastic_breakdown(alpha=0.2, eta=IOR):
    """Mitsuba's `roughplastic` diffuse term, read back from its BSDF (component 1 only, nonlinear
    true): its coating transmittance t(mu) and internal reflectance, against Spectrace's
    1 - S(mu) and F_dr = 1 - T / eta^2 from the model above."""

    def diffuse(refl, mu_o):
        bsdf = mi.load_dict(dict(mi_plastic(alpha, True), diffuse_reflectance={"type": "uniform", "value": refl}))
        ctx = mi.BSDFContext(mi.TransportMode.Radiance, mi.BSDFFlags.All, 1)
        si = dr.zeros(mi.SurfaceInteraction3f)
        si.sh_frame = mi.Frame3f(mi.Vector3f(0, 0, 1))
        si.wi = mi.Vector3f(0, 0, 1)
        wo = mi.Vector3f(math.sqrt(1 - mu_o * mu_o), 0, mu_o)
        return float(np.array(bsdf.eval(ctx, si, wo)).reshape(-1)[0]) / mu_o

    # f(R) = R / (1 - R r_int) t(1) t(mu) / (pi eta^2): two reflectances give r_int, then t.
    f_half, f_one = diffuse(0.5, 1.0), diffuse(1.0, 1.0)
    q = f_one / f_half
    r_int = (2 - q) / (1 - q)
    t1 = math.sqrt(f_half * math.pi * eta**2 * (1 - 0.5 * r_int) / 0.5)
    mus = (0.1, 0.3, 0.5, 0.7, 1.0)
    m_t = [diffuse(0.5, mu) * math.pi * eta**2 * (1 - 0.5 * r_int) / 0.5 / t1 for mu in mus]
    s_t = [1 - rough_albedo(mu, alpha, eta) for mu in mus]
    cs = (np.arange(200) + 0.5) / 200
    big_t = 2 * float(np.mean([(1 - rough_albedo(c, alpha, eta, 48)) * c for c in cs]))
    fdr = 1 - big_t / eta**2
    f_s = (1 - rough_albedo(1.0, alpha, eta)) ** 2 * 0.5 / (math.pi * eta**2 * (1 - 0.5 * fdr))
    return {"mu": list(mus), "mitsuba_t": m_t, "spectrace_t": s_t, "mitsuba_internal": r_int, "spectrace_fdr": fdr,
            "mitsuba_f_normal": f_half, "spectrace_f_normal": f_s}


# ---------------------------------------------------------------------------------------------
# Rendering and comparing


def log(msg):
    print(msg, file=sys.stderr, flush=True)


def blocks(img):
    """(GRID, GRID, 3) block means of a (SIZE, SIZE, 3) image."""
    b = SIZE // GRID
    return img.reshape(GRID, b, GRID, b, 3).mean(axis=(1, 3))


def sphere_pixels():
    """The pixels that see the sphere (any of 4 x 4 rays per pixel)."""
    pos, dirs = peer.camera_rays(CAMERA)
    return peer.hits_sphere(pos, dirs, np.array(SPHERE["center"], dtype=np.float64), SPHERE["radius"]).any(axis=2)


def masked_ratio(s_images, m_images, mask):
    """Mitsuba / Spectrace of the mean Y over `mask`, and its standard error (from the seeds)."""
    sm = np.array([i[..., 1][mask].mean() for i in s_images])
    mm = np.array([i[..., 1][mask].mean() for i in m_images])
    r = mm.mean() / sm.mean()
    se = r * math.sqrt((mm.std(ddof=1) / mm.mean()) ** 2 / len(mm) + (sm.std(ddof=1) / sm.mean()) ** 2 / len(sm))
    return float(r), float(se)


def stats(images):
    """Mean image, per-channel image mean with its standard error, block means with theirs."""
    stack = np.stack(images)
    k = len(images)
    means = stack.mean(axis=(1, 2))  # (k, 3)
    bl = np.stack([blocks(i) for i in images])  # (k, G, G, 3)
    return {
        "mean": means.mean(axis=0),
        "mean_se": means.std(axis=0, ddof=1) / math.sqrt(k),
        "blocks": bl.mean(axis=0),
        "blocks_se": bl.std(axis=0, ddof=1) / math.sqrt(k),
        "image": stack.mean(axis=0),
    }


def compare(s, m, expected):
    """Mitsuba over Spectrace: mean ratios per channel with their standard errors, and the Y
    blocks (those with at least 1% of the brightest block's Y): their ratios, and `z`, the
    difference of Mitsuba's block from `expected` (GRID x GRID) times Spectrace's over its
    standard error."""
    ratio = m["mean"] / s["mean"]
    ratio_se = ratio * np.sqrt((m["mean_se"] / m["mean"]) ** 2 + (s["mean_se"] / s["mean"]) ** 2)
    ys, ym = s["blocks"][..., 1], m["blocks"][..., 1]
    se = np.sqrt((expected * s["blocks_se"][..., 1]) ** 2 + m["blocks_se"][..., 1] ** 2)
    lit = np.maximum(ys, ym) >= 0.01 * max(ys.max(), ym.max())
    z = np.where(se > 0, (ym - expected * ys) / np.where(se > 0, se, 1), 0.0)
    br = (ym / np.where(ys > 0, ys, np.inf))[lit]
    return {
        "ratio": ratio.tolist(),
        "ratio_se": ratio_se.tolist(),
        "lit_blocks": int(lit.sum()),
        "block_ratio_min": float(br.min()),
        "block_ratio_median": float(np.median(br)),
        "block_ratio_max": float(br.max()),
        "block_z_max": float(np.abs(z[lit]).max()),
        "blocks_over_3": int((np.abs(z[lit]) > 3).sum()),
        "block_ratios": np.where(lit, ym / np.where(ys > 0, ys, np.inf), np.nan).round(3).tolist(),
    }


def render_spectrace(spectrace, scene, name, spp, seeds, work):
    path = os.path.join(work, "scenes", name + ".json")
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as f:
        json.dump(scene, f, indent=1)
    images, seconds = [], 0.0
    for k in range(seeds):
        xyz, secs, _ = spectrace.render(path, "path", spp, 500 + k, f"{name}-{k}")
        images.append(xyz)
        seconds += secs
    return images, seconds


def render_mitsuba(d, spp, seeds):
    sc = mi.load_dict(d)
    images = []
    t = time.perf_counter()
    for k in range(seeds):
        img = mi.render(sc, spp=spp, seed=700 + k)
        images.append(np.array(img, dtype=np.float64)[:, :, :3])
    return images, time.perf_counter() - t


def main():
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("--spectrace", required=True, help="the release `spectrace` binary")
    p.add_argument("--root", required=True, help="the workspace root")
    p.add_argument("--work", required=True, help="scratch directory (target/peer-materials)")
    p.add_argument("--spp", type=int, default=512, help="samples per pixel of each seed's render (both renderers)")
    p.add_argument("--seeds", type=int, default=8, help="independent renders per side (the noise estimate)")
    p.add_argument("--cases", default="", help="comma-separated subset of the cases (default all)")
    p.add_argument("--no-docs", action="store_true", help="do not write docs/materials-peer.md")
    args = p.parse_args()
    if args.seeds < 2 or args.spp < 1:
        sys.exit("materials: --seeds must be at least 2 and --spp at least 1")
    os.makedirs(args.work, exist_ok=True)
    mi.set_variant(peer.VARIANT)
    dr.set_thread_count(peer.THREADS)
    spectrace = peer.Spectrace(args.spectrace, args.work)
    frame_ok, frame = check_frames()
    log(f"Mitsuba's floor frame: {frame} ({'matches' if frame_ok else 'DIFFERS from'} Spectrace's t = +x, b = -z)")
    wanted = [c for c in args.cases.split(",") if c]
    known = [c[0] for c in cases()]
    for c in wanted:
        if c not in known:
            sys.exit(f"materials: --cases: unknown case `{c}` (known: {', '.join(known)})")
    started = time.time()
    report = {"mitsuba": mi.__version__, "drjit": dr.__version__, "variant": peer.VARIANT, "threads": peer.THREADS,
              "machine": peer.machine(), "date": time.strftime("%Y-%m-%d"), "spp": args.spp, "seeds": args.seeds,
              "frame_ok": bool(frame_ok), "frame": frame, "cases": []}
    control = 1.0  # Mitsuba / Spectrace on the diffuse control, once measured
    for name, title, material, variants, kind in cases():
        if wanted and name not in wanted:
            continue
        scene = spectrace_scene(material, kind)
        imgs, secs = render_spectrace(spectrace, scene, name, args.spp, args.seeds, args.work)
        s = stats(imgs)
        log(f"[{name}] Spectrace path {args.seeds} x {args.spp} spp: {secs:.1f} s, mean XYZ {s['mean'].round(6).tolist()}")
        entry = {"name": name, "title": title, "kind": kind, "material": material, "spectrace_seconds": secs,
                 "spectrace_mean": s["mean"].tolist(), "spectrace_mean_se": s["mean_se"].tolist(), "mitsuba": []}
        # The expected blocks: the control's offset (the translation's own, measured on the
        # diffuse floor) times the model difference predicted by quadrature where there is one.
        expected = np.full((GRID, GRID), control)
        predicted = None
        if material["type"] == "RoughConductor":
            ax = material.get("roughness", material.get("roughness_u"))
            ay = material.get("roughness", material.get("roughness_v"))
            predicted = predicted_ratio(ax, ay)
        elif material["type"] == "Plastic" and material["reflectance"] == 0 and material["roughness"] > 0:
            a = material["roughness"]
            predicted = predicted_ratio(a, a, fresnel=lambda c: fresnel_dielectric(c, IOR))
        if predicted is not None:
            entry["predicted_ratio"], entry["predicted_blocks"] = predicted[0], predicted[1].tolist()
            expected = expected * predicted[1]
            log(f"[{name}] predicted Mitsuba / Spectrace (separable / height-correlated G): {entry['predicted_ratio']:.4f}")
        np.save(os.path.join(args.work, f"{name}-spectrace.npy"), s["image"].astype(np.float32))
        for i, (label, bsdf) in enumerate(variants):
            mimgs, msecs = render_mitsuba(mitsuba_scene(scene, bsdf), args.spp, args.seeds)
            m = stats(mimgs)
            c = compare(s, m, expected if i == 0 else np.full((GRID, GRID), control))
            c.update({"label": label, "bsdf": bsdf, "seconds": msecs, "mean": m["mean"].tolist(), "mean_se": m["mean_se"].tolist()})
            entry["mitsuba"].append(c)
            np.save(os.path.join(args.work, f"{name}-mitsuba-{i}.npy"), m["image"].astype(np.float32))
            if kind == "sphere":
                mask = sphere_pixels()
                c["sphere_ratio"], c["sphere_ratio_se"] = masked_ratio(imgs, mimgs, mask)
                c["rest_ratio"], c["rest_ratio_se"] = masked_ratio(imgs, mimgs, ~mask)
                c["sphere_fraction"] = float(mask.mean())
            if name == "diffuse":
                control = c["ratio"][1]
            log(f"[{name}] Mitsuba {label}: {msecs:.1f} s, ratio XYZ {np.round(c['ratio'], 4).tolist()} "
                f"+- {np.round(c['ratio_se'], 4).tolist()}, blocks {c['block_ratio_min']:.3f}..{c['block_ratio_max']:.3f}, "
                f"|z| max {c['block_z_max']:.1f}, {c['blocks_over_3']}/{c['lit_blocks']} over 3")
        report["cases"].append(entry)
    if not wanted or "plastic_rough" in wanted:
        report["roughplastic"] = roughplastic_breakdown()
        log(f"roughplastic diffuse term at normal incidence, Mitsuba / Spectrace's model: "
            f"{report['roughplastic']['mitsuba_f_normal'] / report['roughplastic']['spectrace_f_normal']:.4f}")
    report["total_seconds"] = time.time() - started
    with open(os.path.join(args.work, "results.json"), "w") as f:
        json.dump(report, f, indent=1)
    log(f"results: {os.path.join(args.work, 'results.json')} ({report['total_seconds']:.0f} s)")
    if not args.no_docs:
        import materials_docs

        materials_docs.write(report, args.root)


if __name__ == "__main__":
    try:
        main()
    except peer.SceneError as e:
        sys.exit(f"materials: {e}")
