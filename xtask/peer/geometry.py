"""Spectrace's geometry benchmark beside Embree 4 (`cargo xtask peer --geometry`).

Run by the xtask inside the peer virtual environment (target/peer-venv, with the pinned
`embreex` and numpy). This script first pins itself to one core, then runs the release example
`ray_rate` of spectrace-geometry as its child (same core, same process tree): it times
`World::intersect` (closest hit) and `World::occluded` (shadow rays, t_max 2.5) on the geometry
benchmark's mesh (102,400 triangles) and rays, and dumps that mesh and those rays, rounded to
f32, with its own answers. Embree is then given exactly that data (`embreex`: one
`rtcIntersect1` / `rtcOccluded1` per ray in a C loop, single-threaded), timed over as many
repetitions, and checked ray by ray against Spectrace's hits. Both sides report their best
repetition (the one least disturbed by other work on the machine), and the median beside it.

Embree is timed twice: with the robust scene flag (embreex's default; watertight like
Spectrace's test) and with no scene flags (Embree's own default, its fastest). The rate of a
batched `scene.run` call includes that call's fixed Python overhead (argument checks, allocating
the output arrays); it is measured on one-ray calls and printed, and is far below 1% of a
100,000-ray call.

Writes target/peer-geometry/geometry.md and, unless --no-docs, the "Geometry beside Embree"
section of docs/peer.md (between the geometry markers, which the race's report keeps).
"""

import argparse
import datetime
import json
import os
import platform
import statistics
import subprocess
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from peer_docs import GEOMETRY_BEGIN as BEGIN  # noqa: E402  (the markers the race's report keeps)
from peer_docs import GEOMETRY_END as END  # noqa: E402
from peer_docs import replace_between  # noqa: E402

TARGET = 0.6  # the target: Spectrace >= 0.6 x Embree's closest-hit rays/s on one core


def pin(cpu):
    """Pins this process (and so its children, and Embree's TBB pool, which sizes itself from the
    affinity mask) to `cpu`."""
    os.sched_setaffinity(0, {cpu})


def run_spectrace(binary, work, rays, reps):
    """Runs the ray_rate example with --dump into `work`; its JSON report."""
    cmd = [binary, "--rays", str(rays), "--reps", str(reps), "--dump", work]
    print("$ " + " ".join(cmd), file=sys.stderr, flush=True)
    out = subprocess.run(cmd, check=True, stdout=subprocess.PIPE, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def load(work):
    """The dumped scene: vertices (V x 3 f32), triangles (T x 3 u32), ray origins and directions
    (R x 3 f32), Spectrace's closest t (f64, inf for a miss) and triangle, occluded flags, and the
    shadow rays' t_max."""
    with open(os.path.join(work, "scene.json")) as f:
        meta = json.load(f)

    def read(name, dtype, shape):
        a = np.fromfile(os.path.join(work, name), dtype=np.dtype(dtype).newbyteorder("<"))
        if a.size != int(np.prod(shape)):
            raise SystemExit(f"{name}: {a.size} values, expected {shape}")
        return a.reshape(shape).astype(np.dtype(dtype).newbyteorder("="))

    v, t, r = meta["vertices"], meta["triangles"], meta["rays"]
    return {
        "vertices": read("vertices.f32", "f4", (v, 3)),
        "triangles": read("triangles.u32", "u4", (t, 3)).astype(np.int32),
        "origins": np.ascontiguousarray(read("origins.f32", "f4", (r, 3))),
        "directions": np.ascontiguousarray(read("directions.f32", "f4", (r, 3))),
        "closest_t": read("closest_t.f64", "f8", (r,)),
        "closest_triangle": read("closest_triangle.u32", "u4", (r,)),
        "occluded": read("occluded.u8", "u1", (r,)).astype(bool),
        "shadow_t_max": float(meta["shadow_t_max"]),
    }


def embree_scene(data, robust):
    """An embreex scene of the mesh, committed (its BVH built); the scene, the seconds to copy the
    mesh into Embree's buffers, and the seconds of the BVH build (the commit)."""
    from embreex import rtcore as rtc
    from embreex import rtcore_scene as rtcs
    from embreex.mesh_construction import TriangleMesh

    scene = rtcs.EmbreeScene(rtc.EmbreeDevice(), robust=robust)
    start = time.perf_counter()
    TriangleMesh(scene, data["vertices"], data["triangles"])
    copied = time.perf_counter()
    scene.run(data["origins"][:1], data["directions"][:1], query="DISTANCE")  # commits the scene
    return scene, copied - start, time.perf_counter() - copied


def time_query(scene, data, query, dists, reps):
    """The best and median seconds of `reps` calls of one query over all rays, and the last
    call's result."""
    seconds = []
    for _ in range(reps):
        start = time.perf_counter()
        result = scene.run(data["origins"], data["directions"], dists=dists, query=query)
        seconds.append(time.perf_counter() - start)
    return min(seconds), statistics.median(seconds), result


def call_overhead(scene, data, calls=2000):
    """The median seconds of a one-ray closest-hit call: an upper bound of the fixed cost of a
    `scene.run` call (it includes tracing that ray)."""
    o, d = data["origins"][:1].copy(), data["directions"][:1].copy()
    seconds = []
    for _ in range(calls):
        start = time.perf_counter()
        scene.run(o, d, query="INTERSECT")
        seconds.append(time.perf_counter() - start)
    return statistics.median(seconds)


def check(scene, data):
    """Embree's answers against Spectrace's, ray by ray: closest hits (count, hit/miss
    disagreements, different triangles, largest relative difference in t) and shadow rays."""
    out = scene.run(data["origins"], data["directions"], query="INTERSECT", output=1)
    hit = out["primID"] >= 0
    ours = np.isfinite(data["closest_t"])
    both = hit & ours
    rel = np.abs(out["tfar"][both].astype(np.float64) - data["closest_t"][both]) / data["closest_t"][both]
    blocked = scene.run(data["origins"], data["directions"], dists=data["shadow_t_max"], query="OCCLUDED") == 0
    return {
        "closest_hits": int(hit.sum()),
        "closest_disagree": int((hit != ours).sum()),
        "other_triangle": int((out["primID"][both].astype(np.int64) != data["closest_triangle"][both]).sum()),
        "max_rel_t": float(rel.max()) if rel.size else 0.0,
        "shadow_hits": int(blocked.sum()),
        "shadow_disagree": int((blocked != data["occluded"]).sum()),
    }


def measure_embree(data, robust, reps):
    """Build, rates (best and median of `reps`), per-call overhead and the check of one Embree
    configuration."""
    scene, copy_s, build_s = embree_scene(data, robust)
    n = len(data["origins"])
    c_best, c_median, _ = time_query(scene, data, "INTERSECT", None, reps)
    s_best, s_median, _ = time_query(scene, data, "OCCLUDED", data["shadow_t_max"], reps)
    return {
        "robust": robust,
        "copy_seconds": copy_s,
        "build_seconds": build_s,
        "closest_rays_per_second": n / c_best,
        "closest_rays_per_second_median": n / c_median,
        "shadow_rays_per_second": n / s_best,
        "shadow_rays_per_second_median": n / s_median,
        "call_overhead_seconds": call_overhead(scene, data),
        "closest_seconds": c_best,
        **check(scene, data),
    }


def cpu_name():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def rate(x):
    return f"{x / 1e6:.2f} M"


def report(ours, embrees, info):
    """The markdown section: the command line, the rates table, the ratios and target, the check."""
    robust, fast = embrees
    ev = info["embree"]
    lines = [
        "## Geometry beside Embree\n",
        f"Command: `cargo xtask peer --geometry` ({info['date']}; Embree {ev} through embreex "
        f"{info['embreex']}; one thread, both pinned to core {info['cpu']}; machine: {info['machine']}, "
        f"`nproc` = {info['nproc']}, load average {info['load']:.2f} at the start; "
        f"{ours['rays']:,} rays, best of {ours['reps']} repetitions, median in brackets).\n",
        f"The geometry benchmark's mesh (`bench_scenes::bumpy_sphere(160)`: {ours['triangles']:,} triangles, "
        f"{ours['vertices']:,} vertices) and rays (`bench_scenes::rays`: from radius 3 towards the unit "
        f"ball), rounded to f32 so that both engines get bit for bit the same input. Spectrace: "
        f"`World::intersect` and `World::occluded` (t_max {info['t_max']}) of the `ray_rate` example "
        f"(f64, watertight). Embree: embreex's `scene.run`, one `rtcIntersect1` / `rtcOccluded1` per ray "
        f"in a C loop (single rays, no packets); its rates include each call's fixed Python cost, measured "
        f"on one-ray calls at {robust['call_overhead_seconds'] * 1e6:.1f} us "
        f"({100 * robust['call_overhead_seconds'] / robust['closest_seconds']:.2f}% of a closest-hit call). "
        "embreex exposes no packet or stream queries; `rtcIntersect1` is Embree's call for incoherent "
        "single rays like these.\n",
        "| engine | closest hit (rays/s) | shadow rays (rays/s) | BVH build |",
        "|---|---|---|---|",
        f"| Spectrace | {rate(ours['closest_rays_per_second'])} ({rate(ours['closest_rays_per_second_median'])}) "
        f"| {rate(ours['shadow_rays_per_second'])} ({rate(ours['shadow_rays_per_second_median'])}) "
        f"| {ours['build_seconds'] * 1e3:.0f} ms |",
    ]
    for e in embrees:
        name = "robust (embreex's default)" if e["robust"] else "no scene flags (Embree's default)"
        lines.append(
            f"| Embree, {name} | {rate(e['closest_rays_per_second'])} ({rate(e['closest_rays_per_second_median'])}) "
            f"| {rate(e['shadow_rays_per_second'])} ({rate(e['shadow_rays_per_second_median'])}) "
            f"| {e['build_seconds'] * 1e3:.0f} ms |"
        )
    for e in embrees:
        name = "robust" if e["robust"] else "no flags"
        c = ours["closest_rays_per_second"] / e["closest_rays_per_second"]
        s = ours["shadow_rays_per_second"] / e["shadow_rays_per_second"]
        b = ours["build_seconds"] / e["build_seconds"]
        lines.append(f"| **Spectrace / Embree {name}** | **{c:.2f}** | **{s:.2f}** | {b:.2f} (time) |")
    lines.append("")
    for e in embrees:
        name = "robust" if e["robust"] else "with no scene flags"
        c = ours["closest_rays_per_second"] / e["closest_rays_per_second"]
        verdict = "met" if c >= TARGET else "**not met**"
        lines.append(
            f"- Target: Spectrace >= {TARGET}x Embree's closest-hit rays/s on one core, against Embree {name}: "
            f"{c:.2f}x, {verdict}."
        )
    lines.append("")
    lines.append("| check | Spectrace | Embree robust | Embree no flags |")
    lines.append("|---|---|---|---|")
    lines.append(f"| closest hits | {ours['closest_hits']:,} | {robust['closest_hits']:,} | {fast['closest_hits']:,} |")
    lines.append(f"| shadow rays blocked | {ours['shadow_hits']:,} | {robust['shadow_hits']:,} | {fast['shadow_hits']:,} |")
    lines.append(f"| rays hit by one engine only | | {robust['closest_disagree']} | {fast['closest_disagree']} |")
    lines.append(f"| shadow rays blocked for one engine only | | {robust['shadow_disagree']} | {fast['shadow_disagree']} |")
    lines.append(f"| hits on another triangle (ties on shared edges) | | {robust['other_triangle']} | {fast['other_triangle']} |")
    lines.append(
        f"| largest relative difference in t | | {robust['max_rel_t']:.1e} | {fast['max_rel_t']:.1e} |"
    )
    lines.append("")
    lines.append(
        "Every ray of this benchmark aims into the sphere and every shadow ray ends beyond its near side, "
        "so the counts agree by design: the per-ray rows of the check compare the engines. "
        "Embree's BVH build time is the scene commit alone (copying the mesh into its buffers, "
        f"{robust['copy_seconds'] * 1e3:.0f} ms through embreex's Python loop, is left out); Spectrace's is "
        "`World::new`; both are single builds. Embree computes in f32, Spectrace in f64: t agrees to f32 "
        "rounding."
    )
    return "\n".join(lines) + "\n"


def write_docs(root, section):
    """Replaces (or appends) the geometry section of docs/peer.md."""
    path = os.path.join(root, "docs", "peer.md")
    with open(path) as f:
        text = f.read()
    block = f"{BEGIN}\n{section}{END}"
    replaced = replace_between(text, BEGIN, END, block)
    text = replaced if replaced is not None else text.rstrip("\n") + "\n\n" + block + "\n"
    with open(path, "w") as f:
        f.write(text)
    print(f"wrote {path}", file=sys.stderr)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--ray-rate", required=True, help="the release `ray_rate` example of spectrace-geometry")
    p.add_argument("--root", required=True, help="the workspace root")
    p.add_argument("--work", required=True, help="scratch directory (target/peer-geometry)")
    p.add_argument("--rays", type=int, default=100_000, help="rays per repetition (default 100,000)")
    p.add_argument("--reps", type=int, default=5, help="repetitions of each query (default 5)")
    p.add_argument("--cpu", type=int, default=None, help="the core to pin to (default: the last allowed)")
    p.add_argument("--no-docs", action="store_true", help="do not write docs/peer.md")
    args = p.parse_args()

    cpu = args.cpu if args.cpu is not None else max(os.sched_getaffinity(0))
    load_avg = os.getloadavg()[0]
    pin(cpu)  # before embreex is imported, and inherited by the Rust example
    ours = run_spectrace(args.ray_rate, args.work, args.rays, args.reps)
    data = load(args.work)
    embrees = [measure_embree(data, robust, args.reps) for robust in (True, False)]

    import embreex
    from embreex import rtcore as rtc

    info = {
        "date": datetime.date.today().isoformat(),
        "embree": repr(rtc.EmbreeDevice()).split(":")[-1].strip(),
        "embreex": embreex.__version__,
        "cpu": cpu,
        "machine": cpu_name(),
        "nproc": os.cpu_count(),
        "load": load_avg,
        "t_max": data["shadow_t_max"],
    }
    section = report(ours, embrees, info)
    print("\n" + section)
    os.makedirs(args.work, exist_ok=True)
    with open(os.path.join(args.work, "geometry.md"), "w") as f:
        f.write(section)
    with open(os.path.join(args.work, "geometry.json"), "w") as f:
        json.dump({"spectrace": ours, "embree": embrees, "info": info}, f, indent=1)
    if not args.no_docs:
        write_docs(args.root, section)
    bad = [e for e in embrees if abs(e["closest_hits"] - ours["closest_hits"]) > 10 or abs(e["shadow_hits"] - ours["shadow_hits"]) > 10]
    if bad:
        print("Embree's hit counts differ from Spectrace's by more than 10 rays: not the same scene?", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
