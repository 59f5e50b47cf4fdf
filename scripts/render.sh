#!/usr/bin/env bash
# Installs what is missing (scripts/setup.sh), then renders: with no arguments, the built-in Cornell box
# to out/cornell.exr and out/cornell.png. Any arguments are passed to `strata render`.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/scripts/setup.sh"
[ -x "$HOME/.cargo/bin/cargo" ] && export PATH="$HOME/.cargo/bin:$PATH"
cd "$root"
mkdir -p out
if [ $# -eq 0 ]; then set -- -o out/cornell; fi
cargo run --release --quiet -- render "$@"
