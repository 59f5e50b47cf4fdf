"""The Python module against the CLI: same images bit for bit, same refusals, same compare rows;
the GIL is released during renders and Ctrl-C raises KeyboardInterrupt."""

import _thread
import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import strata

ROOT = Path(__file__).resolve().parents[2]
BIN = Path(os.environ.get("STRATA_BIN", ROOT / "target" / "release" / "strata"))
SCENE = ROOT / "scenes" / "light_tiny.test"  # 32 x 32, direct lighting, one light
SHARED = ROOT.parent / "shared"


def cli(*args, check=True):
    r = subprocess.run([str(BIN), *map(str, args)], capture_output=True, text=True)
    if check and r.returncode != 0:
        raise AssertionError(f"strata {' '.join(map(str, args))} failed:\n{r.stderr}")
    return r


def test_render_is_bit_identical_to_the_cli(tmp_path):
    flags = dict(spp=8, seed=3, threads=2, size=(24, 16), light_sampler="sobol", light_samples=2)
    cli("render", SCENE, "--spp", 8, "--seed", 3, "--threads", 2, "--size", "24x16",
        "--light-sampler", "sobol", "--light-samples", 2, "-q", "-o", tmp_path / "cli")
    exr = strata.read_exr(tmp_path / "cli.exr")
    img = strata.render(SCENE, **flags)
    assert img.shape == (16, 24, 3) and img.dtype == np.float32
    assert np.array_equal(np.asarray(img), np.asarray(exr))
    assert np.array_equal(img.variance, exr.variance)
    assert img.stats["spp"] == 8 and exr.stats["strata.seed"] == "3"
    # A point array: the same as the same points in a file.
    pts = np.random.default_rng(7).random((3, 8, 2))
    np.save(tmp_path / "pts.npy", pts)
    cli("render", SCENE, "--spp", 8, "--size", "24x16", "--pixel-sampler", f"file:{tmp_path / 'pts.npy'}",
        "-q", "-o", tmp_path / "file")
    arr = strata.render(SCENE, spp=8, size=(24, 16), pixel_points=pts)
    assert np.array_equal(np.asarray(arr), np.asarray(strata.read_exr(tmp_path / "file.exr")))
    assert not np.array_equal(np.asarray(arr), np.asarray(strata.render(SCENE, spp=8, size=(24, 16))))


@pytest.mark.parametrize(
    "values, why",
    [
        (lambda a: a.__setitem__((1, 2, 0), 1.5), "set 1, point 2, coordinate 0: 1.5 is outside [0, 1)"),
        (lambda a: a.__setitem__((0, 5, 1), np.nan), "set 0, point 5, coordinate 1: NaN (coordinates must be numbers in [0, 1))"),
        (lambda a: a.__setitem__((2, 0, 1), -0.25), "set 2, point 0, coordinate 1: -0.25 is outside [0, 1)"),
    ],
)
def test_arrays_are_refused_with_the_files_messages(tmp_path, values, why):
    a = np.random.default_rng(1).random((3, 16, 2))
    values(a)
    np.save(tmp_path / "bad.npy", a)
    r = cli("render", SCENE, "--spp", 4, "-q", "--pixel-sampler", f"file:{tmp_path / 'bad.npy'}",
            "-o", tmp_path / "x", check=False)
    assert r.returncode != 0
    with pytest.raises(strata.StrataError) as e:
        strata.render(SCENE, spp=4, pixel_points=a)
    # The same message, naming the file or the array.
    assert f"{tmp_path / 'bad.npy'}: {why}" in r.stderr, r.stderr
    assert str(e.value) == f"<array pixel_points>: {why}"


def test_too_few_points_and_cli_errors_have_the_cli_messages(tmp_path):
    a = np.random.default_rng(2).random((1, 4, 2))
    np.save(tmp_path / "few.npy", a)
    r = cli("render", SCENE, "--spp", 8, "-q", "--pixel-sampler", f"file:{tmp_path / 'few.npy'}", check=False)
    with pytest.raises(strata.StrataError) as e:
        strata.render(SCENE, spp=8, pixel_points=a)
    tail = "its sets have 4 points, but 8 spp are drawn per pixel"
    assert tail in r.stderr and tail in str(e.value)
    r = cli("render", SCENE, "--spp", 4, "--max-depth", -7, "-q", check=False)
    with pytest.raises(strata.StrataError) as e:
        strata.render(SCENE, spp=4, max_depth=-7)
    assert str(e.value) == r.stderr.strip().removeprefix("strata: ")
    with pytest.raises(strata.StrataError, match="unexpected argument '--no-such-flag'"):
        strata.render(SCENE, no_such_flag=1)


def test_keyboard_interrupt_stops_a_render(tmp_path):
    # Python's own Ctrl-C handler, as in an interactive session: a process started in the
    # background by a non-interactive shell inherits SIGINT ignored, and then Python installs no
    # handler and `interrupt_main` does nothing (the render would run all its samples).
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    timer = threading.Timer(1.0, _thread.interrupt_main)
    start = time.monotonic()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt, match="render interrupted after"):
            strata.render(SCENE, spp=10_000_000, threads=1, out=tmp_path / "long")
    finally:
        signal.signal(signal.SIGINT, previous)
    assert time.monotonic() - start < 30
    # As the CLI on SIGINT: the image and a checkpoint to resume are written.
    assert (tmp_path / "long.ckpt").is_file() and (tmp_path / "long.exr").is_file()


def test_the_gil_is_released_while_rendering():
    ticks = []
    done = threading.Event()

    def count():
        while not done.is_set():
            ticks.append(time.monotonic())
            time.sleep(0.001)

    t = threading.Thread(target=count)
    t.start()
    time.sleep(0.05)
    start = time.monotonic()
    strata.render(SCENE, spp=16384, threads=1)
    end = time.monotonic()
    done.set()
    t.join()
    during = [x for x in ticks if start < x < end]
    assert end - start > 0.3, "the render should take a while"
    # Were the GIL held for the render, the counting thread could not tick during it.
    assert len(during) >= 20, (len(during), end - start)


def test_compare_rows_equal_the_clis(tmp_path):
    ref = tmp_path / "ref"
    strata.reference(SCENE, spp=256, size=(16, 16), out=ref)
    variants = {"sobol": "--light-sampler sobol", "indep": {"light_sampler": "independent"}}
    cli("compare", SCENE, "--reference", f"{ref}.exr", "--variant", "sobol=--light-sampler sobol",
        "--variant", "indep=--light-sampler independent", "--runs", 2, "--spp-ladder", "1,4",
        "--size", "16x16", "--threads", 2, "--out", tmp_path / "cli")
    rows = strata.compare(SCENE, reference=f"{ref}.exr", variants=variants, runs=2, spp_ladder=[1, 4],
                          size=(16, 16), threads=2, out=tmp_path / "py")
    if not isinstance(rows, list):
        rows = rows.to_dict("records")
    want = json.loads((tmp_path / "cli" / "rows.json").read_text())
    exact = ["variant", "spp", "mse", "rel_mse", "bias", "bias_ci", "variance"]
    assert [{k: r[k] for k in exact} for r in rows] == [{k: r[k] for k in exact} for r in want]


def test_compare_accepts_point_arrays_and_metrics_match_compare(tmp_path):
    ref = tmp_path / "ref"
    refimg = strata.reference(SCENE, spp=64, size=(16, 16), out=ref)
    pts = np.random.default_rng(3).random((4, 16, 2))
    rows = strata.compare(SCENE, reference=f"{ref}.exr", variants={"array": {"light_points": pts}},
                          runs=2, spp_ladder=[4], size=(16, 16), threads=2, out=tmp_path / "c")
    if not isinstance(rows, list):
        rows = rows.to_dict("records")
    assert rows[0]["variant"] == "array" and rows[0]["mse"] > 0
    img = strata.render(SCENE, spp=4, size=(16, 16), light_points=pts)
    d = np.asarray(img, np.float64) - np.asarray(refimg, np.float64)
    assert strata.metrics.rmse(img, refimg) == pytest.approx(float(np.sqrt(np.mean(d**2))), rel=1e-12)
    assert strata.metrics.mse(refimg, refimg) == 0.0
    with pytest.raises(ValueError):
        strata.metrics.rmse(img, refimg[:8])
    # FLIP: the same code as compare's FLIP column; zero for identical images, a per-pixel map whose
    # mean is the number returned.
    assert strata.metrics.flip(refimg, refimg) == 0.0
    mean, fmap = strata.metrics.flip(img, refimg, return_map=True)
    assert fmap.shape == (16, 16) and 0.0 < mean < 1.0
    assert mean == pytest.approx(float(np.mean(fmap.astype(np.float64))), rel=1e-9)


def test_example_runs_at_a_small_size(tmp_path):
    sphere = SHARED / "cse168" / "hw2" / "sphere.test"  # needs ../shared (CI has it)
    assert sphere.is_file(), f"{sphere} missing: the shared corpus is required"
    example = ROOT / "examples" / "python" / "compare_point_sets.py"
    r = subprocess.run([sys.executable, str(example), "--small", "--out", str(tmp_path)],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "rmse_vs_time.png").is_file()
    rows = json.loads((tmp_path / "results.json").read_text())
    assert {r["sampler"] for r in rows} == {"rank1", "jittered", "sobol"}
    # Error falls with spp for every sampler.
    for name in ("rank1", "jittered", "sobol"):
        errs = [r["rmse"] for r in sorted(rows, key=lambda r: r["spp"]) if r["sampler"] == name]
        assert errs[-1] < errs[0], (name, errs)


def test_a_scene_is_parsed_once_and_renders_like_its_path(tmp_path):
    path = tmp_path / "s.test"
    path.write_text(SCENE.read_text())
    scene = strata.Scene(path, size=(16, 8))
    path.write_text("this is no longer a scene\n")  # renders use the parsed scene, not the file
    a = strata.render(scene, spp=4, seed=2)
    b = strata.render(SCENE, spp=4, seed=2, size=(16, 8))
    assert np.array_equal(np.asarray(a), np.asarray(b))
    with pytest.raises(strata.StrataError, match="s.test:1"):
        strata.Scene(path)


def test_files_and_arrays_compare_against_sobol_at_equal_time(tmp_path):
    """The issue's run in one go (small): a hand-written UTK text set, a .npy and an array, each
    against Sobol' with compare's --budget on the hw2 sphere (needs ../shared)."""
    assert (SHARED / "cse168" / "hw2" / "sphere.test").is_file(), "the shared corpus is required"
    example = ROOT / "examples" / "python" / "point_sets_at_equal_time.py"
    r = subprocess.run([sys.executable, str(example), "--small", "--out", str(tmp_path)],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    rows = json.loads((tmp_path / "compare" / "rows.json").read_text())
    assert [row["variant"] for row in rows] == ["utk-text", "npy", "array", "sobol"]
    for row in rows:
        assert row["spp"] > 4 and 0 < row["mse"] < 0.01, row
