#!/usr/bin/env bash
# bench_grid_auto.sh — the `auto` grid of two vbcl binaries, side by side: renders each scene
# with OLD and NEW (both with their default `auto` grid), interleaved and repeated so that
# machine noise hits both alike, and writes OUTDIR/grid_auto.csv (every run) and
# OUTDIR/grid_auto.md (per scene and binary: grid, build ms, triangles tested per ray, the
# median kernel ms, and the ratio new/old of the medians).
# Kernel ms = intersect + shading+shadows + ray trees, from --stats.
# usage: scripts/bench_grid_auto.sh [--quick] OLD_VBCL [NEW_VBCL [OUTDIR]]
#        (default NEW_VBCL: ./vbcl; default OUTDIR: bench-out)
# OLD_VBCL is a copy of a binary built before the change (e.g. cp vbcl /tmp/vbcl-old).
set -euo pipefail
cd "$(dirname "$0")/.."

quick=0
if [ "${1:-}" = "--quick" ]; then quick=1; shift; fi
if [ $# -lt 1 ]; then
    echo "usage: scripts/bench_grid_auto.sh [--quick] OLD_VBCL [NEW_VBCL [OUTDIR]]" >&2
    exit 2
fi
old=$1
new=${2:-./vbcl}
out=${3:-bench-out}
mkdir -p "$out"

if [ $quick = 1 ]; then
    repeats=1
    scenes="scenes/quickstart.json:64:64"
else
    repeats=3
    scenes="scenes/quickstart.json:400:400 scenes/bench/spheres36.json:320:240 scenes/glass_bombed_sphere.json:160:160"
fi

csv="$out/grid_auto.csv"
echo "scene,binary,repeat,grid,cells,grid_build_ms,nonempty_mean,refined,cells_per_ray,tests_per_ray,kernel_ms" > "$csv"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

for spec in $scenes; do
    IFS=: read -r scene w h <<< "$spec"
    for bin in "$old" "$new"; do # builds and caches each binary's kernels
        "$bin" "$scene" -q --width 16 --height 16 -o "$tmp/warm.png"
    done
    for rep in $(seq "$repeats"); do
        for which in old new; do
            if [ $which = old ]; then bin=$old; else bin=$new; fi
            "$bin" "$scene" -q --stats --width "$w" --height "$h" -o "$tmp/img.png" 2> "$tmp/stats.txt"
            awk -v scene="$scene" -v which="$which" -v rep="$rep" '
                /^grid/ { grid = $2; cells = $4; build = $8; sub(/ms,?/, "", build); ne = "-"; rf = 0
                          for (i = 1; i <= NF; i++) {
                              if ($i == "non-empty") { ne = $(i + 2); sub(/,/, "", ne) }
                              if ($i == "refined") rf = $(i + 1) } }
                /^work/ { cpr = $2; tpr = $6 }
                /^time/ { for (i = 1; i <= NF; i++) {
                            if ($i == "intersect") x += $(i + 1)
                            if ($i == "shading+shadows") x += $(i + 1)
                            if ($i == "trees") x += $(i + 1) } }
                END { printf "%s,%s,%s,%s,%s,%s,%s,%s,%s,%s,%.1f\n", scene, which, rep, grid,
                      cells, build, ne, rf, cpr, tpr, x }' "$tmp/stats.txt" >> "$csv"
        done
    done
done

md="$out/grid_auto.md"
{
    echo "| scene | binary | grid | cells | build ms | tris/non-empty cell | refined | cells/ray | tests/ray | kernel ms (runs) | median | new/old |"
    echo "|---|---|---|---|---|---|---|---|---|---|---|---|"
    awk -F, 'NR > 1 { k = $1 "," $2; if (!(k in grid)) { order[++n] = k }
                      grid[k] = $4; cells[k] = $5; build[k] = build[k] (build[k] == "" ? "" : "/") $6
                      ne[k] = $7; rf[k] = $8; cpr[k] = $9; tpr[k] = $10
                      runs[k] = runs[k] (runs[k] == "" ? "" : "/") $11; t[k, ++c[k]] = $11 }
             function median(k,   i, j, v, m) {
                 m = c[k]; for (i = 1; i <= m; i++) v[i] = t[k, i] + 0
                 for (i = 1; i <= m; i++) for (j = i + 1; j <= m; j++)
                     if (v[j] < v[i]) { x = v[i]; v[i] = v[j]; v[j] = x }
                 return m % 2 ? v[(m + 1) / 2] : (v[m / 2] + v[m / 2 + 1]) / 2 }
             END { for (i = 1; i <= n; i++) { k = order[i]; split(k, f, ",")
                       med = median(k); ratio = ""
                       if (f[2] == "new" && (f[1] ",old") in grid)
                           ratio = sprintf("%.2f", med / median(f[1] ",old"))
                       printf "| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %.0f | %s |\n",
                              f[1], f[2], grid[k], cells[k], build[k], ne[k], rf[k], cpr[k],
                              tpr[k], runs[k], med, ratio } }' "$csv"
} > "$md"
cat "$md"
echo "wrote $csv and $md"
