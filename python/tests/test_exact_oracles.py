"""The exact oracles of exact_oracles.py on configurations whose answers are known, and against dense
sampling (a sampled distance is never below the exact one, and comes close to it)."""

from __future__ import annotations

from fractions import Fraction

import numpy as np

import exact_oracles as oracle

UNIT = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)]


def shifted(points, shift):
    return [tuple(c + s for c, s in zip(p, shift)) for p in points]


def test_parallel_faces_vertex_face_and_edge_edge():
    # a's face z = 0 above b's face z = -2: parallel faces 2 apart.
    below = [(0, 0, -2), (4, 0, -2), (0, 4, -2), (1, 1, -6)]
    assert oracle.tet_tet_d2(UNIT, below) == 4
    # A vertex 3 above the middle of a face (the plane x + y + z = 1 at distance 3 along its normal):
    # the squared distance is 9 for a vertex at the face's centroid + 3 n / |n|, here with rational n.
    apex = [(5, 5, 5), (9, 5, 5), (5, 9, 5), (5, 5, 9)]
    assert oracle.tet_tet_d2(UNIT, apex) == Fraction(3 * (5 - Fraction(1, 3)) ** 2)
    # Skew edges: a's edge from (0,0,0) to (1,0,0) and b's from (1/2,-1,-5) to (1/2,1,-5): 5 apart.
    skew = [(Fraction(1, 2), -1, -5), (Fraction(1, 2), 1, -5), (Fraction(1, 2), 0, -9), (3, 0, -9)]
    assert oracle.segment_segment_d2(UNIT[0], UNIT[1], skew[0], skew[1]) == 25
    assert oracle.tet_tet_d2(UNIT, skew) == 25


def test_intersecting_touching_and_nested_tets_are_at_distance_zero():
    assert oracle.tet_tet_d2(UNIT, shifted(UNIT, (Fraction(1, 4), 0, 0))) == 0  # overlapping
    assert oracle.tet_tet_d2(UNIT, shifted(UNIT, (1, 0, 0))) == 0  # touching at a vertex
    inner = [tuple(Fraction(c, 10) + Fraction(1, 10) for c in p) for p in UNIT]
    assert oracle.tet_tet_d2(UNIT, inner) == 0 and oracle.tet_tet_d2(inner, UNIT) == 0  # nested
    # A needle whose vertices all lie outside, one edge through the tet's interior.
    needle = [(-10, Fraction(1, 10), Fraction(1, 10)), (10, Fraction(1, 10), Fraction(1, 10)),
              (10, Fraction(2, 10), Fraction(1, 10)), (10, Fraction(1, 10), Fraction(2, 10))]
    assert not any(oracle.holds(UNIT, v) for v in needle)
    assert oracle.tet_tet_d2(UNIT, needle) == 0
    assert oracle.tet_tet_d2(UNIT, shifted(needle, (0, 0, 1))) > 0


def test_tets_without_volume():
    point = [(2, 0, 0)] * 4
    assert oracle.tet_tet_d2(UNIT, point) == 1
    flat = [(-1, -1, Fraction(1, 2)), (3, -1, Fraction(1, 2)), (-1, 3, Fraction(1, 2)), (3, 3, Fraction(1, 2))]
    assert oracle.holds(flat, (0, 0, 0)) is None
    assert oracle.tet_tet_d2(UNIT, flat) == 0  # the square cuts the tet
    assert oracle.tet_tet_d2(UNIT, shifted(flat, (0, 0, 1))) == Fraction(1, 4)  # 1/2 above its apex
    segment = [(Fraction(1, 4), Fraction(1, 4), -1)] * 3 + [(Fraction(1, 4), Fraction(1, 4), 3)]
    assert oracle.tet_tet_d2(UNIT, segment) == 0  # through the tet, ends outside
    assert oracle.point_tet_d2(flat, (1, 1, 1)) == Fraction(1, 4)
    assert oracle.point_tet_d2(flat, (1, 1, Fraction(1, 2))) == 0


def test_point_location():
    for p, d2 in [((0, 0, 0), 0), ((Fraction(1, 4), Fraction(1, 4), Fraction(1, 4)), 0), ((Fraction(1, 2), Fraction(1, 2), 0), 0),
                  ((-1, 0, 0), 1), ((1, 1, 1), Fraction(4, 3)), ((-1, -1, -1), 3)]:
        assert oracle.point_tet_d2(UNIT, p) == d2
        assert oracle.holds(UNIT, p) == (d2 == 0)


def test_exact_maps_floats_to_integers_over_one_power_of_two():
    exact = oracle.Exact(np.array([0.5, 3.0, 1e-30]), np.array([1e7]))
    for x in (0.5, 3.0, 1e-30, 1e7, 0.0, -0.5):
        assert Fraction(exact.number(x), exact.scale) == Fraction(x)


def samples(tet, k=10):
    """Points of the closed tet on a barycentric grid of step 1/k."""
    w = np.array([(i, j, m, k - i - j - m) for i in range(k + 1) for j in range(k + 1 - i) for m in range(k + 1 - i - j)]) / k
    return w @ np.asarray(tet, dtype=np.float64)


def test_random_pairs_against_dense_sampling():
    rng = np.random.default_rng(48)
    for _ in range(30):
        s = rng.integers(-6, 7, (4, 3)).tolist()
        t = (rng.integers(-6, 7, (4, 3)) + rng.integers(-3, 4, 3) * 4).tolist()
        if rng.random() < 0.25:
            t[3] = t[2]  # a tet without volume
        s, t = [tuple(p) for p in s], [tuple(p) for p in t]
        exact = float(oracle.tet_tet_d2(s, t)) ** 0.5
        a, b = samples(s), samples(t)
        sampled = np.sqrt(((a[:, None, :] - b[None, :, :]) ** 2).sum(axis=-1).min())
        size = np.ptp(np.vstack([s, t]), axis=0).max()
        assert exact <= sampled + 1e-9
        assert sampled <= exact + 0.25 * size  # the grid's spacing bounds how far it stays
