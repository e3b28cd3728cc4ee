#!/usr/bin/env bash
# smoke.sh BUILD — the part of `make test` that keeps the scripts from rotting: the gallery
# script on two figures at 16x16, every benchmark part on tiny images (bench.py --quick) and
# bench_rays_compare.py on one scene. One line per step ("ran" or, after the tail of its
# log, "FAILED"); exits 1 if any failed. make test runs it beside the test workers.
set -u
build=${1:?usage: scripts/smoke.sh BUILD}
rc=0
step() { # name log command...
    local name=$1 log=$2
    shift 2
    if "$@" > "$log" 2>&1; then
        echo "$name"
    else
        tail -30 "$log"
        echo "$name FAILED"
        rc=1
    fi
}
step "gallery --size 16: ran (A.1, A.6)" "$build/gallery-quick.log" \
    scripts/gallery.py --vbcl "$build/vbcl" --size 16 --scenes a1,a6 --out "$build/gallery-quick"
step "bench --quick: every part ran ($build/bench-quick/bench.md)" "$build/bench-quick.log" \
    scripts/bench.py --quick --vbcl "$build/vbcl" --out "$build/bench-quick"
step "bench_rays_compare.py: ran (spheres36, 8x8)" "$build/bench-rays-compare.log" \
    scripts/bench_rays_compare.py -n 1 --size 8 --repeats 1 "$build/vbcl-bench-rays" \
    "$build/vbcl-bench-rays" -- scenes/bench/spheres36.json
exit $rc
