"""Point location from Python: the library's hits as NumPy arrays, against a NumPy brute force with
exact rational orientation signs; Detector.locate per object; errors; the GPU against the CPU."""

from fractions import Fraction

import numpy as np
import pytest

import kdet


def box_mesh():
    """Two unit cubes side by side, six tets each (Kuhn split): vertices shared by several tets."""
    xs, ys, zs = np.meshgrid(np.arange(3.0), np.arange(2.0), np.arange(2.0), indexing="ij")
    vertices = np.stack([xs.ravel(), ys.ravel(), zs.ravel()], axis=1)
    index = {tuple(v): i for i, v in enumerate(vertices)}
    paths = [(0, 1, 2), (0, 2, 1), (1, 0, 2), (1, 2, 0), (2, 0, 1), (2, 1, 0)]
    tets = []
    for cx in range(2):
        for path in paths:
            corner = [cx, 0, 0]
            tet = [index[tuple(float(c) for c in corner)]]
            for axis in path:
                corner[axis] += 1
                tet.append(index[tuple(float(c) for c in corner)])
            tets.append(tet)
    return kdet.TetMesh(vertices, np.array(tets, dtype=np.uint32))


def orient(a, b, c, d):
    rows = [[Fraction(float(x)) - Fraction(float(y)) for x, y in zip(p, a)] for p in (b, c, d)]
    det = (rows[0][0] * (rows[1][1] * rows[2][2] - rows[1][2] * rows[2][1])
           - rows[0][1] * (rows[1][0] * rows[2][2] - rows[1][2] * rows[2][0])
           + rows[0][2] * (rows[1][0] * rows[2][1] - rows[1][1] * rows[2][0]))
    return (det > 0) - (det < 0)


def brute_force(mesh, points):
    v = mesh.vertices.astype(np.float32)
    hits = set()
    for t, tet in enumerate(mesh.tets):
        a, b, c, d = v[tet]
        own = orient(a, b, c, d)
        for p, q in enumerate(points.astype(np.float32)):
            signs = [orient(q, b, c, d), orient(a, q, c, d), orient(a, b, q, d), orient(a, b, c, q)]
            if -own not in signs:
                hits.add((p, t))
    return hits


def query_points(mesh, seed=0):
    rng = np.random.default_rng(seed)
    v = mesh.vertices
    edges = [(v[t[i]] + v[t[j]]) / 2 for t in mesh.tets for i in range(4) for j in range(i + 1, 4)]
    outside = [[2.0 + 1e-7, 0.5, 0.5], [-1e-7, 0.5, 0.5], [1.0, 1.0 + 1e-7, 1.0]]
    random = rng.uniform(-0.2, 2.2, size=(60, 3))
    return np.concatenate([v, np.array(edges), np.array(outside), random]).astype(np.float32).astype(np.float64)


def hits_of(r):
    return {(int(p), int(t)) for p, t in zip(r.points, r.tets)}


def test_locate_matches_exact_brute_force():
    mesh = box_mesh()
    points = query_points(mesh)
    r = kdet.locate(mesh, points)
    assert r.offsets.shape == (len(points) + 1,) and r.offsets.dtype == np.uint64
    assert r.barycentrics.shape == (len(r.tets), 4)
    assert hits_of(r) == brute_force(mesh, points)
    # A grid vertex inside the shared face is held by every tet around it.
    assert max(np.diff(r.offsets)) >= 6
    np.testing.assert_allclose(r.barycentrics.sum(axis=1), 1.0, atol=1e-12)
    rebuilt = np.einsum("kj,kjx->kx", r.barycentrics, mesh.vertices[mesh.tets[r.tets]])
    np.testing.assert_allclose(rebuilt, points[r.points], atol=1e-12)
    assert np.all(r.distances == 0)


def test_within_gives_the_nearest_tet():
    mesh = box_mesh()
    points = np.array([[2.5, 0.5, 0.5], [5.0, 0.5, 0.5], [1.0, 0.5, 0.5]])
    r = kdet.locate(mesh, points, within=1.0)
    assert list(np.diff(r.offsets))[:2] == [1, 0]
    assert r.distances[0] == pytest.approx(0.5)
    np.testing.assert_allclose(r.closest_points[0], [2.0, 0.5, 0.5])
    assert np.all(r.distances[1:] == 0)


def test_device_results_on_the_cpu_are_the_detectors_buffers():
    mesh = box_mesh()
    detector = kdet.Detector()
    detector.add_object(mesh)
    points = query_points(mesh, 2)
    device = detector.locate(points, device_results=True)
    host = kdet.locate(mesh, points)
    np.testing.assert_array_equal(np.from_dlpack(device.tets), host.tets)
    np.testing.assert_array_equal(np.from_dlpack(device.barycentrics), host.barycentrics)


def test_detector_locate_per_object():
    mesh = box_mesh()
    detector = kdet.Detector()
    a = detector.add_object(mesh)
    b = detector.add_object(mesh.vertices + [1.0, 0.0, 0.0], mesh.tets)
    points = np.array([[0.5, 0.5, 0.5], [1.5, 0.5, 0.5], [2.5, 0.5, 0.5]])
    everything = detector.locate(points)
    assert set(everything.objects[everything.points == 1]) == {a, b}
    only_b = detector.locate(points, object=b)
    # The points lie on the cubes' main diagonals, which all six tets of a cube share.
    assert set(only_b.objects) == {b} and list(np.diff(only_b.offsets)) == [0, 6, 6]
    assert hits_of(detector.locate(points, object=a)) == hits_of(kdet.locate(mesh, points))


def test_errors_name_the_argument():
    mesh = box_mesh()
    with pytest.raises(kdet.Error, match="point 1 has a non-finite coordinate"):
        kdet.locate(mesh, np.array([[0.0, 0, 0], [np.nan, 0, 0]]))
    with pytest.raises(kdet.Error, match="within"):
        kdet.locate(mesh, np.zeros((1, 3)), within=-1.0)
    with pytest.raises(TypeError, match="within"):
        kdet.locate(mesh, np.zeros((1, 3)), within="far")
    with pytest.raises(TypeError, match="points"):
        kdet.locate(mesh, "points")
    with pytest.raises(kdet.Error, match="object id 3"):
        kdet.Detector().locate(np.zeros((1, 3)), object=3)
    # A frame's options would change nothing: refused by name, not ignored.
    for keyword in ("margin", "method", "contacts"):
        with pytest.raises(TypeError, match=f"keyword '{keyword}' does not apply to point location"):
            kdet.locate(mesh, np.zeros((1, 3)), **{keyword: kdet.Detector().options[keyword]})
    with pytest.raises(TypeError, match="unexpected keyword argument 'nope'"):
        kdet.locate(mesh, np.zeros((1, 3)), nope=1)
    assert len(kdet.locate(mesh, np.zeros((1, 3)), threads=1, hash="fnv-1a").offsets) == 2


def test_locate_takes_the_keywords_the_table_marks_and_its_docstring_names_them():
    mesh = box_mesh()
    taken = [name for name, entry in kdet.OPTIONS.items() if entry["locate"]]
    assert "threads" in taken and "margin" not in taken
    assert f'marks "locate": {", ".join(taken)}.' in " ".join(kdet.locate.__doc__.split())
    for name, value in kdet.Detector().options.items():
        if name in taken:
            assert len(kdet.locate(mesh, np.zeros((1, 3)), **{name: value}).offsets) == 2
        else:
            with pytest.raises(TypeError, match=f"keyword '{name}' does not apply"):
                kdet.locate(mesh, np.zeros((1, 3)), **{name: value})


@pytest.mark.skipif(not kdet.cuda_available(), reason="no CUDA device")
def test_gpu_locate_matches_cpu():
    mesh = box_mesh()
    points = query_points(mesh, 1)
    cpu = kdet.locate(mesh, points, within=0.3)
    gpu = kdet.locate(mesh, points, within=0.3, backend="cuda")
    for name in ("offsets", "tets", "barycentrics", "closest_points", "distances"):
        np.testing.assert_array_equal(getattr(gpu, name), getattr(cpu, name))
    detector = kdet.Detector(backend="cuda")
    detector.add_object(mesh)
    device = detector.locate(points, within=0.3, device_results=True)
    assert device.points is None
    assert device.tets.__dlpack_device__()[0] == 2  # kDLCUDA: the detector's own GPU buffer
    host = detector.locate(points, within=0.3)
    np.testing.assert_array_equal(host.tets, cpu.tets)
