"""Collision filters from Python: groups and masks, self-exclusion rings and rest contacts give brute
force's pairs filtered here, with fewer candidates; bad values raise kdet.Error."""

from __future__ import annotations

import numpy as np
import pytest

import kdet


def soup(count: int, seed: int, extent: float = 3.0) -> kdet.TetMesh:
    """Random small tets in a cube, four vertices of their own each."""
    rng = np.random.default_rng(seed)
    centres = rng.uniform(0.0, extent, (count, 1, 3))
    vertices = (centres + rng.uniform(-0.2, 0.2, (count, 4, 3))).reshape(-1, 3)
    return kdet.TetMesh(vertices, np.arange(4 * count, dtype=np.uint32).reshape(-1, 4))


def crumpled_box(n: int, seed: int) -> kdet.TetMesh:
    """A box of n x n x n cubes (6 tets each) whose vertices are jittered so that near neighbours overlap."""
    idx = lambda i, j, k: (i * (n + 1) + j) * (n + 1) + k
    grid = np.stack(np.meshgrid(*[np.arange(n + 1)] * 3, indexing="ij"), -1).reshape(-1, 3).astype(float)
    cube = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 0), (0, 0, 1), (1, 0, 1), (0, 1, 1), (1, 1, 1)]
    split = [(0, 1, 3, 7), (0, 1, 5, 7), (0, 2, 3, 7), (0, 2, 6, 7), (0, 4, 5, 7), (0, 4, 6, 7)]
    tets = []
    for i in range(n):
        for j in range(n):
            for k in range(n):
                corner = [idx(i + a, j + b, k + c) for a, b, c in cube]
                tets += [[corner[v] for v in t] for t in split]
    rng = np.random.default_rng(seed)
    return kdet.TetMesh(grid + rng.uniform(-0.45, 0.45, grid.shape), np.asarray(tets, dtype=np.uint32))


def brute_force(meshes: list[kdet.TetMesh]) -> set[tuple[int, int, int, int]]:
    """Every colliding pair, each object against every other and itself."""
    detector = kdet.Detector(method="brute_force_loop")
    for mesh in meshes:
        detector.set_self_collision(detector.add_object(mesh), True)
    return {tuple(p) for p in detector.detect().pairs.tolist()}


def test_groups_and_masks_leave_out_pairs_inside_the_search():
    meshes = [soup(400, seed) for seed in range(4)]
    everything = brute_force(meshes)
    filters = [(1, 0xFFFFFFFE), (1, 0xFFFFFFFE), (2, 0xFFFFFFFF), (3, 2)]
    passes = lambda a, b: (filters[a][0] & filters[b][1]) != 0 and (filters[b][0] & filters[a][1]) != 0
    expected = sorted(p for p in everything if p[0] != p[2] and passes(p[0], p[2]))
    assert 0 < len(expected) < len(everything)
    plain, filtered = kdet.Detector(), kdet.Detector()
    for mesh in meshes:
        plain.add_object(mesh), filtered.add_object(mesh)
    for obj, (group, mask) in enumerate(filters):
        filtered.set_collision_filter(obj, group, mask)
    assert filtered.collision_filter(3) == (3, 2) and plain.collision_filter(0) == (1, 0xFFFFFFFF)
    result = filtered.detect()
    assert [tuple(p) for p in result.pairs.tolist()] == expected
    assert result.counts.candidates < plain.detect().counts.candidates
    # An explicit switch wins over the filters.
    filtered.set_pair_collision(0, 1, True)
    assert {tuple(p) for p in filtered.detect().pairs.tolist()} == set(expected) | {
        p for p in everything if p[:3:2] == (0, 1)
    }


def test_rings_and_rest_contacts_leave_out_pairs_of_one_object():
    box = crumpled_box(4, 1)
    detector = kdet.Detector()
    detector.set_self_collision(detector.add_object(box), True)
    everything = detector.detect()
    assert len(everything.pairs) > 10
    detector.set_self_exclusion_rings(0, 1)
    assert detector.self_exclusion_rings(0) == 1
    ringed = detector.detect()
    assert len(ringed.pairs) < len(everything.pairs) and ringed.counts.candidates < everything.counts.candidates
    assert {tuple(p) for p in ringed.pairs.tolist()} <= {tuple(p) for p in everything.pairs.tolist()}
    detector.set_self_exclusion_rings(0, 0)
    assert detector.exclude_rest_contacts(0) == len(everything.pairs)
    assert detector.detect().pairs.shape == (0, 4)
    # One half crumpled otherwise: the other half's contacts stay, the changed half has new ones.
    other = crumpled_box(4, 2).vertices
    later = kdet.TetMesh(np.where(other[:, :1] > 2.5, other, box.vertices), box.tets)
    detector.set_positions(0, later.vertices)
    now = brute_force([later])
    expected = sorted(now - {tuple(p) for p in everything.pairs.tolist()})
    assert 0 < len(expected) < len(now)
    assert [tuple(p) for p in detector.detect().pairs.tolist()] == expected


def test_bad_filter_values_raise_and_change_nothing():
    detector = kdet.Detector()
    detector.add_object(soup(50, 9))
    with pytest.raises(kdet.Error, match=r"^object 0: exclusion rings 5 out of range \[0, 4\]$"):
        detector.set_self_exclusion_rings(0, kdet.Detector.MAX_EXCLUSION_RINGS + 1)
    with pytest.raises(kdet.Error, match=r"^group -1 out of range \[0, 4294967295\]$"):
        detector.set_collision_filter(0, -1, 1)
    with pytest.raises(kdet.Error, match=r"^mask 4294967296 out of range"):
        detector.set_collision_filter(0, 1, 1 << 32)
    with pytest.raises(kdet.Error, match=r"^object id 2 out of range \(1 objects\)$"):
        detector.exclude_rest_contacts(0, 2)
    assert detector.collision_filter(0) == (1, 0xFFFFFFFF) and detector.self_exclusion_rings(0) == 0
