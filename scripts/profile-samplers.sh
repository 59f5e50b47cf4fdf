#!/usr/bin/env bash
# Sampler cost inside real renders: for each scene (default: hw3 cornellSimple, hw4 cornellBRDF,
# hw2 direct9 of ../shared/cse168) and each registered sampler X, runs
#   strata profile SCENE --pixel-sampler X --light-sampler X [ARGS]
# and prints one row: the sampler phases' share of render time and ns/sample, the replayed
# sampler ns/sample (the render's exact calls, one thread, thread CPU time) and the measured
# profiling overhead. ARGS (after --) go to every run; default: --threads 1 --spp 4 --repeats 3.
#   scripts/profile-samplers.sh [SCENE...] [-- ARGS...]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bin="${STRATA:-$root/target/release/strata}"
[ -x "$bin" ] || (cd "$root" && cargo build --release --quiet)
scenes=()
while [ $# -gt 0 ] && [ "$1" != "--" ]; do scenes+=("$1"); shift; done
[ "${1:-}" = "--" ] && shift
args=("$@")
[ ${#args[@]} -gt 0 ] || args=(--threads 1 --spp 4 --repeats 3)
if [ ${#scenes[@]} -eq 0 ]; then
  s="$root/../shared/cse168"
  scenes=("$s/hw3/cornellSimple.test" "$s/hw4/cornellBRDF.test" "$s/hw2/direct9.test")
fi
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
# The registry's names, as the CLI lists them.
samplers=$("$bin" profile --help | sed -n 's/.*Light sample layout: //p' | sed 's/ ([a-z]*)//g; s/,//g')
printf '%-16s %-12s %9s %14s %13s %10s\n' scene sampler "sampler %" "instr ns/smp" "replay ns/smp" overhead
for scene in "${scenes[@]}"; do
  for x in $samplers; do
    "$bin" profile "$scene" --pixel-sampler "$x" --light-sampler "$x" "${args[@]}" --json "$tmp/p.json" >/dev/null
    python3 - "$tmp/p.json" "$(basename "$scene" .test)" "$x" <<'PY'
import json, sys
p = json.load(open(sys.argv[1]))
s = [r for r in p["phases"] if r["name"].startswith("sampler")]
r = p["sampler_replay"]
print("%-16s %-12s %8.1f%% %14.1f %13.1f %+9.1f%%" % (sys.argv[2], sys.argv[3], 100 * sum(x["share"] for x in s),
      sum(x["ns_per_sample"] for x in s), r["ns_per_sample"], 100 * p["overhead"]))
PY
  done
done
