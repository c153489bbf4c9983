"""Pairs within a margin: Detector(margin=..., distances=True), r.distances, r.closest_points and
kdet.collide(a, b, margin=...), against a pair built at a known distance and against `kdet collide`."""

from __future__ import annotations

import subprocess
from pathlib import Path

import numpy as np
import pytest

import kdet


def tet(points):
    return kdet.TetMesh(np.asarray(points, dtype=np.float64), np.arange(4, dtype=np.uint32).reshape(1, 4))


H = np.float32(0.1)
# a's face on z = 0, b's on z = H above it: the pair is H apart.
LOWER = tet([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0.25, 0.25, -1]])
UPPER = tet([[0.125, 0.125, H], [1.125, 0.125, H], [0.125, 1.125, H], [0.25, 0.25, H + 1]])


def test_a_pair_at_the_margin_is_reported_and_one_float_further_is_not():
    assert kdet.collide(LOWER, UPPER, margin=float(H)).tolist() == [[0, 0]]
    assert kdet.collide(LOWER, UPPER, margin=float(np.nextafter(H, np.float32(0)))).shape == (0, 2)
    assert kdet.collide(LOWER, UPPER).shape == (0, 2)


def test_distances_and_closest_points():
    detector = kdet.Detector(margin=0.5, distances=True)
    detector.add_object(LOWER)
    detector.add_object(UPPER)
    r = detector.detect()
    assert r.pairs.tolist() == [[0, 0, 1, 0]]
    assert r.distances.shape == (1,) and r.distances.dtype == np.float32
    assert r.closest_points.shape == (1, 2, 3) and r.closest_points.dtype == np.float32
    assert r.distances[0] == pytest.approx(float(H), rel=1e-6)
    on_a, on_b = r.closest_points[0]
    assert on_a[2] == pytest.approx(0.0, abs=1e-6) and on_b[2] == pytest.approx(float(H), rel=1e-6)
    assert np.linalg.norm(on_b - on_a) == pytest.approx(float(H), rel=1e-6)
    assert detector.options["margin"] == 0.5 and detector.options["distances"] is True
    plain = kdet.Detector()
    plain.add_object(LOWER)
    assert plain.detect().distances is None and plain.detect().closest_points is None


def test_a_refused_margin_raises_the_librarys_message():
    for bad in (-1.0, float("nan"), float("inf")):
        with pytest.raises(kdet.Error, match="^margin: expected a finite number >= 0"):
            kdet.collide(LOWER, UPPER, margin=bad)
    with pytest.raises(TypeError, match="^margin: expected a float"):
        kdet.Detector(margin="0.1")


def test_pairs_and_distances_are_the_commands(models: Path, cli: Path, tmp_path: Path):
    mesh = kdet.read_tet_mesh(models / "octopus-low.mesh")
    margin = 0.05
    detector = kdet.Detector(margin=margin, distances=True)
    detector.set_self_collision(detector.add_object(mesh), True)
    r = detector.detect()
    assert len(r.pairs) > len(kdet.collide_self(mesh))
    assert np.all(r.distances <= np.float32(margin) * (1 + 1e-6))
    pairs_file, distances_file = tmp_path / "pairs.txt", tmp_path / "distances.txt"
    run = subprocess.run([str(cli), "collide", str(models / "octopus-low.mesh"), "--self", "--margin", str(margin),
                          "--pairs", str(pairs_file), "--distances", str(distances_file)], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    assert np.array_equal(np.loadtxt(pairs_file, dtype=np.uint32, ndmin=2), r.pairs[:, [1, 3]])
    lines = np.loadtxt(distances_file, ndmin=2)
    assert np.allclose(lines[:, 2], r.distances, rtol=1e-6, atol=0)
    assert np.allclose(lines[:, 3:].reshape(-1, 2, 3), r.closest_points, rtol=1e-6, atol=1e-7)
    assert np.array_equal(kdet.collide_self(mesh, margin=margin), r.pairs[:, [1, 3]])
