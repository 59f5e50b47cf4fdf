#!/usr/bin/env bash
# Installs what is missing (scripts/setup.sh), then runs the whole test suite in release mode.
#   scripts/test.sh [--slurm] [cargo test args...]
# --slurm: afterwards, also run scripts/test-slurm.sh (a real one-node Slurm: the job-array
# recipe of examples/cluster with a requeued task, merged bit-identically; root, about a minute).
# A full run (no cargo test args) first checks `cargo fmt --check` and
# `cargo clippy --release --all-targets -- -D warnings`.
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
if [ ${#args[@]} -eq 0 ]; then
  if ! cargo fmt --version >/dev/null 2>&1 || ! cargo clippy --version >/dev/null 2>&1; then
    echo "test: installing rustfmt and clippy (rustup component add)" >&2
    rustup component add rustfmt clippy
  fi
  echo "test: cargo fmt --check" >&2
  cargo fmt --check
  echo "test: cargo clippy --release --all-targets -- -D warnings" >&2
  cargo clippy --release --all-targets -- -D warnings
fi
cargo test --release ${args[@]+"${args[@]}"}
if [ -n "$slurm" ]; then
  "$root/scripts/test-slurm.sh"
fi
