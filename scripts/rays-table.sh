#!/usr/bin/env bash
# The issue-15 throughput table: `strata rays` (whole renderer vs Embree raw on the same packets,
# one thread, thread CPU time) on the five target scenes, for one or more strata binaries run
# interleaved (binary 1 scene 1, binary 2 scene 1, ...) for ROUNDS rounds, as a Markdown table
# (each round's value, and the median of the rounds' ratios).
#   scripts/rays-table.sh [-r ROUNDS] [-s WxH] [-p SPP] BIN [BIN ...]
# Default: 2 rounds, 256x256, 4 spp. Needs ../shared/cse168 beside the checkout and python3.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
rounds=2 size=256x256 spp=4
while getopts "r:s:p:" o; do
  case $o in r) rounds=$OPTARG ;; s) size=$OPTARG ;; p) spp=$OPTARG ;; *) exit 2 ;; esac
done
shift $((OPTIND - 1))
[ $# -ge 1 ] || { echo "usage: $0 [-r ROUNDS] [-s WxH] [-p SPP] BIN [BIN ...]" >&2; exit 2; }
corpus="$root/../shared/cse168"
[ -d "$corpus" ] || { echo "rays-table: $corpus not found" >&2; exit 2; }
scenes=(
  "cornellSimple|hw3/cornellSimple.test|--nee mis --importance-sampling brdf --russian-roulette off"
  "dragon|hw4/dragon.test|"
  "analytic|hw2/analytic.test|--integrator direct"
  "sphere|hw2/sphere.test|"
  "direct3x3|hw2/direct3x3.test|"
)
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
for r in $(seq "$rounds"); do
  for s in "${scenes[@]}"; do
    IFS='|' read -r name file flags <<<"$s"
    for b in $(seq $#); do
      bin="${!b}"
      # shellcheck disable=SC2086
      "$bin" rays "$corpus/$file" $flags --spp "$spp" --size "$size" --threads 1 --json >"$tmp/$name.$b.$r.json"
    done
  done
done
python3 - "$tmp" "$rounds" "$@" <<'EOF'
import json, sys
tmp, rounds, bins = sys.argv[1], int(sys.argv[2]), sys.argv[3:]
names = ["cornellSimple", "dragon", "analytic", "sphere", "direct3x3"]
print("| scene | binary | renderer Mrays/s | Embree raw Mrays/s | renderer / raw | median ratio |")
print("|---|---|---:|---:|---:|---:|")
for n in names:
    for b, path in enumerate(bins, 1):
        rs = [json.load(open(f"{tmp}/{n}.{b}.{r}.json")) for r in range(1, rounds + 1)]
        cell = lambda k, f: " / ".join(f.format(x[k]) for x in rs)
        print(f"| {n} | {path} | {cell('renderer_mrays', '{:.2f}')} | {cell('raw_mixed_mrays', '{:.1f}')} "
              f"| {' / '.join('{:.1f} %'.format(100 * x['ratio']) for x in rs)} "
              f"| {100 * sorted(x['ratio'] for x in rs)[len(rs) // 2]:.1f} % |")
EOF
