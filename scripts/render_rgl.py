"""Renders a sphere with an RGL .bsdf file in Mitsuba 3 (pip install mitsuba).

    python3 scripts/render_rgl.py out/merl-ggx-gold/brdf.bsdf docs/figures/rgl-gold-mitsuba.png

A constant grey sky plus one directional light, path tracing, 256 x 256 pixels.
"""
import sys

import mitsuba as mi

mi.set_variant("scalar_rgb")
bsdf_file, png = sys.argv[1], sys.argv[2]
scene = mi.load_dict({
    "type": "scene",
    "integrator": {"type": "path", "max_depth": 4},
    "sensor": {
        "type": "perspective",
        "fov": 30,
        "to_world": mi.ScalarTransform4f().look_at(origin=[0, 0, 5], target=[0, 0, 0], up=[0, 1, 0]),
        "film": {"type": "hdrfilm", "width": 256, "height": 256, "rfilter": {"type": "gaussian"}},
        "sampler": {"type": "independent", "sample_count": 256},
    },
    "sphere": {"type": "sphere", "bsdf": {"type": "measured", "filename": bsdf_file}},
    "sky": {"type": "constant", "radiance": {"type": "rgb", "value": 0.3}},
    "sun": {"type": "directional", "direction": [-1, -1, -1], "irradiance": {"type": "rgb", "value": 3.0}},
})
mi.util.write_bitmap(png, mi.render(scene))
print(f"wrote {png}")
