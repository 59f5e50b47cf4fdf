"""strata from Python: render, reference and compare scenes as the CLI does, with point sets
given as numpy arrays; error metrics on numpy images.

Keyword arguments are the CLI's flags (``light_samples=4`` is ``--light-samples 4``; ``True``
passes a bare flag; ``size=(w, h)``; a list repeats the flag), parsed by the CLI's own grammar,
so every CLI error is raised here as :class:`StrataError` with the same message. Renders release
the GIL; Ctrl-C stops a render after its pass (writing the checkpoint the CLI would) and raises
``KeyboardInterrupt``.

Point sets (``pixel_points``, ``light_points``, ``points``) are float arrays shaped
``[sets, points, dims]`` or ``[points, dims]`` with values in [0, 1), checked and mapped to
(pixel, dimension) exactly as ``--pixel-sampler file:PATH`` files are (``scramble=``, ``sets=``,
``pad=``, ``shuffle=`` are the file options; see docs/POINTSETS.md).
"""

import json
import os
import shlex

import numpy as np

from . import _strata
from ._strata import StrataError

__all__ = ["render", "reference", "compare", "Image", "Scene", "StrataError", "metrics", "points_sampler", "read_exr"]
__version__ = _strata.version()


class Image(np.ndarray):
    """A render: float32 H x W x 3 linear RGB (the per-pixel mean), with ``variance`` (the
    variance of that mean, H x W x 3), ``stats`` (the ``--stats`` JSON as a dict) and
    ``metadata`` (the ``strata.*`` attributes of the EXR the CLI writes, as a dict; None for a
    plain render)."""

    def __new__(cls, rgb, variance, stats, metadata=None):
        obj = np.asarray(rgb, dtype=np.float32).view(cls)
        obj.variance = variance
        obj.stats = stats
        obj.metadata = metadata
        return obj

    def __array_finalize__(self, obj):
        self.variance = getattr(obj, "variance", None)
        self.stats = getattr(obj, "stats", None)
        self.metadata = getattr(obj, "metadata", None)


class Scene:
    """A scene file parsed once (a bad file raises here), rendered many times: every render
    given it starts from the parsed scene (the Embree scene is still built per render), with
    ``flags`` (e.g. ``size``, ``camera``, ``integrator``) applied before the render's own."""

    def __init__(self, path, **flags):
        self.path = os.fspath(path)
        self.flags = dict(flags)
        self._parsed = _strata.parse_scene(_render_args(self.path, {**self.flags, "progress": True}))

    def __repr__(self):
        return f"strata.Scene({self.path!r}, {self.flags!r})"


def _flag_args(flags):
    args = []
    for key, value in flags.items():
        if value is None or value is False:
            continue
        flag = "--" + key.replace("_", "-")
        if value is True:
            args.append(flag)
        elif key == "size" and isinstance(value, (tuple, list)):
            args += [flag, f"{value[0]}x{value[1]}"]
        elif key == "samples" and isinstance(value, (tuple, list, range)):
            lo, hi = (value.start, value.stop) if isinstance(value, range) else value
            args += [flag, f"{lo}..{hi}"]
        elif isinstance(value, (list, tuple)):
            for v in value:
                args += [flag, str(v)]
        else:
            args += [flag, os.fspath(value) if isinstance(value, os.PathLike) else str(value)]
    return args


def points_sampler(name, array, scramble=None, sets=None, pad=None, shuffle=None):
    """Checks a point array as a point-set file is checked (the messages name ``<array NAME>``)
    and registers it; returns the sampler name that render flags accept."""
    a = np.asarray(array)
    if a.dtype.kind != "f":
        raise StrataError(f"<array {name}>: dtype {a.dtype}: expected float32 or float64")
    if a.ndim == 2:
        a = a[None]
    if a.ndim != 3:
        raise StrataError(f"<array {name}>: shape {list(np.shape(array))}: expected [sets, points, dims] or [points, dims]")
    pairs = (("scramble", scramble), ("sets", sets), ("pad", pad), ("shuffle", shuffle))
    options = "&".join(f"{k}={v}" for k, v in pairs if v)
    data = np.ascontiguousarray(a, dtype="<f8").tobytes()
    return _strata.check_points(name, data, list(a.shape), options)


def _render_args(scene, flags):
    flags = dict(flags)
    if isinstance(scene, Scene):
        flags = {**scene.flags, **flags}
        scene = scene.path
    arrays = {k: flags.pop(k) for k in ("pixel_points", "light_points", "points") if flags.get(k) is not None}
    opts = {k: flags.pop(k, None) for k in ("scramble", "sets", "pad", "shuffle")}
    flag = {"pixel_points": "pixel_sampler", "light_points": "light_sampler", "points": "sampler"}
    for name, array in arrays.items():
        flags[flag[name]] = points_sampler(name, array, **opts)
    if not flags.pop("progress", False):
        flags["quiet"] = True
    args = [] if scene is None else [os.fspath(scene)]
    return args + _flag_args(flags)


def render(scene=None, **flags):
    """Renders ``scene`` (a path, a :class:`Scene`, or None for the built-in Cornell box) with the
    CLI's render flags (``spp``, ``seed``, ``threads``, ``pixel_sampler``, ``light_sampler``,
    ``integrator``, ...), point arrays ``pixel_points`` / ``light_points`` / ``points``, and
    ``out`` (also write OUT.exr and OUT.png as the CLI does). Returns an :class:`Image`."""
    write = flags.get("out") is not None
    parsed = scene._parsed if isinstance(scene, Scene) else None
    rgb, var, w, h, stats = _strata.render(_render_args(scene, flags), write, parsed)
    shape = (h, w, 3)
    return Image(
        np.frombuffer(rgb, dtype="<f4").reshape(shape),
        np.frombuffer(var, dtype="<f4").reshape(shape),
        json.loads(stats),
    )


def read_exr(path):
    """Reads an EXR as strata writes it (a reference, say) into an :class:`Image`; ``stats``
    holds the file's ``strata.*`` metadata, ``variance`` its variance layer (or None)."""
    rgb, var, w, h, meta = _strata.read_exr(os.fspath(path))
    shape = (h, w, 3)
    variance = None if var is None else np.frombuffer(var, dtype="<f4").reshape(shape)
    return Image(np.frombuffer(rgb, dtype="<f4").reshape(shape), variance, dict(meta))


def reference(scene=None, **flags):
    """``strata reference``, run by the same library function as the CLI: ``spp`` is required;
    pixel sample 0 is jittered unless ``first_sample`` says otherwise (a reference is unbiased
    whatever the scene's conventions); ``replicas`` independent renders (default: the largest
    divisor of ``spp`` from 2 to 8) give the variance layer, their variance of the mean. ``out``
    also writes the CLI's EXR (with that layer and its metadata) and PNG. Returns an
    :class:`Image`: ``variance`` is the layer, ``stats`` the ``--stats`` JSON (``replicas``,
    ``variance_estimate``, ...), ``metadata`` the EXR's ``strata.*`` attributes."""
    write = flags.get("out") is not None
    parsed = scene._parsed if isinstance(scene, Scene) else None
    rgb, var, w, h, stats, meta = _strata.reference(_render_args(scene, flags), write, parsed)
    shape = (h, w, 3)
    return Image(
        np.frombuffer(rgb, dtype="<f4").reshape(shape),
        np.frombuffer(var, dtype="<f4").reshape(shape),
        json.loads(stats),
        dict(meta),
    )


def _variant_flags(name, v):
    if isinstance(v, str):
        return v
    args = []
    for a in _render_args(None, {**v, "progress": True}):
        if " " in a:
            raise StrataError(f"variant {name}: `{a}`: compare splits flags at spaces")
        args.append(a)
    return " ".join(args)


def _compare_args(scene, reference, variants, flags):
    """The ``strata compare`` arguments of a :func:`compare` call."""
    flags = dict(flags)
    args = [] if scene is None else [os.fspath(scene.path if isinstance(scene, Scene) else scene)]
    args += ["--reference", os.fspath(reference)]
    # A Scene's flags hold as for render: its size is compare's --size (unless given), the rest
    # go before each variant's own flags.
    scene_flags = dict(scene.flags) if isinstance(scene, Scene) else {}
    if "size" in scene_flags:
        size = scene_flags.pop("size")
        flags.setdefault("size", size)
    for name, v in variants.items():
        if scene_flags:
            v = {**scene_flags, **v} if isinstance(v, dict) else shlex.join(_flag_args(scene_flags)) + " " + v
        args += ["--variant", f"{name}={_variant_flags(name, v)}"]
    for key in ("spp_ladder", "budget"):
        value = flags.pop(key, None)
        if isinstance(value, (list, tuple)):
            value = ",".join(str(s) for s in value)
        if value is not None:
            args += ["--" + key.replace("_", "-"), str(value)]
    return args + _flag_args(flags)


def _literal(value):
    """A keyword argument's value as the report's Python call shows it (arrays by shape)."""
    if isinstance(value, np.ndarray):
        return f"<array {list(value.shape)} {value.dtype}>"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k!r}: {_literal(v)}" for k, v in value.items()) + "}"
    if isinstance(value, Scene):
        return f"strata.Scene({value.path!r}" + "".join(f", {k}={_literal(v)}" for k, v in value.flags.items()) + ")"
    if isinstance(value, os.PathLike):
        return repr(os.fspath(value))
    return repr(value)


def compare(scene=None, *, reference, variants, **flags):
    """``strata compare``: ``variants`` maps names to render flags (a string as on the command
    line, or a dict of keyword arguments, point arrays included); the other keywords are
    compare's flags (``runs``, ``budget`` (one or a list: a budget ladder), ``spp_ladder``,
    ``size``, ``threads``, ``out``, ...), with the CLI's defaults. Writes the CLI's outputs (the
    report's "Reproduce" gives this call, then the CLI's equivalent) and returns the rows (a
    pandas DataFrame if pandas is installed, else a list of dicts)."""
    kwargs = {"reference": reference, "variants": variants, **flags}
    call = "strata.compare(" + ", ".join(
        ([] if scene is None else [_literal(scene)]) + [f"{k}={_literal(v)}" for k, v in kwargs.items()]
    ) + ")"
    rows = json.loads(_strata.compare(_compare_args(scene, reference, variants, flags), call))
    try:
        import pandas
    except ImportError:
        return rows
    return pandas.DataFrame(rows)


from . import metrics  # noqa: E402  (uses _strata)
