#!/usr/bin/env bash
# Installs what is missing (scripts/setup.sh), then runs the whole test suite in release mode.
#   scripts/test.sh [--slurm] [cargo test args...]
# --slurm: afterwards, also run scripts/test-slurm.sh (a real one-node Slurm: the job-array
# recipe of examples/cluster with a requeued task, merged bit-identically; root, about a minute).
# A full run (no cargo test args) first checks `cargo fmt --check` and
# `cargo clippy --profile ci --workspace --all-targets -- -D warnings` (the renderer and python/), and
# after the Rust tests builds the Python module into .venv and runs its pytest suite (python/tests).
# Everything builds in one cargo profile, `ci` (Cargo.toml: release code without thin LTO and debug
# info), so clippy, the tests, the binary, the Python module and the Slurm test share the build
# scripts and dependencies, and the library that the binary, the integration tests and the Python
# module link is compiled once.
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
  echo "test: cargo clippy --profile ci --workspace --all-targets -- -D warnings" >&2
  cargo clippy --profile ci --workspace --all-targets -- -D warnings
fi
# --no-fail-fast: one failing test binary does not hide the others' results (the exit status still fails).
# The tests run with a temp dir of their own, which must be empty afterwards: a test that leaves
# scratch files behind (in every developer's /tmp, run after run) fails the suite.
tests_tmp="$(mktemp -d)"
trap 'rm -rf "$tests_tmp"' EXIT
TMPDIR="$tests_tmp" cargo test --profile ci --no-fail-fast ${args[@]+"${args[@]}"}
if [ -n "$(ls -A "$tests_tmp")" ]; then
  echo "test: the tests left these in their temp dir (use tests/it/common.rs's tmpdir(), removed on drop):" >&2
  ls -A "$tests_tmp" >&2
  exit 1
fi
if [ ${#args[@]} -eq 0 ]; then
  # The Python module (scripts/setup.sh --python builds it into .venv), tested against the binary
  # cargo test just built.
  STRATA_PROFILE=ci "$root/scripts/setup.sh" --python
  echo "test: pytest python/tests" >&2
  STRATA_BIN="$root/target/ci/strata" "$root/.venv/bin/python" -m pytest -q "$root/python/tests"
fi
if [ -n "$slurm" ]; then
  STRATA="${STRATA:-$root/target/ci/strata}" "$root/scripts/test-slurm.sh"
fi
