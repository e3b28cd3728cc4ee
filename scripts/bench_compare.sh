#!/usr/bin/env bash
# bench_compare.sh — two vbcl binaries on the same scenes, interleaved run by run so that
# machine noise hits both alike; reports the median kernel time of each and the ratio.
# usage: scripts/bench_compare.sh OLD_BINARY NEW_BINARY [-n REPEATS] SCENE[:WxH] ...
# Kernel time = the device stages (camera + intersect + shading + ray trees + dispersive
# subtrees): time_ms.kernels of --stats-json (docs/stats.md); a binary older than
# --stats-json is read from its --stats text instead, so that old builds can be compared.
set -euo pipefail
old=$1 new=$2
shift 2
repeats=5
if [ "${1:-}" = "-n" ]; then repeats=$2; shift 2; fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

kernel_ms() { # binary scene w h -> kernel milliseconds
    local size=()
    [ -n "$3" ] && size=(--width "$3" --height "$4")
    if "$1" --help | grep -c -- --stats-json > /dev/null; then
        "$1" "$2" -q --stats-json "$tmp/stats.json" "${size[@]}" -o "$tmp/img.png"
        python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["time_ms"]["kernels"])' \
            "$tmp/stats.json"
    else
        "$1" "$2" -q --stats "${size[@]}" -o "$tmp/img.png" 2>&1 |
            awk '/^time/ { s = 0
                           for (i = 1; i <= NF; i++)
                               if ($i ~ /^(camera|intersect|shading\+shadows|trees|subtrees)$/) s += $(i + 1)
                           print s }'
    fi
}

median() { sort -g | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }

printf '| scene | old ms (median of %d) | new ms | new / old |\n|---|---|---|---|\n' "$repeats"
for spec in "$@"; do
    scene=${spec%%:*} w="" h=""
    if [ "$spec" != "$scene" ]; then size=${spec#*:}; w=${size%x*}; h=${size#*x}; fi
    kernel_ms "$old" "$scene" "$w" "$h" > /dev/null # warm the kernel caches
    kernel_ms "$new" "$scene" "$w" "$h" > /dev/null
    : > "$tmp/old" && : > "$tmp/new"
    for _ in $(seq "$repeats"); do
        kernel_ms "$old" "$scene" "$w" "$h" >> "$tmp/old"
        kernel_ms "$new" "$scene" "$w" "$h" >> "$tmp/new"
    done
    mo=$(median < "$tmp/old") mn=$(median < "$tmp/new")
    printf '| %s | %.1f | %.1f | %.3f |\n' "$spec" "$mo" "$mn" "$(awk -v a="$mn" -v b="$mo" 'BEGIN { print a / b }')"
done
