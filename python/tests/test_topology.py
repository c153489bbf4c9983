"""Topology that changes, from Python: removals, splits, remeshing and re-adds, each frame equal to
brute force on the meshes as they are now; a removed id raises kdet.Error."""

from __future__ import annotations

import numpy as np
import pytest

import kdet
from test_filters import crumpled_box, soup


def oracle(meshes: dict[int, kdet.TetMesh]) -> list[tuple[int, int, int, int]]:
    """Brute force on the live meshes (each self-colliding), under the tested detector's ids."""
    detector = kdet.Detector(method="brute_force_loop")
    ids = sorted(meshes)
    for obj in ids:
        detector.set_self_collision(detector.add_object(meshes[obj]), True)
    return [(ids[a], i, ids[b], j) for a, i, b, j in detector.detect().pairs.tolist()]


def test_random_changes_match_brute_force_every_frame():
    rng = np.random.default_rng(5)
    detector = kdet.Detector(initial_candidate_capacity=1)
    meshes: dict[int, kdet.TetMesh] = {}

    def add(mesh):
        obj = detector.add_object(mesh)
        detector.set_self_collision(obj, True)
        meshes[obj] = mesh

    for seed in range(3):
        add(soup(200, seed, 2.0))
    for step in range(12):
        obj = int(rng.choice(sorted(meshes)))
        mesh = meshes[obj]
        change = step % 4
        if change == 0 and len(meshes) > 1:
            detector.remove_object(obj)
            del meshes[obj]
        elif change == 1:  # split: two thirds stay, the rest becomes an object of its own
            order = rng.permutation(mesh.num_tets)
            kept, broken = mesh.tets[order[: 2 * len(order) // 3]], mesh.tets[order[2 * len(order) // 3 :]]
            detector.set_tets(obj, kept)
            meshes[obj] = kdet.TetMesh(mesh.vertices, kept)
            add(kdet.TetMesh(mesh.vertices, broken))
        elif change == 2:
            box = crumpled_box(3, step)
            fitted = kdet.TetMesh(box.vertices * 0.6, box.tets)
            detector.set_tets(obj, fitted.tets, fitted.vertices)
            meshes[obj] = fitted
        else:
            add(soup(150, 100 + step, 2.0))
        result = detector.detect()
        assert [tuple(p) for p in result.pairs.tolist()] == oracle(meshes), f"step {step}"
        for o in range(detector.object_count):
            assert len(result.colliding[o]) == (meshes[o].num_tets if o in meshes else 0)


def test_a_removed_id_raises_and_bad_tets_change_nothing():
    detector = kdet.Detector()
    mesh = soup(60, 3, 1.0)
    detector.set_self_collision(detector.add_object(mesh), True)
    detector.add_object(mesh)
    before = detector.detect().pairs
    detector.remove_object(1)
    assert detector.contains(0) and not detector.contains(1) and detector.object_count == 2
    for call in (
        lambda: detector.set_positions(1, mesh.vertices),
        lambda: detector.set_tets(1, mesh.tets),
        lambda: detector.remove_object(1),
        lambda: detector.set_collision_filter(1, 1, 1),
        lambda: detector.tet_count(1),
    ):
        with pytest.raises(kdet.Error, match=r"^object id 1 was removed$"):
            call()
    bad = mesh.tets.copy()
    bad[3, 2] = mesh.num_vertices
    with pytest.raises(kdet.Error, match=r"^object 0: tet 3 has vertex index 240 out of range \[0, 240\)$"):
        detector.set_tets(0, bad)
    assert detector.tet_count(0) == mesh.num_tets
    np.testing.assert_array_equal(detector.detect().pairs, before[(before[:, 0] == 0) & (before[:, 2] == 0)])
