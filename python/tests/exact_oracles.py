"""Exact oracles for pairs within a margin and point location, in rational arithmetic (no CGAL).

Every input is a float (float32 values, as the detector stores them), so all of them are integers over one
common power of two: `Exact` maps a scene's coordinates (and margins, query points) to Python integers
over that denominator, and every predicate below is a sign or a ratio of integer polynomials, decided
without rounding. A closed tet is the hull of its four vertices: with volume, its faces and interior;
without (flat, collinear or a point), the union of its four faces, which is its hull.

- `tet_tet_d2`: squared distance of two closed tets, 0 when they share a point (a vertex of one inside
  the other, or an edge of one crossing a face of the other), else the least over vertex-face and
  edge-edge pairs, where the distance of two disjoint polytopes is reached.
- `point_tet_d2`: squared distance of a point and a closed tet, 0 exactly when the tet holds it.
"""

from __future__ import annotations

from fractions import Fraction
from itertools import combinations

import numpy as np

EDGES = list(combinations(range(4), 2))
FACES = list(combinations(range(4), 3))


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def orient(a, b, c, d):
    """Sign of the volume of (a, b, c, d): -1, 0 or 1."""
    v = dot(sub(b, a), cross(sub(c, a), sub(d, a)))
    return (v > 0) - (v < 0)


def point_segment_d2(p, a, b):
    e, w = sub(b, a), sub(p, a)
    ee, t = dot(e, e), dot(w, e)
    if ee == 0 or t <= 0:
        return Fraction(dot(w, w))
    if t >= ee:
        return Fraction(dot(sub(p, b), sub(p, b)))
    return Fraction(dot(cross(w, e), cross(w, e)), ee)


def point_triangle_d2(p, a, b, c):
    n = cross(sub(b, a), sub(c, a))
    if n != (0, 0, 0) and all(dot(cross(sub(v, u), sub(p, u)), n) >= 0 for u, v in ((a, b), (b, c), (c, a))):
        h = dot(n, sub(p, a))
        return Fraction(h * h, dot(n, n))
    return min(point_segment_d2(p, a, b), point_segment_d2(p, b, c), point_segment_d2(p, c, a))


def segment_segment_d2(a, b, c, d):
    e1, e2 = sub(b, a), sub(d, c)
    n = cross(e1, e2)
    if n != (0, 0, 0):
        # The lines' closest points a + s e1 and c + t e2, s and t as numerators over |n|^2.
        r, nn = sub(c, a), dot(n, n)
        s, t = dot(cross(r, e2), n), dot(cross(r, e1), n)
        if 0 <= s <= nn and 0 <= t <= nn:
            h = dot(r, n)
            return Fraction(h * h, nn)
    return min(point_segment_d2(a, c, d), point_segment_d2(b, c, d), point_segment_d2(c, a, b),
               point_segment_d2(d, a, b))


def holds(tet, p):
    """Whether a tet with volume holds p (closed); None for a tet without volume."""
    own = orient(*tet)
    if own == 0:
        return None
    return all(orient(*(p if k == j else tet[k] for k in range(4))) != -own for j in range(4))


def segment_crosses_triangle(p, q, a, b, c):
    """Whether the segment's ends lie strictly on both sides of the triangle's plane and its line passes
    through the closed triangle (the other ways to meet are vertex-face or edge-edge contacts)."""
    if orient(a, b, c, p) * orient(a, b, c, q) >= 0:
        return False
    signs = {orient(p, q, a, b), orient(p, q, b, c), orient(p, q, c, a)}
    return not (1 in signs and -1 in signs)


def tet_tet_d2(s, t):
    """Squared distance of two closed tets (four integer points each)."""
    for a, b in ((s, t), (t, s)):
        if any(holds(a, v) for v in b):
            return Fraction(0)
        for i, j in EDGES:
            if any(segment_crosses_triangle(b[i], b[j], *(a[k] for k in f)) for f in FACES):
                return Fraction(0)
    best = None
    for a, b in ((s, t), (t, s)):
        for v in a:
            for f in FACES:
                d = point_triangle_d2(v, *(b[k] for k in f))
                best = d if best is None or d < best else best
    for i, j in EDGES:
        for k, m in EDGES:
            d = segment_segment_d2(s[i], s[j], t[k], t[m])
            best = d if d < best else best
    return best


def point_tet_d2(tet, p):
    if holds(tet, p):
        return Fraction(0)
    return min(point_triangle_d2(p, *(tet[k] for k in f)) for f in FACES)


class Exact:
    """Floats as integers over one power of two 2^shift, the least denominator that holds them all."""

    def __init__(self, *values):
        denominators = [Fraction(float(x)).denominator for x in np.concatenate([np.ravel(v) for v in values])]
        self.scale = max(denominators, default=1)

    def number(self, x) -> int:
        f = Fraction(float(x)) * self.scale
        assert f.denominator == 1
        return f.numerator

    def points(self, xyz) -> list:
        return [tuple(self.number(c) for c in row) for row in np.asarray(xyz).reshape(-1, 3)]

    def real(self, d2: Fraction) -> Fraction:
        """A squared distance computed on the integers, in the floats' units."""
        return d2 / (self.scale * self.scale)


def float32(values) -> np.ndarray:
    return np.asarray(values, dtype=np.float32).astype(np.float64)


def tets_of(mesh, exact: Exact) -> list:
    v = exact.points(float32(mesh.vertices))
    return [tuple(v[int(i)] for i in tet) for tet in mesh.tets]


def boxes_within(s, t, m: int) -> bool:
    """Whether the boxes of two integer tets lie at most m apart (m an integer in the same units): a
    necessary condition for the tets, so the exact distance is computed only where it holds."""
    gap2 = 0
    for axis in range(3):
        gap = max(min(v[axis] for v in t) - max(v[axis] for v in s), min(v[axis] for v in s) - max(v[axis] for v in t), 0)
        gap2 += gap * gap
    return gap2 <= m * m


def pairs_within(meshes, margin: float, self_collision=()) -> set:
    """The pairs (object, tet, object, tet) at most `margin` apart, exactly for the float32 coordinates and
    margin: between objects (lower object first) and, for the objects in `self_collision`, within one
    (lower tet first) unless the two tets share a vertex index."""
    margin = float(np.float32(margin))
    exact = Exact(*(float32(m.vertices) for m in meshes), np.array([margin]))
    tets = [tets_of(m, exact) for m in meshes]
    m = exact.number(margin)
    within = set()

    def check(oa, ta, ob, tb):
        s, t = tets[oa][ta], tets[ob][tb]
        if boxes_within(s, t, m) and tet_tet_d2(s, t) <= m * m:
            within.add((oa, ta, ob, tb))

    for oa, ob in combinations(range(len(meshes)), 2):
        for ta in range(len(tets[oa])):
            for tb in range(len(tets[ob])):
                check(oa, ta, ob, tb)
    for o in self_collision:
        indices = [set(map(int, tet)) for tet in meshes[o].tets]
        for ta, tb in combinations(range(len(tets[o])), 2):
            if not indices[ta] & indices[tb]:
                check(o, ta, o, tb)
    return within


def pair_d2(meshes, pair) -> float:
    """The exact squared distance of one pair (object, tet, object, tet), as a float."""
    oa, ta, ob, tb = pair
    exact = Exact(float32(meshes[oa].vertices), float32(meshes[ob].vertices))
    return float(exact.real(tet_tet_d2(tets_of(meshes[oa], exact)[ta], tets_of(meshes[ob], exact)[tb])))


def locate(mesh, points):
    """(hits, nearest): the (point, tet) pairs whose closed tet holds the point (float32 values), and per
    point the exact squared distance of its nearest tet (0 for a held point)."""
    exact = Exact(float32(mesh.vertices), float32(points))
    tets, queries = tets_of(mesh, exact), exact.points(float32(points))
    hits, nearest = set(), []
    for p, q in enumerate(queries):
        d2 = [point_tet_d2(t, q) for t in tets]
        hits |= {(p, t) for t, d in enumerate(d2) if d == 0}
        nearest.append(exact.real(min(d2)))
    return hits, nearest
