#!/bin/sh
# intel-ocl.sh — installs Intel's CPU OpenCL runtime from PyPI (intel-opencl-rt, with
# intel-cmplr-lib-rt for libsvml) into a cached venv outside the source tree, and makes it a
# second OpenCL platform beside the system's drivers (docs/testing.md, "Two OpenCL drivers").
#
#   scripts/intel-ocl.sh            install if missing; print the environment file's path
#   . "$(scripts/intel-ocl.sh)"     then every OpenCL program sees Intel's platform too
#
# DIR is $VBCL_INTEL_OCL_DIR, default ${XDG_CACHE_HOME:-~/.cache}/vbcl/intel-ocl; the version
# is $INTEL_OCL_VERSION (default below). A second run with the same version installs nothing.
# DIR/icd/ holds a copy of every system ICD file plus intel-cpu.icd, and DIR/env.sh sets
#   OCL_ICD_VENDORS=DIR/icd   (the ICD loader reads that folder instead of /etc/OpenCL/vendors)
#   LD_PRELOAD=DIR/venv/lib/libtbb.so.12
# The preload: vbcl links OpenImageIO, which loads Debian's oneTBB 2021.8 first; Intel's
# runtime needs symbols of its newer oneTBB (tbb::detail::r1::get_thread_reference_vertex)
# and otherwise fails to load, silently: the platform is just missing. oneTBB keeps its
# ABI backwards compatible, so OpenImageIO runs on the newer library.
set -eu

version=${INTEL_OCL_VERSION:-2026.2.0}
dir=${VBCL_INTEL_OCL_DIR:-${XDG_CACHE_HOME:-$HOME/.cache}/vbcl/intel-ocl}
venv=$dir/venv
stamp=$dir/installed-$version

say() { echo "intel-ocl: $*" >&2; }

if [ ! -f "$stamp" ]; then
    if ! python3 -c 'import venv, ensurepip' 2>/dev/null; then
        say "python3 cannot make a venv: installing python3-venv"
        if [ "$(id -u)" -eq 0 ]; then SUDO=""; else SUDO="sudo"; fi
        $SUDO apt-get update >&2
        DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y --no-install-recommends python3-venv >&2
    fi
    say "installing intel-opencl-rt==$version and intel-cmplr-lib-rt==$version into $venv (about 850 MB)"
    rm -rf "$venv"
    mkdir -p "$dir"
    python3 -m venv "$venv"
    # a slow mirror is not a failure: long timeouts and retries
    "$venv/bin/python" -m pip install --quiet --disable-pip-version-check --timeout 300 \
        --retries 10 "intel-opencl-rt==$version" "intel-cmplr-lib-rt==$version" >&2
    touch "$stamp"
fi

lib=$venv/lib/libintelocl.so
[ -f "$lib" ] || { say "$lib missing after the install (remove $dir and retry)"; exit 1; }
tbb=$venv/lib/libtbb.so.12
[ -f "$tbb" ] || { say "$tbb missing after the install (remove $dir and retry)"; exit 1; }

# the ICD folder: the system's drivers (PoCL) and Intel's, by absolute path; the library
# finds its own dependencies through its RUNPATH ($ORIGIN)
rm -rf "$dir/icd.tmp"
mkdir -p "$dir/icd.tmp"
for f in /etc/OpenCL/vendors/*.icd; do
    [ -e "$f" ] && cp "$f" "$dir/icd.tmp/"
done
echo "$lib" > "$dir/icd.tmp/intel-cpu.icd"
rm -rf "$dir/icd"
mv "$dir/icd.tmp" "$dir/icd"
cat > "$dir/env.sh" <<EOF
# written by scripts/intel-ocl.sh: Intel's CPU OpenCL runtime $version beside the system's drivers
OCL_ICD_VENDORS=$dir/icd
LD_PRELOAD=$tbb\${LD_PRELOAD:+:\$LD_PRELOAD}
export OCL_ICD_VENDORS LD_PRELOAD
EOF
echo "$dir/env.sh"
