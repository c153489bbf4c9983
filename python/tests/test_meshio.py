"""meshio interoperability: TetMesh.to_meshio / kdet.from_meshio and files written by one, read by the other."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import kdet

meshio = pytest.importorskip("meshio", reason="meshio is optional; scripts/test.sh installs it")


@pytest.fixture(scope="module")
def hand(models: Path) -> kdet.TetMesh:
    return kdet.read_tet_mesh(models / "hand.mesh")


def assert_same(a: kdet.TetMesh, b: kdet.TetMesh) -> None:
    np.testing.assert_array_equal(a.vertices, b.vertices)
    np.testing.assert_array_equal(a.tets, b.tets)


def test_round_trip_in_memory(hand):
    mesh = hand.to_meshio()
    assert isinstance(mesh, meshio.Mesh) and mesh.cells[0].type == "tetra" and mesh.cells[0].data.dtype == np.int64
    np.testing.assert_array_equal(mesh.points, hand.vertices)
    assert not np.shares_memory(mesh.points, hand.vertices)
    assert_same(kdet.from_meshio(mesh), hand)


# meshio's own format names: ".msh" alone could also mean ANSYS.
FORMATS = {".vtu": "vtu", ".vtk": "vtk", ".msh": "gmsh", ".mesh": "medit"}


@pytest.mark.parametrize("suffix", FORMATS)
def test_round_trip_through_meshio_files(hand, tmp_path, suffix):
    path = tmp_path / f"hand{suffix}"
    meshio.write(path, hand.to_meshio(), file_format=FORMATS[suffix])
    assert_same(kdet.from_meshio(meshio.read(path)), hand)


@pytest.mark.parametrize("suffix", [".vtk", ".msh", ".mesh"])
def test_kdet_and_meshio_read_each_others_files(hand, tmp_path, suffix):
    written_by_kdet = tmp_path / f"kdet{suffix}"
    kdet.write_tet_mesh(hand, written_by_kdet)
    assert_same(kdet.from_meshio(meshio.read(written_by_kdet)), hand)
    written_by_meshio = tmp_path / f"meshio{suffix}"
    meshio.write(written_by_meshio, hand.to_meshio(), file_format=FORMATS[suffix])
    assert_same(kdet.read_tet_mesh(written_by_meshio), hand)


def test_collide_takes_meshio_meshes(hand):
    other = kdet.TetMesh(hand.vertices + [0.05, 0.0, 0.0], hand.tets)
    np.testing.assert_array_equal(kdet.collide(hand.to_meshio(), other.to_meshio()), kdet.collide(hand, other))


def test_mixed_cells_keep_the_tets_only():
    points = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1], [0.5, 0.5, 0.5]], dtype=float)
    mesh = meshio.Mesh(points, [("triangle", [[0, 1, 2]]), ("tetra", [[0, 1, 2, 3]]), ("tetra10", [[1, 2, 3, 4, 0, 0, 0, 0, 0, 0]])])
    tets = kdet.from_meshio(mesh)
    np.testing.assert_array_equal(tets.tets, [[0, 1, 2, 3], [1, 2, 3, 4]])
    with pytest.raises(kdet.Error, match=r"from_meshio: the mesh has no tetra cells \(it has: triangle\)"):
        kdet.from_meshio(meshio.Mesh(points, [("triangle", [[0, 1, 2]])]))
    with pytest.raises(kdet.Error, match=r"mesh.points: expected an array of shape \(n, 3\)"):
        kdet.from_meshio(meshio.Mesh(points[:, :2], [("tetra", [[0, 1, 2, 3]])]))
    with pytest.raises(TypeError, match="mesh: expected a meshio.Mesh, got int"):
        kdet.from_meshio(3)
