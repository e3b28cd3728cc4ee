#!/bin/sh
# oclgrind_check.sh VBCL SCENE [OCLGRIND_FLAGS [REL]] — runs VBCL on SCENE under oclgrind
# (which replaces the OpenCL platform by its simulator) and fails on any error it reports;
# then renders the scene on the default device (PoCL) too and compares the two EXR images
# per pixel: |a - b| <= 1e-6 or |a - b| <= REL * max(|a|, |b|) (idiff -fail -failrelative).
# REL defaults to 1e-4; ray trees compound the few-ulp freedom OpenCL gives exp, pow and
# sincos, so scenes with dielectrics are compared at 1e-3.
set -eu
vbcl=$1
scene=$2
flags=${3:---check-api --data-races}
rel=${4:-1e-4}
command -v oclgrind >/dev/null || { echo "oclgrind: not installed (scripts/install-deps.sh)" >&2; exit 1; }
tmp=$(mktemp -d /tmp/vbcl-oclgrind-XXXXXX)
trap 'rm -rf "$tmp"' EXIT
# no binary cache: oclgrind must compile the source to report errors with line numbers
# shellcheck disable=SC2086
if ! VBCL_CACHE_DIR=off oclgrind $flags --log "$tmp/log" "$vbcl" "$scene" -q -o "$tmp/oclgrind.exr"; then
    cat "$tmp/log" 2>/dev/null | head -60
    echo "oclgrind: vbcl failed under oclgrind" >&2
    exit 1
fi
if [ -s "$tmp/log" ]; then
    grep -v '^\s*$' "$tmp/log" | head -60
    echo "oclgrind: $(grep -c '^[A-Z]' "$tmp/log" || true) reports from oclgrind $flags" >&2
    exit 1
fi
echo "oclgrind: $flags: no errors"
"$vbcl" "$scene" -q -o "$tmp/pocl.exr"
if ! idiff -q -fail 1e-6 -failrelative "$rel" -warn 1e-6 -warnrelative "$rel" "$tmp/pocl.exr" "$tmp/oclgrind.exr"; then
    idiff -v -fail 1e-6 -failrelative "$rel" "$tmp/pocl.exr" "$tmp/oclgrind.exr" || true
    echo "oclgrind: PoCL and oclgrind images differ beyond $rel relative + 1e-6 absolute" >&2
    exit 1
fi
echo "oclgrind: $scene: PoCL and oclgrind agree to $rel relative + 1e-6 absolute per pixel"
