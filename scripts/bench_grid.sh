#!/usr/bin/env bash
# bench_grid.sh — render time across grid sizes, two levels against one (docs/benchmarks.md).
# Renders each scene with every grid variant, interleaved and repeated so that machine noise
# hits every variant alike, keeps the median of each, and writes OUTDIR/grid_sweep.csv and
# OUTDIR/grid_sweep.md (kernel time relative to the scene's best variant), from
# vbcl --stats-json (docs/stats.md). The variants: the top level at 5^3 .. 64^3, the thesis's
# 20^3 and `auto`, each with automatic sub-grids (`--grid N`) and as one level (`--grid N:1`),
# and `auto`'s top-level density (`--grid-density D`, cells per triangle) with sub-grids.
# usage: scripts/bench_grid.sh [--quick] [OUTDIR]      (default OUTDIR: bench-out)
set -euo pipefail
cd "$(dirname "$0")/.."

quick=0
if [ "${1:-}" = "--quick" ]; then quick=1; shift; fi
out=${1:-bench-out}
mkdir -p "$out"

if [ $quick = 1 ]; then
    sizes="5 auto"
    densities="0.125"
    repeats=1
    scenes="scenes/quickstart.json:64:64"
else
    sizes="5 8 12 16 20 32 64 auto"
    densities="0.03 0.06 0.25 0.5 1"
    repeats=3
    scenes="scenes/thesis/a4_two_prisms.json:400:400 scenes/quickstart.json:400:400 scenes/bench/spheres36.json:320:240"
fi
variants=()
for n in $sizes; do variants+=("$n" "$n:1"); done
for d in $densities; do variants+=("auto/d$d"); done

csv="$out/grid_sweep.csv"
echo "scene,triangles,variant,grid,subgrids,leaves,grid_build_ms,cells_per_ray,tests_per_ray,kernel_ms,mrays_per_s" > "$csv"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

for spec in $scenes; do
    IFS=: read -r scene w h <<< "$spec"
    ./vbcl "$scene" -q --width 16 --height 16 -o "$tmp/warm.png" # builds and caches the kernels
    for rep in $(seq "$repeats"); do
        for v in "${variants[@]}"; do
            opts=(--grid "$v")
            case $v in auto/d*) opts=(--grid auto --grid-density "${v#auto/d}") ;; esac
            ./vbcl "$scene" -q --stats-json "$tmp/stats.json" --width "$w" --height "$h" --aa 0 \
                "${opts[@]}" -o "$tmp/img.png"
            python3 - "$tmp/stats.json" "$scene" "$v" >> "$tmp/runs.csv" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))  # fields: docs/stats.md
g, w = s["grid"], s["work"]
print(f"{sys.argv[2]},{s['scene']['triangles']},{sys.argv[3]},"
      f"{'x'.join(map(str, g['resolution']))},{g['subgrids']},{g['leaves']},{g['build_ms']:.1f},"
      f"{w['cells_visited_per_ray']:.1f},{w['triangles_tested_per_ray']:.1f},"
      f"{s['time_ms']['kernels']:.1f},{s['mrays_per_s']:.2f}")
PY
        done
    done
done

# the median repeat of each (scene, variant), in the order run
python3 - "$tmp/runs.csv" >> "$csv" <<'PY'
import csv, statistics, sys
runs = {}
for row in csv.reader(open(sys.argv[1])):
    runs.setdefault((row[0], row[2]), []).append(row)
for rows in runs.values():
    rows.sort(key=lambda r: float(r[9]))
    print(",".join(rows[len(rows) // 2]))
PY

md="$out/grid_sweep.md"
{
    echo "| scene | variant | grid | sub-grids | leaves | build ms | cells/ray | tests/ray | kernel ms | vs best | Mrays/s |"
    echo "|---|---|---|---|---|---|---|---|---|---|---|"
    awk -F, 'NR > 1 { best[$1] = (best[$1] == "" || $10 < best[$1]) ? $10 : best[$1]; row[NR] = $0 }
             END { for (i = 2; i <= NR; i++) { split(row[i], f, ",")
                   printf "| %s | %s | %s | %s | %s | %s | %s | %s | %s | %.2f | %s |\n",
                          f[1], f[3], f[4], f[5], f[6], f[7], f[8], f[9], f[10], f[10] / best[f[1]], f[11] } }' "$csv"
} > "$md"
cat "$md"
echo "wrote $csv and $md"
