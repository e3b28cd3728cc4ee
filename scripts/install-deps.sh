#!/bin/sh
# install-deps.sh — installs what vbcl needs from Debian's packages, only what is missing.
# Idempotent: a second run installs nothing. Uses sudo when not root.
# usage: scripts/install-deps.sh [--test | --bench]
#   (none)   what building and rendering on one machine need (`make run`): a compiler,
#            OpenCL with PoCL, cJSON, OpenImageIO
#   --test   and what the tests and checks need (`make test`, `make oclgrind`, `make fuzz`):
#            OpenMPI (vbcl is built with MPI where it is installed, docs/scaling.md; the
#            Makefile rebuilds with it once it appears), clinfo, oclgrind, clang (the
#            fuzzers), OpenImageIO's tools (idiff), Python with NumPy and Matplotlib (the
#            gallery and bench scripts)
#   --bench  and, for `make bench`, Embree 3 (libembree-dev), which the bench part "embree"
#            traces the same rays with (docs/benchmarks.md); the renderer never links it.
set -eu

PACKAGES="build-essential pkg-config ocl-icd-opencl-dev opencl-headers pocl-opencl-icd \
libcjson-dev libopenimageio-dev"
TEST_PACKAGES="libopenmpi-dev openmpi-bin clinfo oclgrind clang openimageio-tools python3 python3-numpy python3-matplotlib \
python3-venv"
BENCH_PACKAGES="libembree-dev"

case "${1:-}" in
"") ;;
--test) PACKAGES="$PACKAGES $TEST_PACKAGES" ;;
--bench) PACKAGES="$PACKAGES $TEST_PACKAGES $BENCH_PACKAGES" ;;
*)
    echo "usage: scripts/install-deps.sh [--test | --bench]" >&2
    exit 2
    ;;
esac

missing=""
for p in $PACKAGES; do
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
        missing="$missing $p"
    fi
done

if [ -z "$missing" ]; then
    echo "install-deps: all packages present"
    exit 0
fi

if [ "$(id -u)" -eq 0 ]; then
    SUDO=""
elif command -v sudo >/dev/null 2>&1; then
    SUDO="sudo"
else
    echo "install-deps: need root (or sudo) to install:$missing" >&2
    exit 1
fi

echo "install-deps: installing:$missing"
$SUDO apt-get update
# shellcheck disable=SC2086
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y --no-install-recommends $missing
