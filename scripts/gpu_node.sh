#!/bin/bash
# gpu_node.sh — vbcl on a machine that has a GPU's OpenCL driver but not this project's
# build dependencies (a GPU node, a container): docs/scaling.md, "On an NVIDIA GPU".
#
#   scripts/gpu_node.sh bundle [DIR]     here: build vbcl without MPI into DIR (default
#                                        .gpu), with libcjson and the ICD loader beside it;
#                                        LOADER=/path/libOpenCL.so.1 adds a second loader
#                                        (the Khronos one) as DIR/khronos/libOpenCL.so.1
#   scripts/gpu_node.sh check OUT [DIR]  there, from the source tree with DIR in it: lists
#                                        the devices, renders scripts/drivers_check.py's
#                                        images on the GPU (--save OUT/save, one by one, so
#                                        a run cut short keeps what it made), then times
#                                        six renders, 3 runs each, into OUT/timings.txt
#
# Then here: scripts/drivers_check.py --against OUT/save (PoCL's images against the GPU's).
# Every image is .pfm, which vbcl writes without OpenImageIO. On the GPU machine the
# bundled ocl-icd is tried first; if it lists no device matching DEV (default NVIDIA), the
# Khronos loader of DIR/khronos: Debian's and Ubuntu's ocl-icd 2.3 listed no NVIDIA
# platform with driver 580. NVIDIA builds each program once (7.7 s opaque, about 41 s with
# glass, longer dispersive) and vbcl's kernel cache keeps it, so the slow scenes come last.
set -u
cmd=${1:-}
here=$(cd "$(dirname "$0")/.." && pwd)

bundle() {
    local dir=${1:-.gpu}
    make -C "$here" BUILD="$dir/build" MPI=0 "$dir/build/vbcl" || return 1
    mkdir -p "$here/$dir/lib" || return 1
    local lib
    for lib in libOpenCL.so.1 libcjson.so.1; do
        local path
        path=$(ldd "$here/$dir/build/vbcl" | awk -v l="$lib" '$1 == l { print $3 }')
        [ -n "$path" ] || { echo "gpu_node: $dir/build/vbcl does not link $lib" >&2; return 1; }
        cp -L "$path" "$here/$dir/lib/$lib" || return 1
    done
    if [ -n "${LOADER:-}" ]; then
        mkdir -p "$here/$dir/khronos" && cp -L "$LOADER" "$here/$dir/khronos/libOpenCL.so.1" ||
            return 1
    fi
    echo "gpu_node: $dir holds build/vbcl and lib/ ($(du -sh "$here/$dir" | cut -f1))"
}

check() {
    local out=${1:?usage: gpu_node.sh check OUT [DIR]} dir=${2:-.gpu} dev=${DEV:-NVIDIA}
    cd "$here" || return 1
    mkdir -p "$out/save" || return 1
    local V="$dir/build/vbcl"
    export LD_LIBRARY_PATH="$here/$dir/lib:${LD_LIBRARY_PATH:-}" PYTHONUNBUFFERED=1
    export VBCL_CACHE_DIR=${VBCL_CACHE_DIR:-/tmp/vbcl-gpu-cache}
    "$V" --list-devices
    if ! "$V" --list-devices | grep -q "$dev"; then
        [ -e "$dir/khronos/libOpenCL.so.1" ] ||
            { echo "gpu_node: no device matches $dev and $dir/khronos has no loader" >&2; return 1; }
        echo "gpu_node: the bundled ICD loader lists no $dev; the Khronos loader, traced:"
        export LD_LIBRARY_PATH="$here/$dir/khronos:$LD_LIBRARY_PATH"
        OCL_ICD_ENABLE_TRACE=1 "$V" --list-devices
        "$V" --list-devices | grep -q "$dev" || return 1
    fi
    # the opaque scenes first, then those whose programs take NVIDIA longest to build
    local only
    for only in '^tiny$' penumbra tiny_aa aa_edges '^quickstart' tiny_glass glass_bombed_sphere \
        high_index a4_two_prisms prism_dispersion tiny_dispersion surface_patterns; do
        python3 scripts/drivers_check.py --vbcl "$V" --b "$dev" --save "$out/save" --only "$only"
    done
    local a4aa0="scenes/thesis/.gpu_node_a4aa0.json"
    sed 's/"aa": 0.1/"aa": 0/' scenes/thesis/a4_two_prisms.json >"$a4aa0"
    local name args
    while read -r name args; do
        for _ in 1 2 3; do
            # shellcheck disable=SC2086  # args are words
            "$V" $args --device "$dev" -q -o "$out/timing.pfm" --stats-json "$out/t.json" ||
                { echo "$name: failed" >>"$out/timings.txt"; continue; }
            python3 - "$name" "$out/t.json" >>"$out/timings.txt" <<'EOF'
import json, sys
d = json.load(open(sys.argv[2]))
t = d["time_ms"]
print(f"{sys.argv[1]}: {d['rays']['total']} rays, kernels {t['kernels']:.1f} ms, upload "
      f"{t['upload']:.0f} ms, total {t['total']:.0f} ms, program "
      f"{'cached' if d['program']['cached'] else 'built'} {d['program']['build_ms']:.0f} ms")
EOF
        done
    done <<EOF
a4_aa0_grid20 $a4aa0
a4_aa0.1 scenes/thesis/a4_two_prisms.json
glass_400 scenes/glass_bombed_sphere.json --width 400 --height 400
quickstart_400 scenes/quickstart.json --width 400 --height 400
quickstart_1600 scenes/quickstart.json --width 1600 --height 1600
spheres36 scenes/bench/spheres36.json
EOF
    rm -f "$a4aa0" "$out/t.json" "$out/timing.pfm"
    cat "$out/timings.txt"
}

case "$cmd" in
bundle) shift && bundle "$@" ;;
check) shift && check "$@" ;;
*)
    sed -n '2,20p' "$0" | sed 's/^# \{0,1\}//'
    exit 2
    ;;
esac
