#!/usr/bin/env bash
# Renders the README's gallery into docs/gallery/: the built-in Cornell box and real-world OBJs
# from ../shared/corpora/obj-wild with default flags (automatic camera, default light), plus one
# scene under --sky, and the material preview scenes/materials.xml (640x360). Writes NAME.png per image and docs/gallery/README.md (each image with the
# exact command that made it). Usage: scripts/gallery.sh [SPP]  (default 256; 320x240 each).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/scripts/setup.sh"
[ -x "$HOME/.cargo/bin/cargo" ] && export PATH="$HOME/.cargo/bin:$PATH"
cd "$root"
cargo build --release --quiet
spp="${1:-256}"
wild="../shared/corpora/obj-wild"
[ -f "$wild/SOURCES.md" ] || { echo "gallery.sh: $wild is missing (the shared corpus)" >&2; exit 1; }
out=docs/gallery
mkdir -p "$out"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
md="$out/README.md"
{
  echo "# Gallery"
  echo
  echo "Made by \`scripts/gallery.sh $spp\` (320x240, $spp spp; the OBJs from \`../shared/corpora/obj-wild\`,"
  echo "rendered with default flags: the automatic camera and, where the file has no light, the default one)."
  echo
} > "$md"
# name | title | arguments after `strata render`
while IFS='|' read -r name title args; do
  [ -n "$name" ] || continue
  echo "gallery.sh: $name" >&2
  # shellcheck disable=SC2086
  target/release/strata render $args --size 320x240 --spp "$spp" -q -o "$tmp/$name"
  cp "$tmp/$name.png" "$out/$name.png"
  {
    echo "## $title"
    echo
    echo "![$title]($name.png)"
    echo
    echo '```sh'
    echo "strata render $args --size 320x240 --spp $spp"
    echo '```'
    echo
  } >> "$md"
done <<LIST
cornell|The built-in Cornell box (CSE168 .test)|
mcguire|McGuire's Cornell box (OBJ, Ke light), looked into through its open side|$wild/cornell-original/CornellBox-Original.obj
tinyobj|tinyobjloader's Cornell box (light given as Ka 20 20 20)|$wild/cornell-tinyobj/cornell_box.obj
bunny|Stanford bunny (no light in the file: default area light)|$wild/scan-stanford-bunny/stanford-bunny.obj
house|A z-up house (up axis guessed from the bounds)|$wild/regr01-house/regr01.obj
sponza|Dabrovic Sponza (an interior: camera inside, light under the roof)|$wild/sponza-dabrovic-2005/sponza.obj
sibenik|Sibenik cathedral (interior)|$wild/sibenik-blender/sibenik.obj
dragon|Scanned dragon under a constant sky|$wild/scan-dragon-100k/dragon.obj --sky 0.8
LIST
# The material preview: strata's own Mitsuba XML scene at its own size (640x360).
echo "gallery.sh: materials" >&2
target/release/strata render scenes/materials.xml --spp "$spp" -q -o "$tmp/materials"
cp "$tmp/materials.png" "$out/materials.png"
{
  echo "## Material preview (Mitsuba 3 XML: glass, rough glass, Au, rough Cu, plastic, rough plastic, diffuse)"
  echo
  echo "![Material preview](materials.png)"
  echo
  echo '```sh'
  echo "strata render scenes/materials.xml --spp $spp"
  echo '```'
  echo
} >> "$md"
du -ch "$out"/*.png | tail -1 >&2
