"""Property-based tests (Hypothesis) of pairs within a margin, their distances and closest points, and
point location, against the exact rational oracles of exact_oracles.py: the soups, options, scales and
offsets of test_properties.py, margins drawn at random and margins one float either side of a pair's
own distance, parallel faces and edges built at a float distance, and query points on the tets'
vertices, edges and faces, just outside them and anywhere. Derandomized and bounded as there; failing
examples that Hypothesis found are kept below as plain tests.
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

import kdet  # noqa: E402
import exact_oracles as oracle  # noqa: E402
from test_properties import PROPERTY, soups, with_vertices  # noqa: E402

# The oracle is Python rationals: fewer examples than the other properties keep each to a few seconds.
EXACT = settings(PROPERTY, max_examples=25)

F32 = np.float32


def transformed(mesh, decade, offset):
    """The mesh scaled by 10^decade and shifted by offset (scaled as well when decade < 0, so that the
    tets stay apart from rounding), in float32."""
    return with_vertices(mesh, mesh.vertices * 10.0**decade + np.asarray(offset) * 10.0**min(decade, 0.0))


def margin_detect(meshes, margin, method="brute_force_pairs", test="exact", hash="djb2", threads=1,
                  self_collision=(), distances=False):
    detector = kdet.Detector(method=method, test=test, hash=hash, threads=threads, margin=float(clipped(margin)),
                             distances=distances)
    ids = [detector.add_object(m) for m in meshes]
    for k in self_collision:
        detector.set_self_collision(ids[k], True)
    return detector.detect()


def pairs_of(r):
    return {tuple(map(int, p)) for p in r.pairs}


def assert_pairs(method, r, meshes, expected):
    """The result's pairs (pair methods) or flags (the others) are those of the expected pair set."""
    if method in ("kdet", "brute_force_pairs"):
        assert pairs_of(r) == expected
    flags = [np.zeros(len(mesh.tets), bool) for mesh in meshes]
    for oa, ta, ob, tb in expected:
        flags[oa][ta] = flags[ob][tb] = True
    for got, want in zip(r.colliding, flags):
        np.testing.assert_array_equal(np.asarray(got), want)


options = st.fixed_dictionaries({
    "method": st.sampled_from(kdet.METHODS),
    "hash": st.sampled_from(kdet.HASHES),
    "threads": st.sampled_from([1, 2]),
})
# 1e39 stands for the largest float (every margin is clipped to it): with large coordinates, sizes grown
# by it once overflowed.
margins = st.one_of(st.sampled_from([0.0, 0.25, 0.5, 1.0, 1e39]), st.floats(0.0, 3.0, width=32))
LARGEST = float(np.finfo(np.float32).max)


def clipped(margin) -> np.float32:
    return F32(min(float(margin), LARGEST))
# Up to 10^37.5: soups 2 wide reach 6e37, and margins up to 3 times that stop at the largest float.
scales = st.tuples(st.floats(-30, 37.5), st.tuples(*[st.floats(-1e7, 1e7)] * 3))


def at_scale(meshes, margin, scale):
    decade, offset = scale
    return [transformed(m, decade, offset) for m in meshes], clipped(margin * 10.0**decade)


@EXACT
@given(a=soups(), b=soups(), margin=margins, chosen=options, self_a=st.booleans(), scale=scales)
def test_margin_pairs_are_the_exact_oracles(a, b, margin, chosen, self_a, scale):
    meshes, margin = at_scale([a, b], margin, scale)
    selves = [0] if self_a else []
    expected = oracle.pairs_within(meshes, margin, selves)
    assert_pairs(chosen["method"], margin_detect(meshes, margin, self_collision=selves, **chosen), meshes, expected)


def least_float_at_least(d2: Fraction) -> np.float32:
    """The least float32 m with m^2 >= d2 (exactly): the smallest margin that holds a pair d apart."""
    m = F32(math.sqrt(float(d2)))
    while Fraction(float(m)) ** 2 < d2:
        m = np.nextafter(m, F32(np.inf))
    while m > 0 and Fraction(float(np.nextafter(m, F32(0)))) ** 2 >= d2:
        m = np.nextafter(m, F32(0))
    return m


@EXACT
@given(a=soups(max_tets=4), b=soups(max_tets=4), chosen=options, scale=scales)
def test_margins_one_float_either_side_of_a_pairs_distance(a, b, chosen, scale):
    """At the least float margin that holds the first pair it is reported, one float below it is not;
    every other pair follows the oracle at both margins."""
    meshes, _ = at_scale([a, b], 0.0, scale)
    exact = oracle.Exact(*(oracle.float32(m.vertices) for m in meshes))
    d2 = exact.real(oracle.tet_tet_d2(oracle.tets_of(meshes[0], exact)[0], oracle.tets_of(meshes[1], exact)[0]))
    hypothesis.assume(d2 > 0)
    at = least_float_at_least(d2)
    hypothesis.assume(np.isfinite(at))
    for margin, inside in ((at, True), (np.nextafter(at, F32(0)), False)):
        expected = oracle.pairs_within(meshes, margin)
        assert ((0, 0, 1, 0) in expected) == inside
        assert_pairs(chosen["method"], margin_detect(meshes, margin, **chosen), meshes, expected)


@st.composite
def parallel_pairs(draw):
    """Two tets a float h apart by construction, every coordinate exact in float32: parallel faces (b's
    face on z = h above a's on z = 0) or crossing edges (b's edge over a's, turned a quarter), at a power
    of two scale, with a shared offset that keeps the coordinates exact."""
    h = draw(st.floats(2.0**-10, 2.0, width=32))
    exponent = draw(st.integers(-90, 90))
    shift = draw(st.sampled_from([0.0, 1024.0, -4096.0]))
    if draw(st.booleans()):
        a = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0.25, 0.25, -1]]
        b = [[0.125, 0.125, h], [1.125, 0.125, h], [0.125, 1.125, h], [0.25, 0.25, h + 1]]
    else:
        a = [[-1, 0, 0], [1, 0, 0], [0, 0.5, -1], [0, -0.5, -1]]
        b = [[0, -1, h], [0, 1, h], [0.5, 0, h + 1], [-0.5, 0, h + 1]]
    scale = 2.0**exponent
    tets = np.arange(4, dtype=np.uint32).reshape(1, 4)
    meshes = [kdet.TetMesh((np.asarray(p, np.float64) + shift) * scale, tets) for p in (a, b)]
    hypothesis.assume(all(np.array_equal(oracle.float32(m.vertices), m.vertices) for m in meshes))
    return meshes, F32(h * scale)


@EXACT
@given(built=parallel_pairs(), chosen=options, side=st.sampled_from([-1, 0, 1]))
def test_parallel_faces_and_edges_at_their_float_distance(built, chosen, side):
    meshes, h = built
    margin = {-1: np.nextafter(h, F32(0)), 0: h, 1: np.nextafter(h, F32(np.inf))}[side]
    expected = oracle.pairs_within(meshes, margin)
    assert expected == ({(0, 0, 1, 0)} if side >= 0 else set())
    assert_pairs(chosen["method"], margin_detect(meshes, margin, **chosen), meshes, expected)


@EXACT
@given(a=soups(), b=soups(), margin=margins, test=st.sampled_from(kdet.TESTS), hash=st.sampled_from(kdet.HASHES),
       threads=st.sampled_from([1, 2]))
def test_every_test_with_a_margin_gives_brute_force_pairs(a, b, margin, test, hash, threads):
    # A float test decides what intersects, the margin's exact decision the rest: the grid changes nothing
    # of either (zero-volume tets are left to the exact test, as in test_properties.py).
    reference = margin_detect([a, b], margin, test=test, self_collision=[0])
    got = margin_detect([a, b], margin, method="kdet", test=test, hash=hash, threads=threads, self_collision=[0])
    assert pairs_of(got) == pairs_of(reference)


filter_calls = st.lists(
    st.one_of(
        st.tuples(st.just("set_collision_filter"), st.integers(0, 2), st.integers(0, 3), st.integers(0, 3)),
        st.tuples(st.just("set_pair_collision"), st.integers(0, 2), st.integers(0, 2), st.booleans()),
        st.tuples(st.just("set_self_collision"), st.integers(0, 2), st.booleans()),
        st.tuples(st.just("set_static"), st.integers(0, 2), st.booleans()),
    ),
    max_size=6,
)


@EXACT
@given(meshes=st.lists(soups(max_tets=6), min_size=3, max_size=3), calls=filter_calls, margin=margins, chosen=options)
def test_filters_with_a_margin_give_the_oracles_pairs_that_they_pass(meshes, calls, margin, chosen):
    """Collision filters, pair and self switches and static objects with a margin: the pairs are the
    exact oracle's within the margin that a brute-force detector at margin 0 would let through, i.e.
    that of brute force with the same calls (whose own pairs are checked against the oracle above)."""
    margin = clipped(margin)
    calls = [c for c in calls if not (c[0] == "set_pair_collision" and c[1] == c[2])]

    def run(**how):
        detector = kdet.Detector(test="exact", margin=float(margin), **how)
        for m in meshes:
            detector.add_object(m)
        for name, *args in calls:
            getattr(detector, name)(*args)
        return detector.detect()

    reference = run(method="brute_force_pairs")
    expected = pairs_of(reference)
    everything = oracle.pairs_within(meshes, margin, [0, 1, 2])
    assert expected <= everything
    assert_pairs(chosen["method"], run(**chosen), meshes, expected)


def tolerance(points, *values) -> float:
    """The stated tolerance of a distance or closest point: 1e-6 of the extent of `points` (the pair or
    the tet and its point), plus two float steps of the largest coordinate (the float rounding of a
    point) and of the values themselves."""
    points = np.asarray(points, np.float64).reshape(-1, 3)
    largest = max(np.abs(points).max(), *map(abs, values), np.finfo(np.float32).tiny)
    return 1e-6 * float(np.ptp(points, axis=0).max()) + 2 * float(np.spacing(F32(largest)))


@EXACT
@given(a=soups(), b=soups(), margin=margins, chosen=options, scale=scales)
def test_distances_and_closest_points_match_the_oracle(a, b, margin, chosen, scale):
    hypothesis.assume(chosen["method"] in ("kdet", "brute_force_pairs"))
    meshes, margin = at_scale([a, b], margin, scale)
    r = margin_detect(meshes, margin, self_collision=[0], distances=True, **chosen)
    assert pairs_of(r) == oracle.pairs_within(meshes, margin, [0])
    for pair, distance, (on_a, on_b) in zip(map(tuple, r.pairs.astype(int)), r.distances, r.closest_points):
        oa, ta, ob, tb = pair
        tet_a = oracle.float32(meshes[oa].vertices[meshes[oa].tets[ta]])
        tet_b = oracle.float32(meshes[ob].vertices[meshes[ob].tets[tb]])
        exact = math.sqrt(oracle.pair_d2(meshes, pair))
        tol = tolerance(np.vstack([tet_a, tet_b]), distance, exact)
        assert abs(float(distance) - exact) <= tol, (pair, distance, exact)
        assert abs(float(np.linalg.norm(on_b.astype(np.float64) - on_a)) - exact) <= 2 * tol
        for tet, point in ((tet_a, on_a), (tet_b, on_b)):
            e = oracle.Exact(tet, point)
            assert math.sqrt(float(e.real(oracle.point_tet_d2(e.points(tet), e.points(point)[0])))) <= tol


def query_points(mesh, draw) -> np.ndarray:
    """Vertices, edge and face midpoints and centroids (rounded to float), vertices pushed one float step
    out along each axis, and random points in the mesh's box grown by a fifth."""
    v = oracle.float32(mesh.vertices)
    corners = v[mesh.tets.astype(np.int64)]
    edges = [(corners[:, i] + corners[:, j]) / 2 for i, j in oracle.EDGES]
    faces = [corners[:, list(f)].mean(axis=1) for f in oracle.FACES]
    pushed = [np.nextafter(v.astype(np.float32), np.float32(sign * np.inf)).astype(np.float64) for sign in (-1, 1)]
    lo, hi = v.min(axis=0), v.max(axis=0)
    grown = (hi - lo) * 0.2
    fractions = np.array(draw(st.lists(st.tuples(*[st.floats(0, 1)] * 3), min_size=1, max_size=12)))
    random = lo - grown + fractions * (hi - lo + 2 * grown)
    every = np.vstack([v, *edges, *faces, corners.mean(axis=1), *pushed, random])
    chosen = draw(st.lists(st.integers(0, len(every) - 1), min_size=1, max_size=30, unique=True))
    return oracle.float32(every[sorted(chosen)])


@EXACT
@given(data=st.data(), mesh=soups(max_tets=8), scale=scales, within=st.sampled_from([None, 0.05, 0.5, 4.0]))
def test_locate_gives_the_exact_containment_and_nearest_distance(data, mesh, scale, within):
    (mesh,), _ = at_scale([mesh], 0.0, scale)
    points = query_points(mesh, data.draw)
    within = None if within is None else float(F32(within * 10.0 ** scale[0]))
    r = kdet.locate(mesh, points, within=within)
    hits, nearest = oracle.locate(mesh, points)
    got = {(int(p), int(t)) for p, t in zip(r.points, r.tets)}
    held = {p for p, _ in hits}
    assert {h for h in got if h[0] in held} == hits
    v = oracle.float32(mesh.vertices)
    for p in range(len(points)):
        if p in held:
            continue
        mine = [t for q, t in got if q == p]
        exact = math.sqrt(float(nearest[p]))
        tol = tolerance(np.vstack([v, points[p]]), exact)
        if within is None or exact > within + tol:
            assert mine == []
        elif exact < within - tol:
            assert len(mine) == 1
        if mine:
            k = int(r.offsets[p])
            assert abs(float(r.distances[k]) - exact) <= tol
            assert abs(float(np.linalg.norm(r.closest_points[k] - points[p])) - exact) <= tol


def test_a_tet_without_volume_inside_a_tet_gets_a_common_point_on_itself():
    # Regression (found by test_distances_and_closest_points_match_the_oracle): every point read as
    # inside a tet without volume, so the common point of a point tet inside a tet was the other tet's
    # vertex, 0.25 away from the point tet.
    point = kdet.TetMesh(np.zeros((4, 3)), np.arange(4, dtype=np.uint32).reshape(1, 4), allow_degenerate=True)
    big = kdet.TetMesh([[-0.25, -0.25, 0.5], [0, -1, -1], [-0.75, 0, 0.25], [1, 0.75, -0.5]],
                       np.arange(4, dtype=np.uint32).reshape(1, 4))
    for meshes in ([big, point], [point, big]):
        r = margin_detect(meshes, 0.0, distances=True)
        assert pairs_of(r) == {(0, 0, 1, 0)}
        np.testing.assert_array_equal(r.closest_points[0], np.zeros((2, 3), np.float32))


@settings(EXACT, max_examples=12)
@given(data=st.data(), meshes=st.lists(soups(max_tets=4), min_size=2, max_size=2), scale=scales)
def test_detector_locate_over_objects_gives_each_objects_exact_containment(data, meshes, scale):
    meshes, _ = at_scale(meshes, 0.0, scale)
    points = query_points(kdet.TetMesh(np.vstack([m.vertices for m in meshes]),
                                       np.vstack([meshes[0].tets, meshes[1].tets + len(meshes[0].vertices)]),
                                       allow_degenerate=True), data.draw)
    detector = kdet.Detector()
    ids = [detector.add_object(m) for m in meshes]
    every = detector.locate(points)
    got = {(int(p), int(o), int(t)) for p, o, t in zip(every.points, every.objects, every.tets)}
    expected = set()
    for k, mesh in zip(ids, meshes):
        hits, _ = oracle.locate(mesh, points)
        expected |= {(p, k, t) for p, t in hits}
        only = detector.locate(points, object=k)
        assert {(int(p), int(t)) for p, t in zip(only.points, only.tets)} == hits
    assert got == expected
