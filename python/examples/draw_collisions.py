#!/usr/bin/env python3
"""Finds where mesh B, shifted into mesh A, collides with it, and draws the colliding tets: with
polyscope in a window when it is installed (and --window is given), else with matplotlib into a PNG.

usage: python3 draw_collisions.py [A] [B] [--shift DX DY DZ] [--out collisions.png] [--window]
       (default A and B: octopus-low.mesh from $KDET_DATA_DIR, else ../shared/models; the default
       shift moves B by a tenth of A's size along x)
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path

import numpy as np

import kdet

# The four triangles of a tet, as corner numbers.
FACES = np.array([[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]])


def default_model(name: str) -> Path:
    return Path(os.environ.get("KDET_DATA_DIR", "../shared/models")) / name


def colliding_triangles(mesh: kdet.TetMesh, flags: np.ndarray) -> np.ndarray:
    """(t, 3, 3): the corners of every face of the flagged tets."""
    return mesh.vertices[mesh.tets[flags][:, FACES]].reshape(-1, 3, 3)


def draw_matplotlib(meshes, flags, out: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    figure = plt.figure(figsize=(7, 6))
    axes = figure.add_subplot(projection="3d")
    for mesh, flag, colour in zip(meshes, flags, ("tab:blue", "tab:orange")):
        sample = mesh.vertices[:: max(1, mesh.num_vertices // 2000)]
        axes.scatter(*sample.T, s=2, color=colour, alpha=0.3)
        axes.add_collection3d(Poly3DCollection(colliding_triangles(mesh, flag), facecolor=colour, edgecolor="k",
                                               linewidths=0.1, alpha=0.6))
    everything = np.vstack([m.vertices for m in meshes])
    low, high = everything.min(axis=0), everything.max(axis=0)
    centre, half = (low + high) / 2, (high - low).max() / 2
    for setter, c in zip((axes.set_xlim, axes.set_ylim, axes.set_zlim), centre):
        setter(c - half, c + half)
    axes.set_title(f"{int(flags[0].sum())} + {int(flags[1].sum())} colliding tets")
    figure.savefig(out, dpi=120)
    print(f"wrote {out}")


def draw_polyscope(meshes, flags) -> None:
    import polyscope

    polyscope.init()
    for name, mesh, flag in zip(("A", "B"), meshes, flags):
        volume = polyscope.register_volume_mesh(name, mesh.vertices, tets=mesh.tets)
        volume.add_scalar_quantity("colliding", flag.astype(float), defined_on="cells", enabled=True)
    polyscope.show()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("a", nargs="?", type=Path, default=default_model("octopus-low.mesh"))
    parser.add_argument("b", nargs="?", type=Path, default=default_model("octopus-low.mesh"))
    parser.add_argument("--shift", nargs=3, type=float, metavar=("DX", "DY", "DZ"))
    parser.add_argument("--out", type=Path, default=Path("collisions.png"))
    parser.add_argument("--window", action="store_true", help="show the meshes with polyscope")
    args = parser.parse_args()

    a, b = kdet.read_tet_mesh(args.a), kdet.read_tet_mesh(args.b)
    shift = args.shift if args.shift else [0.1 * np.ptp(a.vertices, axis=0).max(), 0.0, 0.0]
    b = kdet.TetMesh(b.vertices + shift, b.tets)
    detector = kdet.Detector()
    detector.add_object(a)
    detector.add_object(b)
    result = detector.detect()
    print(f"{len(result.pairs)} colliding pairs")
    if args.window:
        draw_polyscope((a, b), result.colliding)
    else:
        draw_matplotlib((a, b), result.colliding, args.out)


if __name__ == "__main__":
    main()
