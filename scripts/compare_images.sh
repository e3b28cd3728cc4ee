#!/usr/bin/env bash
# compare_images.sh — renders every example scene (scenes/*.json, scenes/thesis/*.json;
# frame 0 of an animation) with two vbcl binaries at a small size and compares the EXRs
# with idiff: the check that a change which should not touch the image does not.
# usage: scripts/compare_images.sh OLD_BINARY NEW_BINARY [SIZE (default 96)] [vbcl options]
# Prints one line per scene and "N identical, N different"; exits 1 when any differ
# (bit for bit: idiff -fail 0 -warn 0). A scene the old binary refuses with exit 2 (a key it
# does not know yet) and the new one renders is counted as new, not compared. vbcl options
# go to both binaries, e.g.
# --shadow-samples 4 to make the anti-aliased thesis scenes affordable.
set -euo pipefail
old=$1 new=$2
size=${3:-96}
shift $(($# < 3 ? $# : 3))
opts=("$@")
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
same=0 differ=0 newer=0
for scene in scenes/*.json scenes/thesis/*.json; do
    name=$(basename "$scene" .json)
    case $name in _*) continue ;; esac # scratch copies
    frames=()
    grep -q '"animation"' "$scene" && frames=(--frames 0)
    refused=""
    for b in new old; do
        bin=$old
        [ $b = new ] && bin=$new
        rc=0
        "$bin" "$scene" -q --width "$size" --height "$size" "${frames[@]}" "${opts[@]}" \
            -o "$tmp/$b.exr" >"$tmp/$b.log" 2>&1 || rc=$?
        if [ $rc -eq 2 ] && [ $b = old ]; then refused=$(tail -1 "$tmp/$b.log") && break; fi
        [ $rc -eq 0 ] || { echo "$name: $b binary failed: $(tail -1 "$tmp/$b.log")"; exit 1; }
        [ -f "$tmp/$b.exr" ] || mv "$tmp/${b}"_*.exr "$tmp/$b.exr" 2>/dev/null || true
    done
    if [ -n "$refused" ]; then
        newer=$((newer + 1))
        echo "$name: new (the old binary refuses it: $refused)"
        rm -f "$tmp"/old*.exr "$tmp"/new*.exr
        continue
    fi
    if idiff -fail 0 -warn 0 "$tmp/old.exr" "$tmp/new.exr" >"$tmp/idiff.log" 2>&1; then
        same=$((same + 1))
        echo "$name: identical"
    else
        differ=$((differ + 1))
        echo "$name: DIFFERENT: $(grep -E 'Mean error|RMS error|Max error|pixels' "$tmp/idiff.log" | tr '\n' ' ')"
    fi
    rm -f "$tmp"/old*.exr "$tmp"/new*.exr
done
echo "$same identical, $differ different, $newer new"
[ "$differ" -eq 0 ]
