#!/usr/bin/env bash
# Generates the million-triangle procedural OBJ (bumpy torus, floor, wall, emissive patch) into
# target/mesh/torus1m.{obj,mtl} (about 40 MB, never committed), then renders scenes/torus1m.test.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/setup.sh
cargo build --release
mkdir -p target/mesh out
./target/release/strata gen-mesh target/mesh/torus1m.obj --triangles 1000000
./target/release/strata render scenes/torus1m.test -o out/torus1m "$@"
./target/release/strata rays scenes/torus1m.test --spp 2
