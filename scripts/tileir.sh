#!/usr/bin/env bash
# scripts/tileir.sh BIN: tile-loop instructions (callgrind, one thread, Embree pinned to AVX2 so the
# count does not depend on the CPU's AVX-512) of three renders the performance pages quote:
# cornellSimple (path tracer, 128x128, 4 spp), hw2 analytic under `direct` and `analyticdirect`
# (320x240, 16 spp). Counted inclusively under rayon's worker entry (`bridge_producer_consumer`),
# so scene loading and output are left out. Needs valgrind and ../shared/cse168.
set -euo pipefail
BIN=${1:?usage: scripts/tileir.sh path/to/strata}
S="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)/shared/cse168"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
run() {
    local name=$1
    shift
    STRATA_EMBREE_CONFIG=isa=avx2 valgrind --tool=callgrind --callgrind-out-file="$tmp/cg.$name" \
        --toggle-collect='*bridge_producer_consumer*helper*' "$BIN" render "$@" --threads 1 \
        -o "$tmp/img" >/dev/null 2>&1
    echo "$name $(callgrind_annotate "$tmp/cg.$name" 2>/dev/null | grep -m1 'PROGRAM TOTALS' | awk '{print $1}')"
}
run cornell "$S/hw3/cornellSimple.test" --size 128x128 --spp 4
run analytic_direct "$S/hw2/analytic.test" --integrator direct --size 320x240 --spp 16
run analytic "$S/hw2/analytic.test" --size 320x240 --spp 16
