"""Renders scenes/cbox.xml (or another XML scene, e.g. scenes/sphere_lights.xml) with Mitsuba 3 (the peer in ../shared/peers/mitsuba) into a mean image
and a per-sample variance image (the `moment` integrator, as Mitsuba's own regression references),
for the per-pixel comparison with strata (`cargo run --release --example mitsuba_ztest -- cbox`).

    source ../shared/peers/mitsuba/env.sh
    $PY scripts/cbox-mitsuba.py scenes/cbox.xml OUT_DIR [SPP [NAME]]

NAME (default `cbox`) names the outputs NAME_ref_rgb.exr and NAME_ref_rgb_var.exr.
"""
import sys

import mitsuba as mi
import numpy as np

mi.set_variant("llvm_ad_rgb")
scene_path, out = sys.argv[1], sys.argv[2]
spp = int(sys.argv[3]) if len(sys.argv) > 3 else 4096
name = sys.argv[4] if len(sys.argv) > 4 else "cbox"
scene = mi.load_file(scene_path)
integrator = mi.load_dict({"type": "moment", "nested": scene.integrator()})
img = np.array(mi.render(scene, integrator=integrator, spp=spp))
# moment's channels: the nested image (RGB), then the first (RGB) and second (RGB) moments.
mean = img[:, :, 0:3]
m1, m2 = img[:, :, 3:6], img[:, :, 6:9]
var = np.maximum(m2 - m1 * m1, 0.0)
mi.Bitmap(mean.astype(np.float32)).write(f"{out}/{name}_ref_rgb.exr")
mi.Bitmap(var.astype(np.float32)).write(f"{out}/{name}_ref_rgb_var.exr")
print("spp", spp, "mean", mean.mean(axis=(0, 1)))
