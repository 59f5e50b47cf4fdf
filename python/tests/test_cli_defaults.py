"""Python = CLI (issue 31): every function of the module has the CLI's defaults, read from
``strata CMD --help`` so that they cannot drift; ``strata.reference`` is the CLI's ``reference``
(replicas, their variance layer, jittered first sample, metadata); docs/PYTHON.md's examples run
as written; a Python compare's report reproduces with the Python call."""

import html
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import strata
from strata import _strata

ROOT = Path(__file__).resolve().parents[2]
BIN = Path(os.environ.get("STRATA_BIN", ROOT / "target" / "release" / "strata"))
SCENE = ROOT / "scenes" / "light_tiny.test"  # 32 x 32, direct lighting, one light (first sample: centre)
SHARED = ROOT.parent / "shared"


def cli(*args):
    r = subprocess.run([str(BIN), *map(str, args)], capture_output=True, text=True)
    assert r.returncode == 0, f"strata {' '.join(map(str, args))} failed:\n{r.stderr}"
    return r


def help_defaults(cmd):
    """(flag, value) for every flag whose help in ``strata CMD --help`` ends in ``[default: X]``:
    an entry is a flag line and its indented continuation lines."""
    text = cli(cmd, "--help").stdout
    entries, current = [], None
    for line in text.splitlines():
        m = re.match(r"^\s+(?:-\w, )?(--[a-z0-9-]+)", line)
        if m:
            current = [m.group(1), line]
            entries.append(current)
        elif current is not None and line.startswith("  ") and line.strip():
            current[1] += " " + line.strip()
        else:
            current = None
    out = []
    for flag, body in entries:
        d = re.search(r"\[default: ([^\]]+)\]", body)
        if d:
            out.append((flag, d.group(1)))
    return out


# The arguments each Python function passes to the CLI's parser for its smallest call.
CALLS = {
    "render": lambda: strata._render_args(str(SCENE), {}),
    "reference": lambda: strata._render_args(str(SCENE), {"spp": 16}),
    "compare": lambda: strata._compare_args(str(SCENE), "ref.exr", {"a": "--light-samples 2"}, {}),
}
# What the CLI is given for the same call. Python's one addition is --quiet for render and
# reference (no progress bar on a notebook's stderr): output, not a result.
CLI_ARGS = {
    "render": [str(SCENE), "--quiet"],
    "reference": [str(SCENE), "--spp", "16", "--quiet"],
    "compare": [str(SCENE), "--reference", "ref.exr", "--variant", "a=--light-samples 2"],
}
DEFAULTS = [(cmd, flag, value) for cmd in CALLS for flag, value in help_defaults(cmd)]


def test_the_help_names_defaults_for_every_command():
    cmds = {cmd for cmd, _, _ in DEFAULTS}
    assert cmds == set(CALLS), DEFAULTS
    assert ("compare", "--runs", "4") in DEFAULTS and ("render", "--seed", "0") in DEFAULTS


@pytest.mark.parametrize("cmd, flag, value", DEFAULTS, ids=[f"{c}{f}={v}" for c, f, v in DEFAULTS])
def test_each_cli_default_holds_in_python(cmd, flag, value):
    """Python's call without the flag resolves to the options of the CLI with the flag at its
    documented default."""
    py = _strata.resolve(cmd, CALLS[cmd]())
    assert py == _strata.resolve(cmd, CALLS[cmd]() + [flag, value]), f"{flag} {value}"
    assert py == _strata.resolve(cmd, CLI_ARGS[cmd] + [flag, value])


@pytest.mark.parametrize("cmd", list(CALLS))
def test_python_adds_nothing_to_the_cli_call_but_quiet(cmd):
    assert CALLS[cmd]() == CLI_ARGS[cmd]
    assert _strata.resolve(cmd, CALLS[cmd]()) == _strata.resolve(cmd, CLI_ARGS[cmd])


def test_reference_is_the_clis_reference(tmp_path):
    """Same flags, same reference: the mean and the replicas' variance layer bit for bit, pixel
    sample 0 jittered on a .test scene (whose render default is the centre), and the EXR's
    metadata. Before, strata.reference was render(): centre sample, i.i.d. variance, no metadata."""
    cli("reference", SCENE, "--spp", 16, "--size", "24x16", "--threads", 2, "-q", "-o", tmp_path / "cli")
    exr = strata.read_exr(tmp_path / "cli.exr")
    img = strata.reference(SCENE, spp=16, size=(24, 16), threads=2, out=tmp_path / "py")
    assert np.array_equal(np.asarray(img), np.asarray(exr))
    assert np.array_equal(img.variance, exr.variance)
    assert img.stats["replicas"] == 8 and img.stats["variance_estimate"].startswith("replicas:")
    assert img.metadata["strata.variance"].startswith("replicas: variance of the mean across 8")
    assert img.metadata["strata.first_sample"] == "jittered" == exr.stats["strata.first_sample"]
    written = strata.read_exr(tmp_path / "py.exr")
    # Every attribute but the timings and the build hash (the binary and the module are two builds).
    differ = {"strata.render_seconds", "strata.cpu_seconds", "strata.build"}
    assert set(written.stats) == set(exr.stats) == set(img.metadata)
    for key, value in exr.stats.items():
        if key not in differ:
            assert written.stats[key] == value == img.metadata[key], key
    # Without out=, nothing is written and the image is the same.
    again = strata.reference(SCENE, spp=16, size=(24, 16), threads=2)
    assert np.array_equal(np.asarray(again), np.asarray(exr)) and np.array_equal(again.variance, exr.variance)
    # The CLI's refusals, with its messages.
    with pytest.raises(strata.StrataError, match="needs --spp N"):
        strata.reference(SCENE)


@pytest.mark.parametrize("keyword, flag", [("points", "--sampler"), ("pixel_points", "--pixel-sampler"),
                                           ("light_points", "--light-sampler")])
def test_point_array_options_default_as_files_do(tmp_path, keyword, flag):
    """``points_sampler``'s options (scramble, sets, pad, shuffle) default to a file's: an array
    renders as the same points in a file without options."""
    pts = np.random.default_rng(11).random((2, 32, 2))  # 8 spp x 4 light samples
    np.save(tmp_path / "p.npy", pts)
    cli("render", SCENE, "--spp", 8, "--size", "16x8", flag, f"file:{tmp_path / 'p.npy'}", "-q", "-o", tmp_path / "f")
    img = strata.render(SCENE, spp=8, size=(16, 8), **{keyword: pts})
    assert np.array_equal(np.asarray(img), np.asarray(strata.read_exr(tmp_path / "f.exr")))


def python_blocks(path):
    return re.findall(r"```python\n(.*?)```", path.read_text(), flags=re.S)


def test_python_md_examples_run_as_written(tmp_path):
    """Every ```python block of docs/PYTHON.md runs, in a folder beside ../shared as in a checkout."""
    blocks = python_blocks(ROOT / "docs" / "PYTHON.md")
    assert blocks, "no python examples in docs/PYTHON.md"
    work = tmp_path / "checkout"
    work.mkdir()
    (tmp_path / "shared").symlink_to(SHARED)
    for i, code in enumerate(blocks):
        r = subprocess.run([sys.executable, "-c", code], cwd=work, capture_output=True, text=True, timeout=600)
        assert r.returncode == 0, f"docs/PYTHON.md example {i + 1} failed:\n{code}\n{r.stderr}"


def test_a_python_compare_reproduces_with_the_python_call(tmp_path):
    """The report's "Reproduce" gives the Python call first (arrays by shape), then the CLI's
    equivalent; never `python script.py`."""
    cli("reference", SCENE, "--spp", 64, "--size", "16x8", "-q", "-o", tmp_path / "ref")
    pts = np.random.default_rng(3).random((4, 16, 2))
    strata.compare(SCENE, reference=tmp_path / "ref.exr", runs=2, spp_ladder=[1, 2], size=(16, 8), quiet=True,
                   variants={"mine": {"light_points": pts}, "sobol": "--light-sampler sobol"}, out=tmp_path / "cmp")
    page = html.unescape((tmp_path / "cmp" / "report.html").read_text())
    repro = page[page.index("<h2>Reproduce</h2>"):]
    repro = repro[:repro.index("</pre>")]
    lines = repro.split("\n")[1:]
    want = (f"strata.compare({str(SCENE)!r}, reference={str(tmp_path / 'ref.exr')!r}, "
            "variants={'mine': {'light_points': <array [4, 16, 2] float64>}, 'sobol': '--light-sampler sobol'}, "
            f"runs=2, spp_ladder=[1, 2], size=(16, 8), quiet=True, out={str(tmp_path / 'cmp')!r})")
    assert lines[0].split(">", 1)[-1] == want, lines
    assert lines[1].startswith("strata compare ") and lines[1].endswith("(the CLI's equivalent)"), lines
    assert "python " not in repro and ".py" not in repro, repro
