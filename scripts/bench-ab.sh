#!/usr/bin/env bash
# Encode and decode speed of two `vitrine` builds, interleaved (A, B, A, B, …)
# so that a busy machine slows both alike; prints the median of each.
#
#   scripts/bench-ab.sh BEFORE_BIN AFTER_BIN MESH [ROUNDS]     default 7 rounds
set -euo pipefail
a=$1; b=$2; mesh=$3; rounds=${4:-7}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
seconds() { # command… -> wall seconds
    local t0 t1
    t0=$(date +%s.%N)
    "$@" >/dev/null 2>&1
    t1=$(date +%s.%N)
    echo "$t1 - $t0" | bc
}
for bin in "$a" "$b"; do "$bin" encode "$mesh" -o "$work/warm.vtr" >/dev/null 2>&1; done
for _ in $(seq "$rounds"); do
    for side in a b; do
        bin=$a; [ "$side" = b ] && bin=$b
        seconds "$bin" encode "$mesh" -o "$work/$side.vtr" >>"$work/$side.encode"
        seconds "$bin" decode "$work/$side.vtr" -o "$work/$side.ply" >>"$work/$side.decode"
    done
done
cmp -s "$work/a.vtr" "$work/b.vtr" && same="identical streams" || same="STREAMS DIFFER"
median() { sort -n "$1" | awk '{v[NR]=$1} END {print v[int((NR+1)/2)]}'; }
printf '%s (%s rounds, %s)\n' "$(basename "$mesh")" "$rounds" "$same"
printf '  encode  A %ss  B %ss\n' "$(median "$work/a.encode")" "$(median "$work/b.encode")"
printf '  decode  A %ss  B %ss   (decode + write PLY)\n' "$(median "$work/a.decode")" "$(median "$work/b.decode")"
