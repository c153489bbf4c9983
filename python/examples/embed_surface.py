#!/usr/bin/env python3
"""Embeds a surface's vertices in a tet mesh (each vertex: a tet that holds it and its barycentric
coordinates there), deforms the tet mesh, and carries the surface along: each vertex moves to the same
barycentric combination of its tet's moved vertices, as a simulation's visual mesh follows its cage.

usage: python3 embed_surface.py [TETS] [SURFACE] [--within D]   (SURFACE: .obj, .off, .stl or .ply)
       (default: bunny.mesh and bunny.off from $KDET_DATA_DIR, else ../shared/models)

A vertex that no tet holds (outside the tet mesh) takes the nearest tet within D, with the barycentric
coordinates of its closest point there. The deformation here is affine, under which a barycentric
combination moves exactly as its point: the printed error is rounding only.
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path

import numpy as np

import kdet


def default_model(name: str) -> Path:
    return Path(os.environ.get("KDET_DATA_DIR", "../shared/models")) / name


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("tets", nargs="?", type=Path, default=default_model("bunny.mesh"))
    parser.add_argument("surface", nargs="?", type=Path, default=default_model("bunny.off"))
    parser.add_argument("--within", type=float, default=1e-3)
    args = parser.parse_args()

    mesh = kdet.read_tet_mesh(args.tets)
    points, _ = kdet.read_surface(args.surface)  # any of .obj, .off, .stl, .ply
    located = kdet.locate(mesh, points, within=args.within)

    # One tet per point: the first of its hits (a point on a shared face, edge or vertex has several,
    # all giving the same point back).
    counts = np.diff(located.offsets.astype(np.int64))
    embedded = counts > 0
    first = located.offsets[:-1][embedded].astype(np.int64)
    tets = mesh.tets[located.tets[first]]
    weights = located.barycentrics[first]
    outside = int(np.sum(located.distances[first] > 0))
    print(f"{int(embedded.sum())} of {len(points)} surface points embedded in {len(mesh.tets)} tets "
          f"({int(np.sum(counts > 1))} on faces, edges or vertices shared by several tets, "
          f"{outside} outside within {args.within:g}), {len(points) - int(embedded.sum())} left out")

    # An affine deformation of the tet mesh: a shear and a stretch.
    matrix = np.array([[1.2, 0.3, 0.0], [0.0, 0.9, 0.1], [0.1, 0.0, 1.1]])
    shift = np.array([0.5, -0.2, 0.1])
    moved_vertices = mesh.vertices @ matrix.T + shift
    carried = np.einsum("pk,pkd->pd", weights, moved_vertices[tets])
    # The closest points (the points themselves when a tet holds them) under the same map.
    expected = located.closest_points[first] @ matrix.T + shift
    error = float(np.max(np.abs(carried - expected))) if len(carried) else 0.0
    print(f"carried through the deformation: largest deviation from the mapped point {error:.3g}")


if __name__ == "__main__":
    main()
