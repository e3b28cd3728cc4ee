#!/usr/bin/env bash
# bench_grid.sh — render time against the auto-grid density (cells per triangle).
# Renders each scene at several --grid-density values, interleaved and repeated so that
# machine noise hits every value alike, keeps the fastest run of each, and writes
# OUTDIR/grid_density.csv and OUTDIR/grid_density.md (times relative to the best), from
# vbcl --stats-json (docs/stats.md).
# usage: scripts/bench_grid.sh [--quick] [OUTDIR]      (default OUTDIR: bench-out)
set -euo pipefail
cd "$(dirname "$0")/.."

quick=0
if [ "${1:-}" = "--quick" ]; then quick=1; shift; fi
out=${1:-bench-out}
mkdir -p "$out"

if [ $quick = 1 ]; then
    densities="0.5 3"
    repeats=1
    scenes="scenes/quickstart.json:64:64"
else
    densities="0.25 0.5 1 2 3 4 6 8 12 16"
    repeats=3
    scenes="scenes/quickstart.json:400:400 scenes/bench/spheres36.json:320:240"
fi

csv="$out/grid_density.csv"
echo "scene,triangles,density,grid,cells,grid_build_ms,mean_tris_per_cell,intersect_ms,shading_ms,kernel_ms,mrays_per_s" > "$csv"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

for spec in $scenes; do
    IFS=: read -r scene w h <<< "$spec"
    ./vbcl "$scene" -q --width "$w" --height "$h" -o "$tmp/warm.png" # builds and caches the kernels
    for rep in $(seq "$repeats"); do
        for d in $densities; do
            ./vbcl "$scene" -q --stats-json "$tmp/stats.json" --width "$w" --height "$h" \
                --grid-density "$d" -o "$tmp/img.png"
            python3 - "$tmp/stats.json" "$scene" "$d" >> "$tmp/runs.csv" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))  # fields: docs/stats.md
g, t = s["grid"], s["time_ms"]
print(f"{sys.argv[2]},{s['scene']['triangles']},{sys.argv[3]},"
      f"{'x'.join(map(str, g['resolution']))},{g['cells']},{g['build_ms']:.1f},"
      f"{g['tris_per_cell_mean']:.2f},{t['intersect']:.1f},{t['shading']:.1f},"
      f"{t['intersect'] + t['shading']:.1f},{s['mrays_per_s']:.2f}")
PY
        done
    done
done

# keep the fastest repeat of each (scene, density)
sort -t, -k1,1 -k3,3g -k10,10g "$tmp/runs.csv" | awk -F, '!seen[$1 "," $3]++' >> "$csv"

md="$out/grid_density.md"
{
    echo "| scene | triangles | density | grid | cells | build ms | tris/cell | intersect ms | shading ms | kernel ms | vs best | Mrays/s |"
    echo "|---|---|---|---|---|---|---|---|---|---|---|---|"
    awk -F, 'NR > 1 { best[$1] = (best[$1] == "" || $10 < best[$1]) ? $10 : best[$1]; row[NR] = $0 }
             END { for (i = 2; i <= NR; i++) { split(row[i], f, ",")
                   printf "| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %.2f | %s |\n",
                          f[1], f[2], f[3], f[4], f[5], f[6], f[7], f[8], f[9], f[10], f[10] / best[f[1]], f[11] } }' "$csv"
} > "$md"
cat "$md"
echo "wrote $csv and $md"
