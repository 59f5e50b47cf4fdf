"""Three ways to bring a point set, compared against Sobol' at equal time on the hw2 sphere:
a UTK text file (written by hand here, as UTK would write one), a NumPy .npy file, and a numpy
array passed directly. All serve the light samples (``--light-sampler``).

    python examples/python/point_sets_at_equal_time.py [--small] [--out DIR]

Writes DIR/hand.txt, DIR/lattice.npy, DIR/ref.exr and the compare outputs in DIR/compare/
(rows.csv, rows.json, table.md, error.svg), and prints the rows.
"""

import argparse
from pathlib import Path

import numpy as np

import strata

ROOT = Path(__file__).resolve().parents[2]
SPHERE = ROOT.parent / "shared" / "cse168" / "hw2" / "sphere.test"

# 4 sets of 16 points, in UTK's text format: one point per line, sets separated by '#'.
# Each set is a 4 x 4 jittered grid, jitters written out by hand.
HAND = "\n#\n".join(
    "\n".join(f"{(i % 4 + j) / 4:.4f} {(i // 4 + k) / 4:.4f}" for i, (j, k) in enumerate(jit))
    for jit in [
        [(0.5, 0.5)] * 16,
        [(0.1, 0.9), (0.3, 0.2), (0.8, 0.6), (0.5, 0.4)] * 4,
        [(0.7, 0.3), (0.2, 0.8), (0.4, 0.1), (0.9, 0.5)] * 4,
        [(0.25, 0.75), (0.6, 0.35), (0.15, 0.45), (0.85, 0.05)] * 4,
    ]
) + "\n"


def fibonacci_lattice(n_fib=12):
    """The Fibonacci lattice of F_k points: (i / F_k, frac(i F_{k-1} / F_k))."""
    f = [1, 1]
    while len(f) < n_fib:
        f.append(f[-1] + f[-2])
    n, g = f[-1], f[-2]
    i = np.arange(n)
    return np.stack([i / n, (i * g % n) / n], axis=1)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--small", action="store_true", help="a small, fast version (the test suite runs it)")
    ap.add_argument("--out", default="point_sets_at_equal_time", help="output folder")
    a = ap.parse_args()
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    size, ref_spp, budget, runs = ((64, 48), 512, 0.3, 2) if a.small else ((320, 240), 4096, 4.0, 4)
    (out / "hand.txt").write_text(HAND)
    np.save(out / "lattice.npy", fibonacci_lattice()[None])  # one set of 144 points
    array = np.random.default_rng(24).random((8, 64, 2))  # stand-in for your own generator
    strata.reference(SPHERE, spp=ref_spp, size=size, light_sampler="sobol", out=out / "ref")
    common = "--light-samples 4"
    rows = strata.compare(
        SPHERE,
        reference=out / "ref.exr",
        variants={
            "utk-text": f"{common} --light-sampler file:{out / 'hand.txt'}",
            "npy": f"{common} --light-sampler file:{out / 'lattice.npy'}",
            "array": {"light_samples": 4, "light_points": array},
            "sobol": f"{common} --light-sampler sobol",
        },
        budget=budget,
        runs=runs,
        size=size,
        out=out / "compare",
    )
    print(rows)


if __name__ == "__main__":
    main()
