#!/usr/bin/env bash
# How closely Spectrace's camera integrators keep a time budget when one pass over the image
# takes longer than the budget.
#
#   xtask/scripts/time-budget.sh BINARY [BUDGET]   (or: cargo xtask budget [BUDGET])
#
# Renders a copy of the shipped Cornell box (`scenes/cornell.json`) at 4x its resolution
# (1600 x 1600; nothing else changed, written into a temporary folder) with the path tracer and
# BDPT for `--time BUDGET` seconds (default 1) on 2 threads, and prints per estimator the
# render's own wall time (the sidecar's `wall_seconds`: the render loop, without loading, the
# pre-render probe or writing), its ratio to the budget, the samples done, the passes cut
# (`chunks_cut`; 0 for builds that predate it), and the whole process' wall time. At this size
# one pass (one sample per pixel) takes the path tracer about 7 s and BDPT about 28 s on 2
# threads: a render that only stopped between passes would overrun a 1 s budget by that much.
# Needs python3.
set -euo pipefail

if [[ $# -lt 1 || $# -gt 2 ]]; then
    echo "usage: $0 BINARY [BUDGET]" >&2
    exit 2
fi
BIN=$(realpath "$1")
BUDGET=${2:-1}
HERE=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
[[ -x $BIN ]] || { echo "error: $BIN is not an executable" >&2; exit 2; }

WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
python3 - "$HERE/../../scenes/cornell.json" "$WORK/cornell.json" <<'PY'
import json, sys
scene = json.load(open(sys.argv[1]))
scene["camera"]["width"] *= 4
scene["camera"]["height"] *= 4
json.dump(scene, open(sys.argv[2], "w"), indent=1)
PY

printf '| estimator | budget (s) | render (s) | render / budget | samples | passes cut | process (s) |\n'
printf '|---|---|---|---|---|---|---|\n'
for integrator in path bdpt; do
    out="$WORK/out-$integrator"
    start=$(date +%s.%N)
    "$BIN" render "$WORK/cornell.json" --integrator "$integrator" --time "$BUDGET" --threads 2 \
        --quiet --out "$out" > /dev/null 2> "$WORK/stderr-$integrator"
    end=$(date +%s.%N)
    python3 - "$out/cornell.json" "$integrator" "$BUDGET" "$start" "$end" <<'PY'
import json, sys
report = json.load(open(sys.argv[1]))
budget, start, end = float(sys.argv[3]), float(sys.argv[4]), float(sys.argv[5])
wall = report["wall_seconds"]
print(f"| {sys.argv[2]} | {budget:g} | {wall:.3f} | {wall / budget:.3f} | {report['beams']} "
      f"| {report.get('chunks_cut', 0)} | {end - start:.2f} |")
PY
done
