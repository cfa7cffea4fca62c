#!/usr/bin/env bash
# Marginal instructions per work item of Spectrace's three estimators, counted by callgrind.
#
#   xtask/scripts/callgrind.sh BINARY OUTFILE   (or: cargo xtask callgrind [BINARY [OUTFILE]])
#
# For every case, renders twice under `valgrind --tool=callgrind`, with N and with 2N work items
# (one thread, seed 1, no progress bar, outputs into a temporary folder), and reports
# (I(2N) - I(N)) / N: the instructions one more work item costs, start-up, scene loading, the
# pre-render probe and the image writing cancelled out. A work item is one beam for the light
# tracer and one pixel sample for the path tracer and BDPT.
#
# The scenes are the project's own (`scenes/`, or $SCENES): the light tracer renders them
# unchanged; the camera integrators render `quarter/` copies, written into a temporary folder,
# whose camera width and height are a quarter of the shipped ones (nothing else changed; the CLI
# has no resolution override), so that one pass (one sample per pixel) is small. To compare two
# builds, run this script on each binary in the same checkout: the instruction counts are
# repeatable to about 0.01 per item whatever else the machine is doing.
#
# Environment: ONLY=REGEX runs only the cases whose "scene integrator" matches (e.g.
# ONLY='cornell bdpt'); SCENES (default: the workspace's `scenes/`); VALGRIND (default valgrind);
# NICE (default `nice -n 10`). Needs valgrind and python3.
set -euo pipefail

if [[ $# -ne 2 ]]; then
    echo "usage: $0 BINARY OUTFILE" >&2
    exit 2
fi
BIN=$(realpath "$1")
OUTFILE=$2
HERE=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
SOURCE=${SCENES:-$HERE/../../scenes}
VALGRIND=${VALGRIND:-valgrind}
NICE=${NICE:-nice -n 10}
ONLY=${ONLY:-}

[[ -x $BIN ]] || { echo "error: $BIN is not an executable" >&2; exit 2; }

# scene file (relative to $SCENES) | integrator | effort option | N (2N is also run) | items per unit of N
# An integrator written `path:batched` renders with `--kernel batched` (the path tracer's batched
# kernel; plain `path` is the default scalar kernel).
# Light tracer: N beams, a multiple of the 16,384-beam chunk, so 2N is exactly twice the chunks.
# Camera integrators: N samples per pixel; items = N x width x height of the quarter scene.
CASES=(
    "fading_spot.json          light --beams 393216 1"
    "cornell.json              light --beams 81920  1"
    "caustic_ring.json         light --beams 262144 1"
    "quarter/spot_torus.json   path  --spp   16     9600"
    "quarter/spot_torus.json   path:batched --spp 16 9600"
    "quarter/cornell.json      path  --spp   12     10000"
    "quarter/cornell.json      path:batched --spp 12 10000"
    "quarter/caustic_ring.json bdpt  --spp   24     9600"
    "quarter/cornell.json      bdpt  --spp   4      10000"
)

WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT

# The scenes: the originals, and quarter-resolution copies of the camera integrators' scenes.
SCENES="$WORK/scenes"
mkdir -p "$SCENES/quarter"
cp "$SOURCE"/{fading_spot,cornell,caustic_ring,spot_torus}.json "$SCENES/"
for name in cornell caustic_ring spot_torus; do
    python3 - "$SCENES/$name.json" "$SCENES/quarter/$name.json" <<'PY'
import json, sys
scene = json.load(open(sys.argv[1]))
scene["camera"]["width"] //= 4
scene["camera"]["height"] //= 4
json.dump(scene, open(sys.argv[2], "w"), indent=1)
PY
done

# instructions SCENE INTEGRATOR OPTION VALUE EXPECTED_ITEMS: prints callgrind's total Ir of one render.
instructions() {
    local scene=$1 integrator=$2 option=$3 value=$4 expected=$5
    local out="$WORK/out" log="$WORK/valgrind.log" stdout="$WORK/stdout"
    local kernel=()
    if [[ $integrator == *:* ]]; then
        kernel=(--kernel "${integrator#*:}")
        integrator=${integrator%%:*}
    fi
    rm -rf "$out"
    mkdir -p "$out"
    if ! $NICE "$VALGRIND" --tool=callgrind --callgrind-out-file=/dev/null \
        "$BIN" render "$SCENES/$scene" --integrator "$integrator" "${kernel[@]}" "$option" "$value" \
        --threads 1 --seed 1 --quiet --out "$out" >"$stdout" 2>"$log"; then
        echo "error: the render failed: $scene $integrator $option $value" >&2
        cat "$log" "$stdout" >&2
        exit 1
    fi
    # The render's own report: "<items> beams in ..."; check that it traced what we asked for.
    local traced
    traced=$(grep -oP '^[0-9]+(?= beams in )' "$stdout" || true)
    if [[ "$traced" != "$expected" ]]; then
        echo "error: $scene $integrator $option $value traced '$traced' items, expected $expected" >&2
        cat "$stdout" >&2
        exit 1
    fi
    local ir
    ir=$(grep -oP '== Collected : \K[0-9]+' "$log" || true)
    if [[ -z $ir ]]; then
        echo "error: no callgrind total for $scene $integrator $option $value" >&2
        cat "$log" >&2
        exit 1
    fi
    echo "$ir"
}

TABLE="| scene | integrator | items | instructions per item |
|---|---|---|---|"
RAW="| scene | integrator | effort N | effort 2N | I(N) | I(2N) |
|---|---|---|---|---|---|"

for case in "${CASES[@]}"; do
    read -r scene integrator option n per <<<"$case"
    name=$(basename "$scene" .json)
    [[ "$scene" == quarter/* ]] && name="$name (1/4 res)"
    if [[ -n $ONLY ]] && ! [[ "$(basename "$scene" .json) $integrator" =~ $ONLY ]]; then
        continue
    fi
    items=$((n * per))
    echo "== $name $integrator: $option $n and $((2 * n)) ($items and $((2 * items)) items)" >&2
    i1=$(instructions "$scene" "$integrator" "$option" "$n" "$items")
    i2=$(instructions "$scene" "$integrator" "$option" "$((2 * n))" "$((2 * items))")
    marginal=$(awk -v a="$i1" -v b="$i2" -v n="$items" 'BEGIN { printf "%.1f", (b - a) / n }')
    echo "   I(N) = $i1, I(2N) = $i2, marginal = $marginal per item" >&2
    TABLE+=$'\n'"| \`$name\` | $integrator | $items | $marginal |"
    RAW+=$'\n'"| \`$name\` | $integrator | $option $n | $option $((2 * n)) | $i1 | $i2 |"
done

REPORT="$TABLE

Marginal instructions per work item, (I(2N) - I(N)) / N, counted by callgrind (\`valgrind
--tool=callgrind\`, total Ir of all threads); items = N (beams for light, pixel samples for
path and bdpt). Binary: \`$BIN\` (sha256 $(sha256sum "$BIN" | cut -c1-16)); scenes: \`$SOURCE\`;
every render: \`--threads 1 --seed 1 --quiet\`.

$RAW"

echo "$REPORT"
mkdir -p "$(dirname "$OUTFILE")"
printf '%s\n' "$REPORT" >"$OUTFILE"
