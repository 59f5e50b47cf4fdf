"""Your own point sets inside a real render, from numpy: a rank-1 lattice and a jittered set
against strata's Owen-scrambled Sobol' on the CSE168 hw2 sphere, RMSE against time.

    python examples/python/compare_point_sets.py [--small] [--out DIR]

Each set serves every sampler dimension (``points=``: pixel jitter and light samples, one light
sample per light and pixel sample, so a set of N points serves N spp), randomized per pixel and
dimension by a Cranley-Patterson shift, with the point index shuffled per dimension (both
strata's defaults for point arrays: without the shuffle, ``shuffle="none"``, the pixel and the
light dimension of a sample take the same point, and the lattice becomes a correlated 4D
pattern). Neither set is progressive (a lattice's or a row-ordered jittered set's prefixes are
no sets of their own), so each is made at the spp it serves and used whole. Writes
DIR/rmse_vs_time.png and DIR/results.json.
"""

import argparse
import json
from pathlib import Path

import numpy as np

import strata

ROOT = Path(__file__).resolve().parents[2]
SPHERE = ROOT.parent / "shared" / "cse168" / "hw2" / "sphere.test"


def rank1_lattice(n):
    """The Korobov lattice {(i/n, frac(i g/n))} whose generator g maximizes the minimum
    toroidal distance (searched over every g coprime to n)."""
    i = np.arange(n)
    best, best_d = 1, -1.0
    for g in range(1, n):
        if np.gcd(g, n) != 1:
            continue
        p = np.stack([i / n, (i * g % n) / n], axis=1)
        d = np.abs(p[1:] - p[0])  # a lattice: distances from point 0 are all the distances
        d = np.minimum(d, 1 - d)
        m = np.sqrt((d**2).sum(axis=1)).min()
        if m > best_d:
            best, best_d = g, m
    return np.stack([i / n, (i * best % n) / n], axis=1)


def jittered(n, rng, sets=16):
    """`sets` jittered sets of n points on an nx x ny grid (nx ny = n, as square as n allows)."""
    nx = 1 << (int(np.log2(n)) // 2)
    ny = n // nx
    cx, cy = np.meshgrid(np.arange(nx), np.arange(ny), indexing="xy")
    cells = np.stack([cx.ravel() / nx, cy.ravel() / ny], axis=1)
    return cells[None] + rng.random((sets, n, 2)) / np.array([nx, ny])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--small", action="store_true", help="a small, fast version (the test suite runs it)")
    ap.add_argument("--out", default="compare_point_sets", help="output folder")
    a = ap.parse_args()
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    size, spps, ref_spp = ((80, 60), [16, 32, 64], 1024) if a.small else ((640, 480), [16, 32, 64, 128, 256], 8192)
    common = dict(size=size, light_samples=1, threads=0)
    ref = strata.render(SPHERE, spp=ref_spp, sampler="sobol", seed=99, **common)
    rng = np.random.default_rng(2018)
    rows = []
    for spp in spps:
        samplers = {
            "rank1": dict(points=rank1_lattice(spp)),
            "jittered": dict(points=jittered(spp, rng)),
            "sobol": dict(sampler="sobol"),
        }
        for name, flags in samplers.items():
            img = strata.render(SPHERE, spp=spp, seed=1, **common, **flags)
            rows.append(
                dict(sampler=name, spp=spp, seconds=img.stats["cpu_seconds"], rmse=strata.metrics.rmse(img, ref))
            )
            print(f"{name:>9} {spp:>4} spp: RMSE {rows[-1]['rmse']:.5f} in {rows[-1]['seconds']:.2f} CPU s")
    (out / "results.json").write_text(json.dumps(rows, indent=1))

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4))
    for name in ("rank1", "jittered", "sobol"):
        pts = [(r["seconds"], r["rmse"]) for r in rows if r["sampler"] == name]
        ax.loglog(*zip(*pts), marker="o", label=name)
    ax.set_xlabel("CPU seconds (worker threads)")
    ax.set_ylabel("RMSE")
    ax.set_title(f"hw2 sphere {size[0]}x{size[1]}, {spps[0]}-{spps[-1]} spp")
    ax.legend()
    fig.tight_layout()
    fig.savefig(out / "rmse_vs_time.png", dpi=120)
    print(f"written to {out}/ (rmse_vs_time.png, results.json)")


if __name__ == "__main__":
    main()
