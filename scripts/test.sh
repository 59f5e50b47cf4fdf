#!/usr/bin/env bash
# Installs what is missing (scripts/setup.sh), then runs the whole test suite in release mode.
#   scripts/test.sh [--slurm] [cargo test args...]
# --slurm: afterwards, also run scripts/test-slurm.sh (a real one-node Slurm: the job-array
# recipe of examples/cluster with a requeued task, merged bit-identically; root, about a minute).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
slurm=
args=()
for a in "$@"; do  # --slurm is ours (before a `--`), the rest goes to cargo test
  if [ "$a" = --slurm ] && [[ " ${args[*]-} " != *" -- "* ]]; then slurm=1; else args+=("$a"); fi
done
"$root/scripts/setup.sh"
[ -x "$HOME/.cargo/bin/cargo" ] && export PATH="$HOME/.cargo/bin:$PATH"
cd "$root"
cargo test --release ${args[@]+"${args[@]}"}
if [ -n "$slurm" ]; then
  "$root/scripts/test-slurm.sh"
fi
