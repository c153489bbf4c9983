"""Static objects: Detector.set_static leaves out the pairs of two static objects and nothing else,
frame after frame, as objects turn static and move."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import kdet
from helpers import extent, moved


@pytest.fixture(scope="module")
def octopus(models: Path) -> kdet.TetMesh:
    return kdet.read_tet_mesh(models / "octopus-low.mesh")


def expected_pairs(meshes, static):
    """Brute force on every pair, then the pairs of two static objects removed."""
    detector = kdet.Detector(method="brute_force_loop")
    for mesh in meshes:
        detector.add_object(mesh)
    pairs = detector.detect().pairs
    keep = ~(np.asarray(static)[pairs[:, 0]] & np.asarray(static)[pairs[:, 2]])
    return pairs[keep]


def test_static_objects_keep_moving_pairs_only(octopus):
    step = 0.1 * extent(octopus)
    meshes = [moved(octopus, 0.2 * k, (step * k, 0.0, 0.0)) for k in range(3)]
    static = [True, True, False]
    detector = kdet.Detector()
    for mesh, is_static in zip(meshes, static):
        detector.set_static(detector.add_object(mesh), is_static)
    assert [detector.is_static(o) for o in range(3)] == static
    for frame in range(4):
        result = detector.detect()
        np.testing.assert_array_equal(result.pairs, expected_pairs(meshes, static))
        assert len(result.pairs) > 0
        # Move a static object by set_positions, then turn another one moving.
        meshes[frame % 3] = moved(meshes[frame % 3], 0.1, (0.5 * step, 0.0, 0.0))
        detector.set_positions(frame % 3, meshes[frame % 3].vertices)
        if frame == 1:
            static[0] = False
            detector.set_static(0, False)


def test_set_static_refuses_a_bad_object(octopus):
    detector = kdet.Detector()
    detector.add_object(octopus)
    with pytest.raises(kdet.Error, match="object id 2 out of range"):
        detector.set_static(2)
