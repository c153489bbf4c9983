"""The file functions besides read_tet_mesh and write_tet_mesh: surfaces, query points, the Gmsh and VTK
writers with their versions, and validate_tet_mesh for a mesh changed in place."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import kdet


@pytest.fixture(scope="module")
def octopus(models: Path) -> kdet.TetMesh:
    return kdet.read_tet_mesh(models / "octopus-low.mesh")


def obj_by_hand(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """The v and f records of an OBJ file, polygons fanned from their first vertex (1-based, a/b/c forms)."""
    vertices, triangles = [], []
    for line in path.read_text().splitlines():
        fields = line.split()
        if fields[:1] == ["v"]:
            vertices.append([float(x) for x in fields[1:4]])
        elif fields[:1] == ["f"]:
            corners = [int(f.split("/")[0]) - 1 for f in fields[1:]]
            triangles += [[corners[0], corners[k], corners[k + 1]] for k in range(1, len(corners) - 1)]
    return np.array(vertices), np.array(triangles)


def test_read_surface_gives_an_objs_vertices_and_triangles(models: Path):
    vertices, triangles = kdet.read_surface(models / "stanford-bunny.obj")
    expected_vertices, expected_triangles = obj_by_hand(models / "stanford-bunny.obj")
    assert vertices.dtype == np.float64 and triangles.dtype == np.uint32
    np.testing.assert_array_equal(vertices, expected_vertices)
    np.testing.assert_array_equal(triangles, expected_triangles)


def test_read_surface_names_the_file_and_line(tmp_path: Path):
    path = tmp_path / "bad.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n")
    with pytest.raises(kdet.Error, match=rf"^{path}:4: "):
        kdet.read_surface(path)
    with pytest.raises(kdet.Error, match="cannot open"):
        kdet.read_surface(tmp_path / "missing.off")


def test_read_points_reads_text_and_mesh_files(octopus, models: Path, tmp_path: Path):
    text = tmp_path / "points.txt"
    text.write_text("# x y z\n0 0 0\n1.5 -2 3e-3  # a comment\n\n")
    np.testing.assert_array_equal(kdet.read_points(text), [[0, 0, 0], [1.5, -2, 3e-3]])
    np.testing.assert_array_equal(kdet.read_points(models / "octopus-low.mesh"), octopus.vertices)
    text.write_text("0 0 0\n1 2\n")
    with pytest.raises(kdet.Error, match=rf"^{text}:2: "):
        kdet.read_points(text)


@pytest.mark.parametrize("binary", [False, True])
@pytest.mark.parametrize(
    "write, version, header, suffix",
    [
        (kdet.write_gmsh, "4.1", b"$MeshFormat\n4.1", ".msh"),
        (kdet.write_gmsh, "2.2", b"$MeshFormat\n2.2", ".msh"),
        (kdet.write_vtk, "5.1", b"# vtk DataFile Version 5.1", ".vtk"),
        (kdet.write_vtk, "4.2", b"# vtk DataFile Version 4.2", ".vtk"),
    ],
)
def test_the_gmsh_and_vtk_writers_write_each_version_that_reads_back_exactly(
    octopus, tmp_path: Path, write, version, header, suffix, binary
):
    path = tmp_path / f"octopus{suffix}"
    write(octopus, path, version=version, binary=binary)
    assert path.read_bytes().startswith(header)
    again = kdet.read_tet_mesh(path)
    np.testing.assert_array_equal(again.vertices, octopus.vertices)
    np.testing.assert_array_equal(again.tets, octopus.tets)


def test_the_writers_refuse_a_version_they_do_not_write(octopus, tmp_path: Path):
    with pytest.raises(kdet.Error, match=r"^version: Gmsh MSH '3.0' is not written \(2.2 or 4.1\)$"):
        kdet.write_gmsh(octopus, tmp_path / "a.msh", version="3.0")
    with pytest.raises(kdet.Error, match=r"^version: legacy VTK '2.0' is not written \(4.2 or 5.1\)$"):
        kdet.write_vtk(octopus, tmp_path / "a.vtk", version="2.0")


def test_validate_tet_mesh_checks_a_mesh_changed_in_place(octopus):
    mesh = kdet.TetMesh(octopus.vertices, octopus.tets)
    kdet.validate_tet_mesh(mesh)
    mesh.vertices[3, 1] = np.inf
    with pytest.raises(kdet.Error, match=r"^simulation: vertex 3: coordinate y is not finite"):
        kdet.validate_tet_mesh(mesh, "simulation")
    mesh.vertices[3] = mesh.vertices[mesh.tets[0, 0]]
    mesh.vertices[mesh.tets[0, 1]] = mesh.vertices[mesh.tets[0, 0]]
    with pytest.raises(kdet.Error, match=r"^TetMesh: tet 0: "):
        kdet.validate_tet_mesh(mesh)
    kdet.validate_tet_mesh(mesh, allow_degenerate=True)
