"""The throughput's tables (throughput.py): the section "Samples per second at equal spp" of
docs/peer.md and a compact block inside the README's race block, both between markers so that
`--throughput-only` can rewrite them alone."""

import os

import peer_docs
from peer_docs import replace_between as replace
from peer_docs import sig
from throughput import PAIRS, VARIANTS, find, label, ratios

BEGIN = "<!-- throughput:begin (written by cargo xtask peer, or alone by --throughput-only) -->"
END = "<!-- throughput:end -->"
README_BEGIN = "<!-- peer-throughput:begin -->"
README_END = "<!-- peer-throughput:end -->"
# The targets: Spectrace's rate / Mitsuba llvm's, at least this, on these scenes.
TARGETS = (
    ("path", ("spot_plane", "cornell"), 0.5),
    ("light", None, 1.0),
)


def rate(x):
    return "-" if x is None else f"{x / 1e6:.2f} M"


def rounds(t):
    return f"best of {t['reps']} rounds" if t["reps"] > 1 else "1 round"


def header(report):
    t, m = report["throughput"], report["machine"]
    command = "cargo xtask peer" if report.get("scenes") else "cargo xtask peer --throughput-only"
    load = " to ".join(f"{x:.2f}" for x in t["load_average"])
    return (
        f"Command: `{command}` ({report['date']}; Mitsuba {report['mitsuba']}, Dr.Jit {report['drjit']}, "
        f"variants `{'` and `'.join(VARIANTS)}`; {t['threads']} threads each; machine: {m['cpu']}, "
        f"`nproc` = {m['nproc']}, shared with other work, load average {load}; {t['spp']} spp: "
        f"{t['spp']} camera samples per pixel, {t['spp']} x pixels light paths; {rounds(t)}, median "
        f"in brackets; {t['seconds']:.0f} s in all)."
    )


def verdicts(t):
    """The issue's targets on each scene: (text, met)."""
    out = []
    for scene in t["scenes"]:
        r = ratios(scene)
        for ours, scenes, target in TARGETS:
            if (scenes is None or scene["scene"] in scenes) and (ours, VARIANTS[0]) in r:
                x = r[(ours, VARIANTS[0])]
                theirs = dict(PAIRS)[ours]
                text = f"{scene['scene']}: Spectrace {ours} / Mitsuba llvm {theirs} = {x:.2f} (target >= {target:g})"
                out.append((text, x >= target))
    return out


def verdict_lines(t):
    return "\n".join(f"- {text}: {'met' if met else '**not met**'}" for text, met in verdicts(t))


def compact(t):
    """One row per scene: Spectrace's rates and their ratios to Mitsuba's (the README's table)."""
    lines = [
        "| scene | Spectrace path (samples/s) | / Mitsuba llvm path | / Mitsuba scalar path "
        "| Spectrace light (paths/s) | / Mitsuba llvm ptracer | / Mitsuba scalar ptracer |",
        "|---|---|---|---|---|---|---|",
    ]
    for scene in t["scenes"]:
        r = ratios(scene)
        cells = [scene["scene"]]
        for ours, _ in PAIRS:
            row = find(scene, "spectrace", ours)
            cells.append(rate(row.get("per_second")) if row and not row["cannot"] else "cannot render")
            cells += [f"{r[(ours, v)]:.2f}" if (ours, v) in r else "-" for v in VARIANTS]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def seconds_cell(row):
    if row["cannot"]:
        return f"cannot render {row['cannot']}"
    cell = f"{sig(row['seconds'])} s ({sig(row['median_seconds'])})"
    if row["process_seconds"]:
        cell += f"; process {sig(min(row['process_seconds']))} s"
    return cell


def detail(t):
    """Every row of every scene: work, times, rates, and the race's numbers when it ran."""
    rows = [row for scene in t["scenes"] for row in scene["rows"]]
    rmse = any(row["rmse"] is not None for row in rows)
    ttt = any(row.get("time_to_10") for row in rows)
    head = ["scene", "estimator", "work", "render time", "samples or paths / s"]
    head += [f"relative RMSE at {t['spp']} spp"] if rmse else []
    head += [f"time to 10% (race of {t['race_date']})"] if ttt else []
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for scene in t["scenes"]:
        for row in scene["rows"]:
            cells = [scene["scene"], label(row), "-" if row["cannot"] else f"{row['work']:,} {row['unit']}"]
            cells += [seconds_cell(row), rate(row.get("per_second"))]
            if rmse:
                cells.append("-" if row["rmse"] is None else f"{100 * row['rmse']:.2f}%")
            if ttt:
                cells.append(peer_docs.fmt_time(tuple(row["time_to_10"])) if row.get("time_to_10") else "-")
            lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def section(report):
    """The docs/peer.md section, markers included."""
    t = report["throughput"]
    notes = (
        "Spectrace's render time is its sidecar's `wall_seconds`, the render loop alone (after the "
        "process started, the scene loaded and the pre-render probe ran, before the EXR and sidecar are "
        "written); the whole process's time is beside it. Mitsuba's is the `mi.render` call (film "
        "developed and copied to numpy included), `llvm_ad_spectral` after untimed warm-up renders "
        "that compile its kernels, `scalar_spectral` with nothing to compile. Samples/s: camera "
        "samples (spp x pixels) per second for path tracers, light paths per second for light "
        "tracers; every path carries 4 wavelengths in both renderers. On the glass sphere neither "
        "path tracer can render the caustic (next-event estimation of the sky cannot pass the "
        "glass), so their samples there are cheaper than the light tracers' paths, which do. "
        "Method: below, \"Samples per second\"."
    )
    if not t.get("race_date"):
        notes += (
            " No race results were at hand (`target/peer/results.json`): the time to 10% is in the "
            "race's tables above, from their own run."
        )
    return (
        f"{BEGIN}\n## Samples per second at equal spp\n\n{header(report)}\n\n{compact(t)}\n\n"
        f"Targets (samples per second against Mitsuba's `llvm_ad_spectral`):\n\n{verdict_lines(t)}\n\n"
        f"{detail(t)}\n\n{notes}\n{END}"
    )


def readme_block(report):
    """The README's compact block, markers included."""
    t = report["throughput"]
    return (
        f"{README_BEGIN}\nSamples per second at equal spp ({t['spp']} spp; {t['spp']} x pixels light paths; "
        f"{report['date']}; {rounds(t)}; [docs/peer.md](docs/peer.md#samples-per-second-at-equal-spp)):\n\n"
        f"{compact(t)}\n\nTargets (Spectrace's path tracer at least 0.5x Mitsuba llvm's samples/s on "
        f"spot_plane and cornell, its light tracer at least 1x Mitsuba llvm `ptracer`'s paths/s):\n\n"
        f"{verdict_lines(t)}\n{README_END}"
    )


def refresh_method(text, method):
    """`text` (docs/peer.md) with its method part (from "## Method" to the geometry block or the
    end, as peer_docs.write lays it out) replaced by `method`."""
    start = text.find("## Method\n")
    if start < 0:
        return text
    stop = text.find(peer_docs.GEOMETRY_BEGIN, start)
    return text[:start] + method + ("\n" + text[stop:] if stop >= 0 else "")


def write_alone(report, root):
    """`--throughput-only`: rewrites the throughput section (placed before the method if it has
    none yet) and the method of docs/peer.md, and the throughput block of the README's race block
    (placed at its end), leaving the race's and the geometry's parts as they are."""
    path = os.path.join(root, "docs", "peer.md")
    with open(path) as f:
        text = f.read()
    with open(os.path.join(root, "xtask", "peer", "method.md")) as f:
        method = f.read()
    block = section(report)
    new = replace(text, BEGIN, END, block)
    if new is None:
        at = text.find("## Method\n")
        new = text[:at] + block + "\n\n" + text[at:] if at >= 0 else text.rstrip("\n") + "\n\n" + block + "\n"
    with open(path, "w") as f:
        f.write(refresh_method(new, method))
    readme = os.path.join(root, "README.md")
    with open(readme) as f:
        text = f.read()
    block = readme_block(report)
    new = replace(text, README_BEGIN, README_END, block)
    if new is None:
        at = text.find(peer_docs.README_END)
        if at >= 0:
            new = text[:at].rstrip("\n") + "\n\n" + block + "\n" + text[at:]
        else:
            new = text.rstrip("\n") + f"\n\n{peer_docs.README_BEGIN}\n{block}\n{peer_docs.README_END}\n"
    with open(readme, "w") as f:
        f.write(new)
