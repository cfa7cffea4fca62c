"""docs/peer.md, docs/peer.svg and the README's race table from the race's results (peer.py);
the samples-per-second section and block come from throughput_docs.py."""

import math
import os
import re

TARGETS = (0.10, 0.05)
COLOURS = {
    ("spectrace", "light"): "#d62728",
    ("spectrace", "path"): "#1f77b4",
    ("spectrace", "bdpt"): "#9467bd",
    ("mitsuba", "ptracer"): "#ff7f0e",
    ("mitsuba", "path"): "#2ca02c",
}
TITLES = {
    "spot_plane": "spot light over a plane",
    "cornell": "spectral Cornell box (area light)",
    "glass_sphere": "glass sphere under parallel light",
}
README_BEGIN = "<!-- peer:begin (written by cargo xtask peer) -->"
README_END = "<!-- peer:end -->"
# The geometry comparison's section of docs/peer.md (written by geometry.py), kept on a rewrite.
GEOMETRY_BEGIN = "<!-- geometry:begin (written by cargo xtask peer --geometry) -->"
GEOMETRY_END = "<!-- geometry:end -->"


def time_to(points, target):
    """(seconds, how): log-log interpolation between the points around target; the first point's
    time if it is already below (an upper bound); extrapolated with slope -1/2 if never reached."""
    if not points:
        return None, "cannot"
    if points[0]["rmse"] <= target:
        return points[0]["seconds"], "at most"
    for a, b in zip(points, points[1:]):
        if b["rmse"] <= target:
            la, lb = math.log(a["rmse"]), math.log(b["rmse"])
            f = (la - math.log(target)) / (la - lb) if la > lb else 1.0
            lt = math.log(a["seconds"]) + f * (math.log(b["seconds"]) - math.log(a["seconds"]))
            return math.exp(lt), "interpolated"
    last = points[-1]
    return last["seconds"] * (last["rmse"] / target) ** 2, "extrapolated"


def sig(v):
    if v is None:
        return "-"
    if v >= 100:
        return f"{v:.0f}"
    if v >= 10:
        return f"{v:.1f}"
    if v >= 1:
        return f"{v:.2f}"
    return f"{v:.3f}"


def fmt_time(t):
    secs, how = t
    if secs is None:
        return "cannot render"
    return {"at most": f"<= {sig(secs)} s", "interpolated": f"{sig(secs)} s", "extrapolated": f"~{sig(secs)} s (extrap.)"}[how]


def label(entry):
    return f"{'Spectrace' if entry['renderer'] == 'spectrace' else 'Mitsuba'} {entry['integrator']}"


def analyse(scene):
    """Per entry: times to each target and ratios to Mitsuba's best."""
    rows = []
    best = {}
    for target in TARGETS:
        times = [time_to(e["points"], target)[0] for e in scene["results"] if e["renderer"] == "mitsuba"]
        times = [t for t in times if t is not None]
        best[target] = min(times) if times else None
    for e in scene["results"]:
        row = {"entry": e, "times": {}, "ratios": {}}
        for target in TARGETS:
            t = time_to(e["points"], target)
            row["times"][target] = t
            row["ratios"][target] = t[0] / best[target] if t[0] is not None and best[target] else None
        rows.append(row)
    return rows, best


def verdicts(scene, rows):
    """The issue's two targets on this scene (at 10%): (text, met)."""
    by = {(r["entry"]["renderer"], r["entry"]["integrator"]): r for r in rows}
    out = []
    light, ptracer = by[("spectrace", "light")]["times"][0.10][0], by[("mitsuba", "ptracer")]["times"][0.10][0]
    if light is not None and ptracer is not None:
        r = light / ptracer
        out.append((f"Spectrace light / Mitsuba ptracer = {r:.2f} (target <= 0.5)", r <= 0.5))
    sp = [r["times"][0.10][0] for r in rows if r["entry"]["renderer"] == "spectrace" and r["times"][0.10][0]]
    mt = [r["times"][0.10][0] for r in rows if r["entry"]["renderer"] == "mitsuba" and r["times"][0.10][0]]
    if sp and mt:
        r = min(sp) / min(mt)
        fractions = {r["entry"].get("mask_fraction") for r in rows if r["times"][0.10][0]}
        note = " (measured on different pixels: see the table)" if len(fractions) > 1 else ""
        out.append((f"Spectrace best / Mitsuba best = {r:.2f} (target <= 0.5){note}", r <= 0.5))
    return out


def table(scene, rows):
    lines = [
        "| integrator | renders | time to 10% | time to 5% | / Mitsuba's best (10%) | / Mitsuba's best (5%) | mean / reference |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        e = r["entry"]
        part = "all" if not e["cannot"] else ("nothing" if e.get("mask_fraction") is None else f"{100 * e['mask_fraction']:.0f}% of pixels")
        ratio = lambda t: "-" if r["ratios"][t] is None else f"{r['ratios'][t]:.2f}"
        mean = "-" if not e["points"] else f"{e['points'][-1]['mean_ratio']:.4f}"
        lines.append(
            f"| {label(e)} | {part} | {fmt_time(r['times'][0.10])} | {fmt_time(r['times'][0.05])} | "
            f"{ratio(0.10)} | {ratio(0.05)} | {mean} |"
        )
    return "\n".join(lines)


def svg(report):
    """Log-log error against time, one panel per scene."""
    scenes = report["scenes"]
    pw, ph, ml, mr, mt, mb = 330, 260, 55, 15, 30, 45
    width = len(scenes) * (pw + ml + mr)
    height = ph + mt + mb + 60
    out = [
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" '
        f'font-family="sans-serif" font-size="11">',
        f'<rect width="{width}" height="{height}" fill="white"/>',
    ]
    for i, scene in enumerate(scenes):
        x0, y0 = i * (pw + ml + mr) + ml, mt
        pts = [(p["seconds"], p["rmse"]) for e in scene["results"] for p in e["points"] if p["seconds"] > 0]
        if not pts:
            continue
        tmin = 10 ** math.floor(math.log10(min(t for t, _ in pts)))
        tmax = 10 ** math.ceil(math.log10(max(t for t, _ in pts)))
        emin = 10 ** math.floor(math.log10(min(min(e for _, e in pts), 0.04)))
        emax = 10 ** math.ceil(math.log10(max(e for _, e in pts)))

        def X(t):
            return x0 + pw * (math.log10(t) - math.log10(tmin)) / (math.log10(tmax) - math.log10(tmin))

        def Y(e):
            return y0 + ph * (math.log10(emax) - math.log10(e)) / (math.log10(emax) - math.log10(emin))

        out.append(f'<rect x="{x0}" y="{y0}" width="{pw}" height="{ph}" fill="none" stroke="#444"/>')
        out.append(f'<text x="{x0 + pw / 2}" y="{y0 - 10}" text-anchor="middle" font-size="13">{TITLES.get(scene["scene"], scene["scene"])}</text>')
        d = tmin
        while d <= tmax * 1.001:
            out.append(f'<line x1="{X(d):.1f}" y1="{y0}" x2="{X(d):.1f}" y2="{y0 + ph}" stroke="#ddd"/>')
            out.append(f'<text x="{X(d):.1f}" y="{y0 + ph + 15}" text-anchor="middle">{d:g}</text>')
            d *= 10
        d = emin
        while d <= emax * 1.001:
            out.append(f'<line x1="{x0}" y1="{Y(d):.1f}" x2="{x0 + pw}" y2="{Y(d):.1f}" stroke="#ddd"/>')
            out.append(f'<text x="{x0 - 5}" y="{Y(d) + 4:.1f}" text-anchor="end">{100 * d:g}%</text>')
            d *= 10
        for target in TARGETS:
            out.append(f'<line x1="{x0}" y1="{Y(target):.1f}" x2="{x0 + pw}" y2="{Y(target):.1f}" stroke="#888" stroke-dasharray="4 3"/>')
        out.append(f'<text x="{x0 + pw / 2}" y="{y0 + ph + 32}" text-anchor="middle">render time (s, 2 threads)</text>')
        if i == 0:
            out.append(f'<text transform="translate({x0 - 42},{y0 + ph / 2}) rotate(-90)" text-anchor="middle">relative RMSE</text>')
        for e in scene["results"]:
            p = [(q["seconds"], q["rmse"]) for q in e["points"] if q["seconds"] > 0]
            if not p:
                continue
            colour = COLOURS[(e["renderer"], e["integrator"])]
            dash = "" if e["renderer"] == "spectrace" else ' stroke-dasharray="6 3"'
            path = " ".join(f"{X(t):.1f},{Y(v):.1f}" for t, v in p)
            out.append(f'<polyline points="{path}" fill="none" stroke="{colour}" stroke-width="1.8"{dash}/>')
            for t, v in p:
                out.append(f'<circle cx="{X(t):.1f}" cy="{Y(v):.1f}" r="2.5" fill="{colour}"/>')
    # Legend.
    lx, ly = ml, ph + mt + mb + 15
    for j, (key, colour) in enumerate(COLOURS.items()):
        x = lx + j * 170
        dash = "" if key[0] == "spectrace" else ' stroke-dasharray="6 3"'
        out.append(f'<line x1="{x}" y1="{ly}" x2="{x + 25}" y2="{ly}" stroke="{colour}" stroke-width="2"{dash}/>')
        name = ("Spectrace " if key[0] == "spectrace" else "Mitsuba ") + key[1]
        out.append(f'<text x="{x + 30}" y="{ly + 4}">{name}</text>')
    out.append(f'<text x="{lx}" y="{ly + 25}">dashed grey: 10% and 5%; solid: Spectrace, dashed: Mitsuba 3 {report["mitsuba"]} ({report["variant"]})</text>')
    out.append("</svg>")
    return "\n".join(out) + "\n"


def header(report):
    m = report["machine"]
    reused = ", with references reused from an earlier run" if any(sc["reference"].get("reused") for sc in report["scenes"]) else ""
    return (
        f"Command: `cargo xtask peer` ({report['date']}; Mitsuba {report['mitsuba']}, Dr.Jit "
        f"{report['drjit']}, variant `{report['variant']}`; {report['threads']} threads each; "
        f"machine: {m['cpu']}, `nproc` = {m['nproc']}, shared with other work; whole run "
        f"{report['total_seconds'] / 60:.0f} min{reused})."
    )


def summary_table(report):
    """One row per scene and integrator: the README's table."""
    lines = [
        "| scene | integrator | time to 10% | time to 5% | / Mitsuba's best (10%) |",
        "|---|---|---|---|---|",
    ]
    for scene in report["scenes"]:
        rows, _ = analyse(scene)
        for r in rows:
            ratio = "-" if r["ratios"][0.10] is None else f"{r['ratios'][0.10]:.2f}"
            lines.append(
                f"| {scene['scene']} | {label(r['entry'])} | {fmt_time(r['times'][0.10])} | "
                f"{fmt_time(r['times'][0.05])} | {ratio} |"
            )
    return "\n".join(lines)


def targets_text(report):
    lines = []
    for scene in report["scenes"]:
        rows, _ = analyse(scene)
        for text, met in verdicts(scene, rows):
            lines.append(f"- {scene['scene']}: {text}: {'met' if met else '**not met**'}")
    return "\n".join(lines)


def replace_between(text, begin, end, block):
    """`text` with the part from marker `begin` to marker `end` (markers included) replaced by
    `block`, or None if it lacks either marker: the one place docs blocks are rewritten."""
    if begin not in text or end not in text:
        return None
    return re.sub(re.escape(begin) + ".*?" + re.escape(end), lambda _: block, text, flags=re.S)


def kept_geometry_section(path):
    """The geometry comparison's block (markers included) of the docs/peer.md at `path`, or ""."""
    try:
        with open(path) as f:
            text = f.read()
    except OSError:
        return ""
    found = re.search(re.escape(GEOMETRY_BEGIN) + ".*?" + re.escape(GEOMETRY_END), text, flags=re.S)
    return found.group(0) if found else ""


def glass_text(scene):
    """The path tracers on the pixels that see the glass sphere (the reference cannot judge them):
    the mean Y of each one's last image there, and Spectrace's over Mitsuba's."""
    means = {(e["renderer"], e["integrator"]): e["glass_mean"] for e in scene["results"] if "glass_mean" in e}
    ours, theirs = means.get(("spectrace", "path")), means.get(("mitsuba", "path"))
    if ours is None or theirs is None or not theirs > 0:
        return ""
    others = ", ".join(f"{label({'renderer': r, 'integrator': i})} {v:.3e}" for (r, i), v in sorted(means.items()))
    return (
        f"On the pixels that see the glass sphere (no reference there): Spectrace path / Mitsuba path = "
        f"**{ours / theirs:.4f}** (mean Y of each one's last image; issue 23's target: within 2%). All: {others}.\n"
    )


def write(report, root, method_path=None):
    docs = os.path.join(root, "docs")
    with open(os.path.join(docs, "peer.svg"), "w") as f:
        f.write(svg(report))
    method_path = method_path or os.path.join(root, "xtask", "peer", "method.md")
    with open(method_path) as f:
        method = f.read()
    parts = ["# The race against Mitsuba 3\n", header(report) + "\n", "![relative RMSE against render time](peer.svg)\n"]
    parts.append("## Targets (time to 10%)\n\n" + targets_text(report) + "\n")
    for scene in report["scenes"]:
        rows, best = analyse(scene)
        ref = scene["reference"]
        parts.append(
            f"## {TITLES.get(scene['scene'], scene['scene'])} (`{scene['scene']}`, {scene['width']}x{scene['height']})\n\n"
            f"Reference: {ref['integrator']}, {ref['work']:,} {ref['unit']} in two halves of different seeds "
            f"({sig(ref['seconds'])} s); its own noise (half the RMSE between the halves): "
            f"{100 * ref['noise']:.2f}%.\n\n" + table(scene, rows) + "\n"
        )
        cannot = [f"- {label(e)}: cannot render {e['cannot']}." for e in scene["results"] if e["cannot"]]
        if cannot:
            parts.append("\n".join(cannot) + "\n")
        pts = []
        for e in scene["results"]:
            if e["points"]:
                p = e["points"][-1]
                extra = f", kernel compile before the ladder {sig(e['compile_seconds'])} s (not timed)" if "compile_seconds" in e else ""
                pts.append(
                    f"- {label(e)}: {len(e['points'])} renders, last {p['effort']:,} {p['unit']} in "
                    f"{sig(p['seconds'])} s: {100 * p['rmse']:.2f}%, mean {p['mean_ratio']:.4f} of the reference{extra}"
                )
        parts.append("Ladders:\n\n" + "\n".join(pts) + "\n")
        parts.append(glass_text(scene))
    throughput = None
    if report.get("throughput"):
        import throughput_docs as throughput  # imported here: it needs Mitsuba, geometry.py does not

        parts.append(throughput.section(report) + "\n")
    parts.append(method)
    path = os.path.join(docs, "peer.md")
    geometry = kept_geometry_section(path)
    if geometry:
        parts.append(geometry + "\n")
    with open(path, "w") as f:
        f.write("\n".join(parts))
    readme = os.path.join(root, "README.md")
    with open(readme) as f:
        text = f.read()
    section = (
        f"{README_BEGIN}\n{header(report)}\n\n{summary_table(report)}\n\nTargets (Spectrace's light "
        f"tracer in at most half of Mitsuba's `ptracer` time to 10%, Spectrace's best in at most half of "
        f"Mitsuba's best):\n\n{targets_text(report)}\n"
        + (f"\n{throughput.readme_block(report)}\n" if throughput else "")
        + README_END
    )
    replaced = replace_between(text, README_BEGIN, README_END, section)
    if replaced is not None:
        text = replaced
    else:
        text = text.rstrip("\n") + "\n\n## The race against Mitsuba 3\n\n" + section + "\n"
    with open(readme, "w") as f:
        f.write(text)
