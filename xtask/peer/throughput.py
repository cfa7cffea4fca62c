"""Samples per second at equal spp: part of the race (`cargo xtask peer`), or alone with
`cargo xtask peer --throughput-only` (about a minute).

Every race scene (translated by peer.py) is rendered at one equal effort, 2 threads each, by
Spectrace's `path` (spp samples per pixel) and `light` (spp x pixels light paths, `--beams`), and
by Mitsuba 3's `path` (spp samples per pixel) and `ptracer` (spp x pixels light paths) in two
variants: `llvm_ad_spectral` (kernels compiled by untimed warm-up renders, as in the race) and
`scalar_spectral` (one sample at a time in C++, nothing compiled). Each of the `reps` rounds
renders every row once, interleaved, so that load from other work spreads over all rows; the
fastest round counts. Spectrace's time is its sidecar's `wall_seconds`: the render loop alone,
after the process started, the scene loaded and the pre-render probe ran, before the outputs are
written (the whole process's time is kept beside it). Mitsuba's is the timed `mi.render` call of
the race (peer.Mitsuba), film developed and copied to numpy included.
"""

import json
import os
import statistics
import time

import numpy as np

import peer
from peer import log, mi

VARIANTS = ("llvm_ad_spectral", "scalar_spectral")
# (renderer, Mitsuba variant, integrator), in the order rendered and tabled.
ROWS = (
    ("spectrace", None, "path"),
    ("spectrace", None, "light"),
    ("mitsuba", "llvm_ad_spectral", "path"),
    ("mitsuba", "llvm_ad_spectral", "ptracer"),
    ("mitsuba", "scalar_spectral", "path"),
    ("mitsuba", "scalar_spectral", "ptracer"),
)
# The rows Spectrace's two estimators are compared with: (Spectrace integrator, Mitsuba integrator).
PAIRS = (("path", "path"), ("light", "ptracer"))
LIGHT_TRACERS = ("light", "ptracer")


def new_row(renderer, variant, integrator, masks):
    """An empty row; `mask` None when the integrator cannot render the scene (the race's masks)."""
    mask, cannot = masks[(renderer, integrator)]
    return {
        "renderer": renderer,
        "variant": variant,
        "integrator": integrator,
        "unit": "light paths" if integrator in LIGHT_TRACERS else "camera samples",
        "cannot": cannot if mask is None else "",
        "mask": mask,
        "all_seconds": [],
        "process_seconds": [],
        "rmse": None,
    }


def render_row(row, scene, name, path, spp, seed, spectrace, mitsubas):
    """One render of `row` at the equal effort: (XYZ image, seconds, work done)."""
    pixels = int(scene["camera"]["width"]) * int(scene["camera"]["height"])
    integrator = row["integrator"]
    if row["renderer"] == "spectrace":
        effort = spp * pixels if integrator == "light" else spp
        xyz, secs, work = spectrace.render(path, integrator, effort, seed, f"{name}-throughput-{integrator}")
        row["process_seconds"].append(spectrace.process_seconds)
        return xyz, secs, work
    # Mitsuba's ptracer traces spp x pixels light paths; its path tracer spp samples per pixel.
    xyz, secs = mitsubas[row["variant"]].render(scene, name, integrator, spp, seed)
    return xyz, secs, spp * pixels


def measure_scene(name, args, spectrace, mitsubas, reference):
    """The rows of one scene: every round renders each row once; the fastest round counts."""
    path = os.path.join(args.scenes_dir, name + ".json")
    with open(path) as f:
        scene = json.load(f)
    masks, _ = peer.masks_for(name, scene)
    rows = [new_row(r, v, i, masks) for r, v, i in ROWS]
    spp = args.throughput_spp
    for rep in range(args.throughput_reps):
        for row in rows:
            if row["cannot"]:
                continue
            xyz, secs, work = render_row(row, scene, name, path, spp, 2000 + rep, spectrace, mitsubas)
            row["work"] = work
            row["all_seconds"].append(secs)
            if rep == 0 and reference is not None:
                row["rmse"] = peer.relative_rmse(xyz, reference, row["mask"])
            log(f"[{name}] throughput {label(row)}: {work:,} {row['unit']} in {secs:.3f} s")
    for row in rows:
        del row["mask"]
        if row["all_seconds"]:
            row["seconds"] = min(row["all_seconds"])
            row["median_seconds"] = statistics.median(row["all_seconds"])
            row["per_second"] = row["work"] / row["seconds"]
    return {"scene": name, "width": scene["camera"]["width"], "height": scene["camera"]["height"], "rows": rows}


def label(row):
    """`Spectrace path`, `Mitsuba llvm path`, `Mitsuba scalar ptracer`."""
    if row["renderer"] == "spectrace":
        return f"Spectrace {row['integrator']}"
    return f"Mitsuba {row['variant'].split('_')[0]} {row['integrator']}"


def find(scene, renderer, integrator, variant=None):
    """The row of `scene` for the renderer, integrator and variant, or None."""
    for row in scene["rows"]:
        if (row["renderer"], row["integrator"], row["variant"]) == (renderer, integrator, variant):
            return row
    return None


def ratios(scene):
    """{(Spectrace integrator, Mitsuba variant): Spectrace's rate / Mitsuba's} where both ran."""
    out = {}
    for ours, theirs in PAIRS:
        a = find(scene, "spectrace", ours)
        for variant in VARIANTS:
            b = find(scene, "mitsuba", theirs, variant)
            if a and b and a.get("per_second") and b.get("per_second"):
                out[(ours, variant)] = a["per_second"] / b["per_second"]
    return out


def attach_race(result, race):
    """Puts the race's time to 10% (peer_docs.time_to) on each row the race also ran (Spectrace's
    rows and Mitsuba's in the race's variant), and the race's date on the result."""
    import peer_docs

    result["race_date"] = race["date"]
    for scene in result["scenes"]:
        raced = next((s for s in race["scenes"] if s["scene"] == scene["scene"]), None)
        for row in scene["rows"]:
            if raced is None or row["variant"] not in (None, race["variant"]):
                continue
            entry = next(
                (e for e in raced["results"] if (e["renderer"], e["integrator"]) == (row["renderer"], row["integrator"])),
                None,
            )
            if entry is not None:
                row["time_to_10"] = list(peer_docs.time_to(entry["points"], 0.10))


def run(args, spectrace, names, race=None, rmse=False):
    """The throughput of every scene of `names`; with `rmse`, each first round's relative RMSE
    against the race's reference (target/peer/NAME-reference.npy, just written by the race); with
    `race` (a race report), the race's time to 10% beside each row."""
    mitsubas = {v: peer.Mitsuba(v) for v in VARIANTS}
    load = os.getloadavg()[0]
    started = time.time()
    result = {"spp": args.throughput_spp, "reps": args.throughput_reps, "threads": peer.THREADS, "scenes": []}
    for name in names:
        reference = None
        if rmse:
            reference = np.load(os.path.join(args.work, f"{name}-reference.npy")).astype(np.float64)
        result["scenes"].append(measure_scene(name, args, spectrace, mitsubas, reference))
    mi.set_variant(peer.VARIANT)
    result["load_average"] = [load, os.getloadavg()[0]]
    result["seconds"] = time.time() - started
    if race is not None and race.get("scenes"):
        attach_race(result, race)
    import throughput_docs

    print(f"{throughput_docs.compact(result)}\n\n{throughput_docs.verdict_lines(result)}", flush=True)
    return result


def alone(args, report, spectrace, names, started):
    """`--throughput-only`: the throughput with the time to 10% of an earlier race's
    results.json in the work folder if there is one; writes throughput.json and, unless
    --no-docs, the throughput sections of docs/peer.md and of the README's race block."""
    earlier = None
    try:
        with open(os.path.join(args.work, "results.json")) as f:
            earlier = json.load(f)
    except (OSError, ValueError):
        pass
    report["throughput"] = run(args, spectrace, names, race=earlier)
    report["total_seconds"] = time.time() - started
    out = os.path.join(args.work, "throughput.json")
    with open(out, "w") as f:
        json.dump(report, f, indent=1)
    log(f"throughput: {out} ({report['total_seconds']:.0f} s)")
    if not args.no_docs:
        import throughput_docs

        throughput_docs.write_alone(report, args.root)
