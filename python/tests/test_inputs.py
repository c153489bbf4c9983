"""Bad input gets kdet.Error (a ValueError) or a TypeError naming the argument, never a crash; float32,
float64, lists and arrays of any strides are read, and give the same pairs."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import kdet
from helpers import extent, moved


@pytest.fixture(scope="module")
def octopus(models: Path) -> kdet.TetMesh:
    return kdet.read_tet_mesh(models / "octopus-low.mesh")


@pytest.fixture(scope="module")
def other(octopus: kdet.TetMesh) -> kdet.TetMesh:
    return moved(octopus, 0.3, (0.1 * extent(octopus), 0.0, 0.0))


def one_tet() -> tuple[np.ndarray, np.ndarray]:
    return np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=np.float64), np.array([[0, 1, 2, 3]], np.uint32)


def test_error_is_a_value_error_with_the_library_message(tmp_path):
    assert issubclass(kdet.Error, ValueError)
    missing = tmp_path / "missing.mesh"
    with pytest.raises(kdet.Error, match=f"^{missing}: "):
        kdet.read_tet_mesh(missing)
    (tmp_path / "bad.mesh").write_text("MeshVersionFormatted 1\nDimension 3\nVertices\n2\n0 0 0 0\n0 0 x 0\n")
    with pytest.raises(kdet.Error, match=r"bad.mesh:6: ") as caught:
        kdet.read_tet_mesh(str(tmp_path / "bad.mesh"))
    assert "\n" not in str(caught.value)
    with pytest.raises(kdet.Error, match="unsupported mesh format"):
        kdet.read_tet_mesh(tmp_path / "mesh.obj")
    with pytest.raises(kdet.Error, match="cannot write mesh format"):
        kdet.write_tet_mesh(kdet.TetMesh(*one_tet()), tmp_path / "mesh.obj")


@pytest.mark.parametrize(
    "vertices, tets, error, message",
    [
        (np.zeros((4, 2)), [[0, 1, 2, 3]], kdet.Error, r"vertices: expected an array of shape \(n, 3\), got shape \(4, 2\)"),
        (np.zeros((4, 3, 1)), [[0, 1, 2, 3]], kdet.Error, r"vertices: .*got shape \(4, 3, 1\)"),
        (np.zeros(12), [[0, 1, 2, 3]], kdet.Error, r"vertices: .*got shape \(12,\)"),
        (np.zeros((4, 3), np.int64), [[0, 1, 2, 3]], TypeError, "vertices: dtype int64 is not supported"),
        (np.zeros((4, 3), np.complex64), [[0, 1, 2, 3]], TypeError, "vertices: dtype complex64"),
        ("vertices", [[0, 1, 2, 3]], TypeError, "vertices: expected an array .* got str"),
        ([[0, 0], [1]], [[0, 1, 2, 3]], TypeError, "vertices: cannot read the sequence"),
        (one_tet()[0], [[0, 1, 2]], kdet.Error, r"tets: expected an array of shape \(n, 4\), got shape \(1, 3\)"),
        (one_tet()[0], [[0.0, 1.0, 2.0, 3.0]], TypeError, "tets: dtype float64 is not supported"),
        (one_tet()[0], [[0, 1, 2, -3]], kdet.Error, "tets: tet 0 has the negative vertex index -3"),
        (one_tet()[0], np.array([[0, 1, 2, 2**40]]), kdet.Error, "tets: tet 0 has vertex index 1099511627776, beyond 32 bits"),
        (one_tet()[0], [[0, 1, 2, 4]], kdet.Error, r"TetMesh: tet 0: vertex index 4 out of range"),
        (one_tet()[0] * [1, 1, 0], [[0, 1, 2, 3]], kdet.Error, "TetMesh: tet 0: .*zero volume"),
        (np.where(np.eye(4, 3) > 0, np.nan, 0.0), [[0, 1, 2, 3]], kdet.Error, "TetMesh: vertex 0: .*finite"),
    ],
)
def test_bad_mesh_arrays(vertices, tets, error, message):
    with pytest.raises(error, match=message):
        kdet.TetMesh(vertices, tets)


def test_a_degenerate_tet_is_accepted_when_allowed():
    vertices, tets = one_tet()
    mesh = kdet.TetMesh(vertices * [1, 1, 0], tets, allow_degenerate=True)
    assert mesh.num_tets == 1


def test_detector_arguments_are_checked(octopus):
    detector = kdet.Detector()
    ia = detector.add_object(octopus)
    with pytest.raises(kdet.Error, match=r"object 0: got 3 vertices, expected 452"):
        detector.set_positions(ia, np.zeros((3, 3)))
    with pytest.raises(kdet.Error, match=r"object id 1 out of range \(1 objects\)"):
        detector.set_positions(1, octopus.vertices)
    with pytest.raises(kdet.Error, match=r"object id -1 out of range"):
        detector.set_self_collision(-1, True)
    with pytest.raises(kdet.Error, match="object 0: vertex 7 has a non-finite coordinate"):
        positions = octopus.vertices.copy()
        positions[7, 2] = np.inf
        detector.set_positions(ia, positions)
    with pytest.raises(kdet.Error, match="object 1: vertex 3 has a non-finite coordinate"):
        positions = octopus.vertices.copy()
        positions[3, 0] = np.nan
        detector.add_object(positions, octopus.tets)
    # Strided and Fortran-ordered arrays are read where they lie: the bad vertex is still the one named.
    with pytest.raises(kdet.Error, match="object 0: vertex 9 has a non-finite coordinate"):
        positions = np.asfortranarray(octopus.vertices)
        positions[9, 1] = 1e300  # beyond float32 range
        detector.set_positions(ia, positions)
    with pytest.raises(kdet.Error, match="object 0: vertex 11 has a non-finite coordinate"):
        positions = np.repeat(octopus.vertices.astype(np.float32), 2, axis=0)
        positions[23, 0] = np.inf  # row 23 is not read; row 22 is vertex 11
        positions[22, 2] = np.inf
        detector.set_positions(ia, positions[::2])
    with pytest.raises(kdet.Error, match="object 1: vertex 450 has a non-finite coordinate"):
        positions = octopus.vertices.copy()
        positions[1, 2] = np.nan
        detector.add_object(positions[::-1], octopus.tets)
    with pytest.raises(kdet.Error, match=r"object 1: tet 0 has vertex index 452 out of range \[0, 452\)"):
        tets = octopus.tets.copy()
        tets[0, 0] = 452
        detector.add_object(octopus.vertices, tets)
    with pytest.raises(TypeError, match="positions: dtype float16 is not supported"):
        detector.set_positions(ia, octopus.vertices.astype(np.float16))
    with pytest.raises(kdet.Error, match="set_pair_collision needs two different objects"):
        detector.set_pair_collision(ia, ia, False)
    assert detector.object_count == 1  # the failed add_object calls left the detector as it was


@pytest.mark.parametrize(
    "options, error, message",
    [
        ({"method": "nope"}, kdet.Error, "invalid value 'nope' for method: expected kdet, kdet_no_pairs, "),
        ({"test": "sat2"}, kdet.Error, "invalid value 'sat2' for test: expected sat, "),
        ({"hash": ""}, kdet.Error, "invalid value '' for hash"),
        ({"backend": "tpu"}, kdet.Error, "invalid value 'tpu' for backend: expected cpu or cuda"),
        ({"threads": 0}, kdet.Error, "threads: expected a positive number"),
        ({"bucket_capacity": -2}, kdet.Error, r"bucket_capacity: expected 0 \(chosen from the scene\) or a positive"),
        ({"bucket_capacity": 5000}, kdet.Error, r"bucket capacity 5000 out of range \[0, 4096\]"),
        ({"block_size": 2000}, kdet.Error, r"block size 2000 out of range \[1, 1024\]"),
        ({"initial_candidate_capacity": -1}, kdet.Error, "initial_candidate_capacity"),
        ({"method": 3}, TypeError, "method"),
        ({"contacts": "yes"}, TypeError, "contacts"),
        ({"tests": "sat"}, TypeError, "tests"),
        ({"cuda_stream": 1}, kdet.Error, "option cuda_stream is set, but the backend is 'cpu'"),
        ({"cuda_stream": -1}, kdet.Error, "cuda_stream: -1 is not a stream handle"),
        ({"cuda_stream": "stream"}, TypeError, "cuda_stream: expected None, a cudaStream_t as an int or a CUDA stream"),
    ],
)
def test_bad_options(options, error, message):
    with pytest.raises(error, match=message):
        kdet.Detector(**options)


def test_cuda_stream_objects_are_read_as_the_gpu_libraries_hand_them_out():
    class Protocol:  # the CUDA stream protocol
        def __cuda_stream__(self):
            return (0, 0)

    class Torch:  # torch.cuda.Stream, warp.Stream
        cuda_stream = 7

    class CuPy:  # cupy.cuda.Stream
        ptr = 9

    assert kdet.Detector(cuda_stream=Protocol()).options["cuda_stream"] is None  # the default stream
    # A handle that was read is refused on the CPU backend, which proves it was read.
    for stream in (Torch(), CuPy()):
        with pytest.raises(kdet.Error, match="option cuda_stream is set"):
            kdet.Detector(cuda_stream=stream)


def test_bad_meshes_for_collide(octopus):
    with pytest.raises(TypeError, match="b: expected a kdet.TetMesh, a meshio.Mesh or a"):
        kdet.collide(octopus, 3)
    with pytest.raises(kdet.Error, match="'kdet_no_pairs' only flags colliding tets"):
        kdet.collide(octopus, octopus, method="kdet_no_pairs")
    # What a one-off query would compute and not return is refused, not dropped.
    with pytest.raises(kdet.Error, match="collide: results_to_host=false keeps the pairs on the device"):
        kdet.collide(octopus, octopus, results_to_host=False)
    with pytest.raises(kdet.Error, match="collide_self: contacts would be computed and dropped"):
        kdet.collide_self(octopus, contacts=True)
    with pytest.raises(kdet.Error, match="collide: distances would be computed and dropped"):
        kdet.collide(octopus, octopus, margin=0.1, distances=True)


def test_results_kept_on_the_device_need_device_results(octopus):
    detector = kdet.Detector(results_to_host=False)
    detector.add_object(octopus)
    with pytest.raises(kdet.Error, match=r"call detect\(device_results=True\)"):
        detector.detect()
    assert detector.detect(device_results=True).counts.colliding_pairs == 0


class FakeCudaArray:
    """An object that claims to live in GPU memory (it is never read: the checks come first)."""

    def __init__(self, rows: int, typestr: str = "<f4"):
        self.__cuda_array_interface__ = {"shape": (rows, 3), "typestr": typestr, "data": (8, False), "version": 3}


def test_gpu_arrays_need_the_cuda_backend(octopus):
    detector = kdet.Detector()
    ia = detector.add_object(octopus)
    with pytest.raises(kdet.Error, match="positions: a CUDA array needs"):
        detector.set_positions(ia, FakeCudaArray(octopus.num_vertices))
    with pytest.raises(TypeError, match="positions: dtype <i4 is not supported"):
        detector.set_positions(ia, FakeCudaArray(octopus.num_vertices, "<i4"))
    with pytest.raises(TypeError, match="vertices: add_object reads the rest shape on the host"):
        detector.add_object(FakeCudaArray(4), [[0, 1, 2, 3]])
    with pytest.raises(kdet.Error, match="points: a CUDA array needs"):
        detector.locate(FakeCudaArray(3))


def test_numpys_scalars_are_read_as_pythons(octopus):
    # What indexing a NumPy array gives: np.bool_ for every bool argument, NumPy numbers for ids and within.
    is_static = np.array([True, False])
    detector = kdet.Detector()
    ia, ib = detector.add_object(octopus), detector.add_object(octopus)
    detector.set_static(ia, is_static[0])
    assert detector.is_static(ia) and not detector.is_static(ib)
    detector.set_self_collision(np.int64(ib), np.True_)
    detector.set_pair_collision(ia, ib, np.bool_(True))
    assert len(detector.detect(device_results=np.False_).pairs) > 0
    hits = detector.locate(octopus.vertices[:3], object=np.uint8(ia), within=np.float32(0.5))
    assert len(hits.offsets) == 4
    assert kdet.TetMesh(octopus.vertices, octopus.tets, allow_degenerate=np.False_).num_tets == octopus.num_tets
    with pytest.raises(TypeError, match=r"within: expected a float or None, got numpy\.bool_?$"):
        detector.locate(octopus.vertices[:3], within=np.True_)


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda d: d.set_static(0, 0), r"is_static: expected a bool, got int"),
        (lambda d: d.set_self_collision(0, "yes"), r"enabled: expected a bool, got str"),
        (lambda d: d.set_pair_collision(0, 1.0, True), r"b: expected an int, got float"),
        (lambda d: d.set_collision_filter(0, 1.0, 1), r"group: expected an int, got float"),
        (lambda d: d.set_self_exclusion_rings(0, "2"), r"rings: expected an int, got str"),
        (lambda d: d.exclude_rest_contacts(0, "1"), r"other: expected an int, got str"),
        (lambda d: d.set_positions(np.float64(0), np.zeros((3, 3))), r"object: expected an int, got numpy\.float64"),
        (lambda d: d.is_static(True), r"object: expected an int, got bool"),
        (lambda d: d.detect(device_results=1), r"device_results: expected a bool, got int"),
        (lambda d: d.locate(np.zeros((1, 3)), device_results="no"), r"device_results: expected a bool, got str"),
        (lambda d: kdet.add_scene_objects(d, kdet.open_scene("procedural", tets=200, frames=2), 1),
         r"self_collision: expected a bool or 'scene', got int"),
        (lambda d: kdet.open_scene("procedural", frames=2.5), r"frames: expected an int, got float"),
    ],
)
def test_a_wrong_type_is_one_line_naming_the_argument(octopus, call, message):
    # nanobind's own mismatch lists every signature over several lines; kdet reads its scalars itself
    # (None is still nanobind's to refuse, before any reading).
    detector = kdet.Detector()
    detector.add_object(octopus)
    detector.add_object(octopus)
    with pytest.raises(TypeError, match=f"^{message}$"):
        call(detector)


def test_an_int_beyond_64_bits_is_refused_naming_the_argument(octopus):
    detector = kdet.Detector()
    detector.add_object(octopus)
    with pytest.raises(kdet.Error, match=r"^object: 18446744073709551616 is beyond a 64-bit integer$"):
        detector.set_positions(2**64, octopus.vertices)
    with pytest.raises(kdet.Error, match=r"^rings: 4294967296 is beyond a 32-bit integer$"):
        detector.set_self_exclusion_rings(0, 2**32)
    with pytest.raises(kdet.Error, match=r"^rings: 18446744073709551616 is beyond a 32-bit integer$"):
        detector.set_self_exclusion_rings(0, 2**64)


def pairs_with(a: kdet.TetMesh, b_vertices, b_tets) -> np.ndarray:
    detector = kdet.Detector()
    detector.add_object(a)
    ib = detector.add_object(b_vertices, b_tets)
    first = detector.detect().pairs
    detector.set_positions(ib, b_vertices)  # the same positions again, through set_positions
    np.testing.assert_array_equal(detector.detect().pairs, first)
    return first


def test_every_layout_and_dtype_gives_the_same_pairs(octopus, other):
    expected = kdet.collide(octopus, other)
    assert len(expected) > 100
    v, t = other.vertices, other.tets
    wide = np.zeros((len(v), 7))
    wide[:, 2:5] = v
    reversed_rows = np.ascontiguousarray(v[::-1])
    layouts = {
        "float64": (v, t),
        "float32": (v.astype(np.float32), t),
        "fortran": (np.asfortranarray(v), np.asfortranarray(t)),
        "column slice": (wide[:, 2:5], t.astype(np.int64)),
        "every other row": (np.repeat(v, 2, axis=0)[::2], np.repeat(t, 2, axis=0)[::2].astype(np.int32)),
        "negative strides": (reversed_rows[::-1], t[:, ::-1][:, ::-1]),
        "transposed": (np.ascontiguousarray(v.T).T, np.ascontiguousarray(t.T).T.astype(np.uint16 if len(v) < 65536 else np.uint32)),
        "read-only": (np.lib.stride_tricks.as_strided(v, writeable=False), t),
        "big-endian": (v.astype(">f8"), t.astype(">i4")),
        "lists": (v.tolist(), t.tolist()),
    }
    for name, (vertices, tets) in layouts.items():
        pairs = pairs_with(octopus, vertices, tets)
        np.testing.assert_array_equal(pairs[:, [1, 3]], expected, err_msg=name)
        # The mesh class reads the same layouts.
        np.testing.assert_array_equal(kdet.collide(octopus, (vertices, tets)), expected, err_msg=name)


def test_a_single_uint32_tet_is_read_through_its_column_stride():
    # One row is read in place only where its columns are adjacent; any other stride is gathered.
    vertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]
    every_other_column = np.array([[0, 9, 1, 9, 2, 9, 3, 9]], dtype=np.uint32)[:, ::2]
    reversed_columns = np.array([[3, 2, 1, 0]], dtype=np.uint32)[:, ::-1]
    for name, tets in {"every other column": every_other_column, "reversed columns": reversed_columns}.items():
        assert kdet.TetMesh(vertices, tets).tets.tolist() == [[0, 1, 2, 3]], name


def test_mesh_arrays_are_views_of_the_mesh(octopus):
    mesh = kdet.TetMesh(octopus.vertices, octopus.tets)
    assert mesh.vertices.dtype == np.float64 and mesh.vertices.shape == (452, 3) and not mesh.vertices.flags.owndata
    assert mesh.tets.dtype == np.uint32 and mesh.tets.shape == (1140, 4)
    assert np.shares_memory(mesh.vertices, mesh.vertices)
    view = mesh.vertices
    view[0, 0] += 1.0
    assert mesh.vertices[0, 0] == view[0, 0]  # one memory: the change shows through a new view
    del mesh
    assert view[0, 0] == octopus.vertices[0, 0] + 1.0  # the view keeps the mesh alive
