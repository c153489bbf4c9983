"""Meshes and reference pairs for the tests."""

from __future__ import annotations

import subprocess
from pathlib import Path

import numpy as np

import kdet


def cli_pairs(cli: Path, tmp_path: Path, meshes: list[Path], *flags: str) -> np.ndarray:
    """The (k, 2) pairs of `kdet collide MESHES FLAGS --pairs FILE`."""
    out = tmp_path / "cli_pairs.txt"
    subprocess.run([str(cli), "collide", *map(str, meshes), *flags, "--pairs", str(out)], check=True, capture_output=True)
    pairs = np.loadtxt(out, dtype=np.uint32, ndmin=2)
    return pairs.reshape(-1, 2)


def moved(mesh: kdet.TetMesh, angle: float, shift: tuple[float, float, float]) -> kdet.TetMesh:
    """The mesh turned by `angle` about z around its centre, then shifted."""
    v = mesh.vertices
    centre = v.mean(axis=0)
    c, s = np.cos(angle), np.sin(angle)
    turn = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    return kdet.TetMesh((v - centre) @ turn.T + centre + np.asarray(shift), mesh.tets)


def extent(mesh: kdet.TetMesh) -> float:
    return float(np.ptp(mesh.vertices, axis=0).max())


def union(a: kdet.TetMesh, b: kdet.TetMesh) -> kdet.TetMesh:
    """One mesh holding both: its self-collisions include every pair between a and b."""
    return kdet.TetMesh(np.vstack([a.vertices, b.vertices]), np.vstack([a.tets, b.tets + a.num_vertices]))
