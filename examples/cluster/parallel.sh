#!/usr/bin/env bash
# A large reference on one host with GNU parallel: SHARDS processes, each rendering one range of
# sample indices (`--samples A..B`), then `strata merge`. The merged image is bit-identical to
# `strata render SCENE --spp SPP` on one machine (same flags and seed), whatever SHARDS and JOBS are.
#
#   SCENE=scene.test SPP=4096 SHARDS=8 JOBS=4 THREADS=2 OUT=ref examples/cluster/parallel.sh
#
# Re-running the script after a crash or reboot resumes every unfinished part from its checkpoint
# and skips the finished ones. Extra render flags (size, seed, samplers) go in FLAGS; they must be
# the same for every part (merge refuses parts of different renders).
set -euo pipefail
: "${SCENE:?set SCENE to a .test file}"
SPP=${SPP:-4096} SHARDS=${SHARDS:-8} JOBS=${JOBS:-4} THREADS=${THREADS:-1} OUT=${OUT:-ref}
FLAGS=${FLAGS:-} STRATA=${STRATA:-strata} PARTS=${PARTS:-$OUT.parts}
mkdir -p "$PARTS"
export SCENE SPP SHARDS THREADS FLAGS STRATA PARTS

part() { # part I: samples I*SPP/SHARDS .. (I+1)*SPP/SHARDS
    local i=$1 a=$(( $1 * SPP / SHARDS )) b=$(( ($1 + 1) * SPP / SHARDS ))
    local stem="$PARTS/part-$i" resume=()
    [ "$a" -lt "$b" ] || return 0
    if [ -f "$stem.ckpt" ]; then resume=(--resume "$stem.ckpt"); fi
    # shellcheck disable=SC2086 # FLAGS is a list of flags
    "$STRATA" render "$SCENE" --spp "$SPP" --samples "$a..$b" --threads "$THREADS" \
        --checkpoint "$stem.ckpt" --checkpoint-every 300 -o "$stem" -q $FLAGS "${resume[@]}"
}
export -f part

seq 0 $(( SHARDS - 1 )) | parallel --halt now,fail=1 -j "$JOBS" part {}
"$STRATA" merge "$PARTS"/part-*.ckpt -o "$OUT"
