"""Property-based tests (Hypothesis): random tet soups, meshes with shared and coincident vertices,
slivers and zero-volume tets, scales from 1e-30 to 3e38 (where tets' edges overflow float) and offsets
to 1e7, random options and random sequences of frames on one Detector.

The oracle is the brute-force method with the exact test on the same float32 coordinates, and, for a
scene scaled by a power of two (exact in float32 while nothing becomes subnormal), the answer for the
unscaled scene. Runs are derandomized (the same examples every run) and bounded to a few seconds per
property. Failing examples that Hypothesis found are kept below as plain tests.
"""

from __future__ import annotations

import numpy as np
import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

import kdet  # noqa: E402

PROPERTY = settings(
    max_examples=40,
    deadline=None,
    derandomize=True,
    database=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large, HealthCheck.filter_too_much],
)

# Methods with a pair list; the others flag colliding tets only.
PAIR_METHODS = ["kdet", "brute_force_pairs"]


@st.composite
def soups(draw, max_tets: int = 10) -> kdet.TetMesh:
    """Tets over a small pool of vertices: indices repeat (shared vertices, adjacency), coordinates on a
    quarter grid coincide and touch, and tets may be slivers or of zero volume (a repeated index, or
    flat on the grid)."""
    vertex_count = draw(st.integers(4, 14))
    grid = st.integers(-8, 8).map(lambda k: k / 4.0)
    anywhere = st.floats(-2.0, 2.0, width=32, allow_subnormal=False)
    coordinate = st.one_of(grid, grid, anywhere)
    vertices = np.array(draw(st.lists(st.tuples(coordinate, coordinate, coordinate), min_size=vertex_count,
                                      max_size=vertex_count)), dtype=np.float32)
    index = st.integers(0, vertex_count - 1)
    tets = np.array(draw(st.lists(st.tuples(index, index, index, index), min_size=1, max_size=max_tets)),
                    dtype=np.uint32)
    return kdet.TetMesh(vertices.astype(np.float64), tets, allow_degenerate=True)


def with_vertices(mesh: kdet.TetMesh, vertices: np.ndarray) -> kdet.TetMesh:
    return kdet.TetMesh(np.asarray(vertices, dtype=np.float32).astype(np.float64), mesh.tets, allow_degenerate=True)


def detect(meshes, method="brute_force_pairs", test="exact", hash="djb2", threads=1, self_collision=(),
           pairs_off=()):
    """(pairs as a set of 4-tuples, colliding flags per object) of one detection of fresh objects."""
    detector = kdet.Detector(method=method, test=test, hash=hash, threads=threads)
    ids = [detector.add_object(mesh) for mesh in meshes]
    for k in self_collision:
        detector.set_self_collision(ids[k], True)
    for a, b in pairs_off:
        detector.set_pair_collision(ids[a], ids[b], False)
    r = detector.detect()
    return {tuple(map(int, p)) for p in r.pairs}, [np.asarray(c).copy() for c in r.colliding]


def assert_same(method, answer, reference):
    pairs, flags = answer
    reference_pairs, reference_flags = reference
    if method in PAIR_METHODS:
        assert pairs == reference_pairs
    for got, want in zip(flags, reference_flags):
        np.testing.assert_array_equal(got, want)


options = st.fixed_dictionaries({
    "method": st.sampled_from(kdet.METHODS),
    "hash": st.sampled_from(kdet.HASHES),
    "threads": st.sampled_from([1, 2]),
})


def solid_only(mesh: kdet.TetMesh) -> kdet.TetMesh | None:
    """The mesh's tets of clearly non-zero volume (as the readers' check), or None when there is none."""
    v = mesh.vertices[mesh.tets.astype(np.int64)]
    e = v[:, 1:] - v[:, :1]
    volume = np.abs(np.einsum("ij,ij->i", e[:, 0], np.cross(e[:, 1], e[:, 2])))
    longest = np.linalg.norm(v[:, :, None] - v[:, None, :], axis=-1).max(axis=(1, 2))
    keep = volume > 1e-6 * longest**3
    return kdet.TetMesh(mesh.vertices, mesh.tets[keep]) if keep.any() else None


def exactly_scaled(mesh: kdet.TetMesh, exponent: int) -> kdet.TetMesh | None:
    """The mesh times 2^exponent in float32, or None where that is not exact (a coordinate would be subnormal)."""
    v = mesh.vertices.astype(np.float32)
    scaled = (v.astype(np.float64) * 2.0**exponent).astype(np.float32)
    if not np.array_equal(scaled.astype(np.float64) * 2.0**-exponent, v.astype(np.float64)):
        return None
    return with_vertices(mesh, scaled)


@PROPERTY
@given(a=soups(), b=soups(), chosen=options, self_a=st.booleans(), self_b=st.booleans())
def test_every_method_gives_the_brute_force_answer(a, b, chosen, self_a, self_b):
    selves = [k for k, on in enumerate([self_a, self_b]) if on]
    reference = detect([a, b], self_collision=selves)
    assert_same(chosen["method"], detect([a, b], test="exact", self_collision=selves, **chosen), reference)


@PROPERTY
@given(a=soups(), b=soups(), test=st.sampled_from(kdet.TESTS), hash=st.sampled_from(kdet.HASHES),
       exponent=st.sampled_from([-90, 0, 90]))
def test_the_grid_gives_brute_force_pairs_for_every_test(a, b, test, hash, exponent):
    # Whatever the test, the grid and its pre-tests change no answer of it, at any size. The float tests
    # get tets of non-zero volume only: on a zero-volume tet they find too few axes and may call pairs
    # far apart colliding, which the pre-test separates (a point and a segment 0.18 apart: sat, sat_mtv
    # and fast say colliding under brute force, not in the grid).
    if test != "exact":
        a, b = solid_only(a), solid_only(b)
        hypothesis.assume(a is not None and b is not None)
    sa, sb = exactly_scaled(a, exponent), exactly_scaled(b, exponent)
    hypothesis.assume(sa is not None and sb is not None)
    assert_same("kdet", detect([sa, sb], method="kdet", test=test, hash=hash, self_collision=[0]),
                detect([sa, sb], test=test, self_collision=[0]))


@PROPERTY
@given(a=soups(), b=soups(), exponent=st.integers(-100, 120), chosen=options)
def test_power_of_two_scales_give_the_unscaled_answer(a, b, exponent, chosen):
    sa, sb = exactly_scaled(a, exponent), exactly_scaled(b, exponent)
    hypothesis.assume(sa is not None and sb is not None)
    assert_same(chosen["method"], detect([sa, sb], self_collision=[0], **chosen), detect([a, b], self_collision=[0]))


def test_two_tets_scaled_by_2_to_the_100_keep_their_pairs():
    # Regression: every pair was lost once squared sizes overflowed float (scales above about 2^64).
    a = kdet.TetMesh([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], [[0, 1, 2, 3]])
    b = kdet.TetMesh([[0.5, 0, 0], [1.5, 0, 0], [0.5, 1, 0], [0.5, 0, 1]], [[0, 1, 2, 3]])
    for method in kdet.METHODS:
        assert_same(method, detect([exactly_scaled(a, 100), exactly_scaled(b, 100)], method=method),
                    ({(0, 0, 1, 0)}, [np.ones(1, bool), np.ones(1, bool)]))


def test_tets_whose_edges_overflow_float_keep_the_exact_answer():
    # Regression (found by a longer random search): tets with coordinates up to 3e38 of both signs beside
    # small tets; the face-plane pre-test took such a pair's longest edge from the small tet alone and
    # proved pairs 4e37 apart intersecting.
    rng = np.random.default_rng(7)
    tets = np.arange(160, dtype=np.uint32).reshape(40, 4)
    large = kdet.TetMesh(rng.uniform(-3e38, 3e38, (160, 3)).astype(np.float32).astype(np.float64), tets,
                         allow_degenerate=True)
    corners = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], np.float64)
    small = kdet.TetMesh(np.vstack([corners * rng.uniform(0.1, 1) + 2 * (t % 4) for t in range(40)]), tets)
    reference = detect([large, small], self_collision=[0])
    for method in kdet.METHODS:
        assert_same(method, detect([large, small], method=method, self_collision=[0]), reference)


def test_segments_longer_than_the_largest_float_keep_their_pair():
    # Regression (found by the arbitrary-scale property in a longer run): zero-volume tets through the
    # origin whose lengths exceed the largest float; the pair was lost, or the frame ran out of memory.
    def segment(end_a, end_b):
        return kdet.TetMesh([end_a, end_a, end_a, end_b], [[0, 1, 2, 3]], allow_degenerate=True)

    for a, b in [(segment([0, 0, 0], [0, 1.5399265e38, 3.0798531e38]), segment([0, 0, 1.9249082e38], [0, 0, -1.5399265e38])),
                 (segment([0, 0, 0], [0, 0, 2.6670430e38]), segment([0, 0, 0], [0, 0, -1.0001410e38]))]:
        reference = detect([a, b])
        assert reference[0] == {(0, 0, 1, 0)}
        for method in kdet.METHODS:
            assert_same(method, detect([a, b], method=method), reference)


@PROPERTY
@given(a=soups(), b=soups(), decade=st.floats(-30, 38.2), offset=st.tuples(*[st.floats(-1e7, 1e7)] * 3),
       chosen=options)
def test_any_scale_and_offset_gives_the_brute_force_answer(a, b, decade, offset, chosen):
    def moved(mesh):
        return with_vertices(mesh, mesh.vertices * 10.0**decade + np.asarray(offset) * 10.0**min(decade, 0.0))

    ma, mb = moved(a), moved(b)
    reference = detect([ma, mb], self_collision=[0, 1])
    assert_same(chosen["method"], detect([ma, mb], self_collision=[0, 1], **chosen), reference)


frames = st.lists(
    st.one_of(
        st.tuples(st.just("move"), st.integers(0, 2), st.floats(-1.5, 1.5), st.sampled_from([2.0**-80, 1.0, 2.0**80])),
        st.tuples(st.just("self"), st.integers(0, 2), st.booleans()),
        st.tuples(st.just("pair"), st.integers(0, 2), st.integers(0, 2), st.booleans()),
        st.tuples(st.just("detect")),
    ),
    min_size=1,
    max_size=12,
)


@PROPERTY
@given(meshes=st.lists(soups(max_tets=6), min_size=3, max_size=3), steps=frames, chosen=options)
def test_frame_sequences_give_what_a_fresh_detector_gives(meshes, steps, chosen):
    """Positions moved (also to other scales), self- and pair collision switched, in any order, on one
    detector: every frame equals a fresh brute-force detector's answer for the same state."""
    detector = kdet.Detector(test="exact", **chosen)
    ids = [detector.add_object(m) for m in meshes]
    current = list(meshes)
    selves, off = set(), set()
    for step in steps + [("detect",)]:
        if step[0] == "move":
            _, k, shift, scale = step
            moved = with_vertices(meshes[k], (meshes[k].vertices + shift) * scale)
            current[k] = moved
            detector.set_positions(ids[k], moved.vertices.astype(np.float32))
        elif step[0] == "self":
            _, k, on = step
            detector.set_self_collision(ids[k], on)
            (selves.add if on else selves.discard)(k)
        elif step[0] == "pair":
            _, a, b, on = step
            if a == b:
                continue
            detector.set_pair_collision(ids[a], ids[b], on)
            (off.discard if on else off.add)((min(a, b), max(a, b)))
        else:
            r = detector.detect()
            answer = ({tuple(map(int, p)) for p in r.pairs}, [np.asarray(c).copy() for c in r.colliding])
            assert_same(chosen["method"], answer, detect(current, self_collision=sorted(selves), pairs_off=sorted(off)))


# What has landed since the sequences above: collision filters, self-exclusion rings, rest contacts,
# static objects, removal and new tets, and a memory limit. Masks and groups are drawn from 2 bits, so
# that filters both pass and block pairs.
filtered_steps = st.lists(
    st.one_of(
        st.tuples(st.just("move"), st.integers(0, 2), st.floats(-1.5, 1.5), st.sampled_from([2.0**-80, 1.0, 2.0**80])),
        st.tuples(st.just("self"), st.integers(0, 2), st.booleans()),
        st.tuples(st.just("pair"), st.integers(0, 2), st.integers(0, 2), st.booleans()),
        st.tuples(st.just("filter"), st.integers(0, 2), st.integers(0, 3), st.integers(0, 3)),
        st.tuples(st.just("rings"), st.integers(0, 2), st.integers(0, 2)),
        st.tuples(st.just("rest"), st.integers(0, 2), st.one_of(st.none(), st.integers(0, 2))),
        st.tuples(st.just("static"), st.integers(0, 2), st.booleans()),
        st.tuples(st.just("remove"), st.integers(0, 2)),
        st.tuples(st.just("tets"), st.integers(0, 2), soups(max_tets=6)),
        st.tuples(st.just("detect")),
    ),
    min_size=1,
    max_size=14,
)


def replay(meshes, log, **options):
    """A fresh detector given the same objects and the same calls, in the same order."""
    detector = kdet.Detector(**options)
    for mesh in meshes:
        detector.add_object(mesh)
    for name, args in log:
        getattr(detector, name)(*args)
    return detector


def answer_of(detector):
    r = detector.detect()
    return {tuple(map(int, p)) for p in r.pairs}, [np.asarray(c).copy() for c in r.colliding]


@PROPERTY
@given(meshes=st.lists(soups(max_tets=6), min_size=3, max_size=3), steps=filtered_steps, chosen=options,
       memory_limit=st.sampled_from([0, 0, 3000, 100000]))
def test_filtered_sequences_give_what_brute_force_gives_the_same_calls(meshes, steps, chosen, memory_limit):
    """Filters, rings, rest contacts, static objects, removals and new tets switched in any order on one
    detector, also under a memory limit: every frame equals a fresh brute-force detector given the same
    calls (rest contacts are recorded where the positions were when they were asked for, so the calls
    are replayed in order), or, where the limit cannot hold the frame, it fails naming memory_limit and
    the detector goes on as it was."""
    detector = kdet.Detector(test="exact", memory_limit=memory_limit, **chosen)
    ids = [detector.add_object(m) for m in meshes]
    live = set(ids)
    current = [m.vertices.astype(np.float32) for m in meshes]  # each object's positions as set last
    log = []
    for step in steps + [("detect",)]:
        kind, args = step[0], step[1:]
        if kind != "detect" and args[0] not in live:
            continue
        if kind == "move":
            k, shift, scale = args
            moved = (current[k].astype(np.float64) + shift) * scale
            if not np.all(np.abs(moved) <= np.finfo(np.float32).max):
                continue  # beyond float: refused, as test_inputs.py checks
            current[k] = moved.astype(np.float32)
            call = ("set_positions", (k, current[k]))
        elif kind == "self":
            call = ("set_self_collision", args)
        elif kind == "pair":
            if args[0] == args[1] or args[1] not in live:
                continue
            call = ("set_pair_collision", args)
        elif kind == "filter":
            call = ("set_collision_filter", args)
        elif kind == "rings":
            call = ("set_self_exclusion_rings", args)
        elif kind == "rest":
            k, other = args
            if other is not None and (other == k or other not in live):
                continue
            call = ("exclude_rest_contacts", (k,) if other is None else (k, other))
        elif kind == "static":
            call = ("set_static", args)
        elif kind == "remove":
            if len(live) == 1:
                continue
            live.discard(args[0])
            call = ("remove_object", args)
        elif kind == "tets":
            k, mesh = args
            current[k] = mesh.vertices.astype(np.float32)
            call = ("set_tets", (k, mesh))
        else:
            try:
                answer = answer_of(detector)
            except kdet.Error as error:
                assert memory_limit and "memory_limit" in str(error), str(error)
                continue
            reference = answer_of(replay(meshes, log, method="brute_force_pairs", test="exact"))
            assert_same(chosen["method"], answer, reference)
            continue
        try:
            getattr(detector, call[0])(*call[1])
        except kdet.Error as error:  # only recording rest contacts detects, and may meet the limit
            assert call[0] == "exclude_rest_contacts" and memory_limit and "memory_limit" in str(error), str(error)
            continue
        log.append(call)
