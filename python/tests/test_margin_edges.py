"""Margins and query points at the ends of float32 from Python (issue 48): answered exactly or refused
with one line naming the argument and its range, as on the C++ API and the command line."""

from __future__ import annotations

import numpy as np
import pytest

import kdet

LARGEST = float(np.finfo(np.float32).max)
SMALLEST = float(np.finfo(np.float32).smallest_subnormal)
TET = np.arange(4, dtype=np.uint32).reshape(1, 4)


def faces_apart(h: float, z0: float = 0.0, s: float = 1.0):
    """a's face on z = z0, b's on z = z0 + h above it (every coordinate a float)."""
    a = kdet.TetMesh([[0, 0, z0], [s, 0, z0], [0, s, z0], [s / 4, s / 4, z0 - s]], TET)
    b = kdet.TetMesh([[s / 8, s / 8, z0 + h], [s + s / 8, s / 8, z0 + h], [s / 8, s + s / 8, z0 + h],
                      [s / 4, s / 4, float(np.float32(z0 + h + s))]], TET)
    return a, b


@pytest.mark.parametrize("h, z0, s", [(SMALLEST, 0.0, 1.0), (float(np.float32(1e-30)), 0.0, 1.0),
                                      (2.0**104, 2.0**127, 2.0**110), (2.0**120, 0.0, 2.0**126)])
def test_pairs_at_the_ends_are_reported_at_their_distance_and_not_one_float_below(h, z0, s):
    a, b = faces_apart(h, z0, s)
    below = float(np.nextafter(np.float32(h), np.float32(0)))
    for method in kdet.METHODS:
        for margin, count in ((h, 1), (below, 0), (LARGEST, 1)):
            r = kdet.Detector(method=method, margin=margin)
            r.add_object(a)
            r.add_object(b)
            flags = r.detect().colliding
            assert int(flags[0][0]) == int(flags[1][0]) == count, (method, margin)


def test_refused_margins_and_within_name_the_argument_and_range():
    a, b = faces_apart(1.0)
    for bad in (1e39, -SMALLEST, float("inf"), float("nan")):
        with pytest.raises(kdet.Error, match=r"^margin: expected a finite number >= 0, got") as caught:
            kdet.collide(a, b, margin=bad)
        assert "\n" not in str(caught.value)
    with pytest.raises(kdet.Error, match=r"within must be finite and not negative, got -1e-300$"):
        kdet.locate(a, np.zeros((1, 3)), within=-1e-300)
    with pytest.raises(kdet.Error, match=r"point 1 has a non-finite coordinate \(or one beyond float range\)"):
        kdet.locate(a, np.array([[0.0, 0, 0], [0, 1e39, 0]]))


def test_points_and_within_at_the_ends():
    o, s, step = 2.0**127, 2.0**126, 2.0**103
    corner = kdet.TetMesh([[o, o, o], [o + s, o, o], [o, o + s, o], [o, o, o + s]], TET)
    points = np.array([[o + s / 4] * 3, [o - step, o + s / 4, o + s / 4], [-LARGEST] * 3])
    assert list(np.diff(kdet.locate(corner, points).offsets)) == [1, 0, 0]
    near = kdet.locate(corner, points, within=2 * step)
    assert list(np.diff(near.offsets)) == [1, 1, 0]
    assert near.distances[1] == pytest.approx(step, rel=1e-12)
    everywhere = kdet.locate(corner, points, within=1e300)
    assert list(np.diff(everywhere.offsets)) == [1, 1, 1]
    assert LARGEST < everywhere.distances[2] < np.inf
    tiny = kdet.TetMesh([[0, 0, 0], [2.0**-140, 0, 0], [0, 2.0**-140, 0], [0, 0, 2.0**-140]], TET)
    points = np.array([[SMALLEST] * 3, [-SMALLEST, SMALLEST, SMALLEST]])
    assert list(np.diff(kdet.locate(tiny, points).offsets)) == [1, 0]
    assert list(np.diff(kdet.locate(tiny, points, within=2 * SMALLEST).offsets)) == [1, 1]
