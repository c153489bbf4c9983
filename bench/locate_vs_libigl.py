"""Point location: kdet.locate against libigl's in_element with its AABB tree (PyPI libigl) and, when
VTK is installed (PyPI vtk), VTK's vtkStaticCellLocator::FindCell, on one CPU, same mesh and points;
the answers are compared where both define one.

    python bench/locate_vs_libigl.py --cubes 55 --points 1000000 --threads 2

The mesh is a box of cubes split into six tets each (about 6 * cubes^3 tets), its vertices moved at
random by up to a fifth of a cube (no tet inverts), so that points rarely fall on a face; the points
are uniform in the box. libigl and VTK return one containing tet per point (or -1); kdet every tet
whose closed set holds the point: each peer's answer must be among kdet's, and kdet must find none
where the peer finds none, up to points the peer's floating-point test calls the other way (counted,
not failed). VTK runs FindCell per point in C++ through vtkProbeFilter, with a vtkStaticCellLocator as
its locator, probing a cell array of tet ids (one thread: VTK's SMP back end is set to sequential).
run-locate-vs-libigl.sh installs the peers into a virtual environment and runs this.
"""

import argparse
import time

import numpy as np

import igl
import kdet

try:
    import vtk
    from vtk.util import numpy_support
except ImportError:
    vtk = None


def box_mesh(n, rng):
    g = np.arange(n + 1, dtype=np.float64)
    x, y, z = np.meshgrid(g, g, g, indexing="ij")
    vertices = np.stack([x.ravel(), y.ravel(), z.ravel()], axis=1)
    inner = np.all((vertices > 0) & (vertices < n), axis=1)
    vertices[inner] += rng.uniform(-0.2, 0.2, size=(int(inner.sum()), 3))
    vertices /= n
    index = np.arange((n + 1) ** 3).reshape(n + 1, n + 1, n + 1)
    c = np.stack(np.meshgrid(np.arange(n), np.arange(n), np.arange(n), indexing="ij"), axis=-1).reshape(-1, 3)
    tets = []
    for path in [(0, 1, 2), (0, 2, 1), (1, 0, 2), (1, 2, 0), (2, 0, 1), (2, 1, 0)]:
        corner = c.copy()
        tet = [index[corner[:, 0], corner[:, 1], corner[:, 2]]]
        for axis in path:
            corner[:, axis] += 1
            tet.append(index[corner[:, 0], corner[:, 1], corner[:, 2]])
        tets.append(np.stack(tet, axis=1))
    return vertices, np.concatenate(tets).astype(np.int64)


def best_of(runs, f):
    best, out = float("inf"), None
    for _ in range(runs):
        start = time.perf_counter()
        out = f()
        best = min(best, time.perf_counter() - start)
    return best, out


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--cubes", type=int, default=55)
    parser.add_argument("--points", type=int, default=1_000_000)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--runs", type=int, default=3)
    args = parser.parse_args()
    rng = np.random.default_rng(1)
    vertices, tets = box_mesh(args.cubes, rng)
    # Both get the float32 values kdet locates.
    vertices = vertices.astype(np.float32).astype(np.float64)
    points = rng.uniform(0, 1, size=(args.points, 3)).astype(np.float32).astype(np.float64)
    mesh = kdet.TetMesh(vertices, tets.astype(np.uint32))
    print(f"{len(tets)} tets, {len(points)} points, kdet on {args.threads} threads, libigl on one")

    t_kdet, r = best_of(args.runs, lambda: kdet.locate(mesh, points, threads=args.threads))

    def igl_locate():
        tree = igl.AABB()
        tree.init(vertices, tets)
        return igl.in_element(vertices, tets, points, tree)

    t_igl, found = best_of(args.runs, igl_locate)

    counts = np.diff(r.offsets.astype(np.int64))
    held = counts > 0
    print(f"kdet.locate       {t_kdet * 1e3:9.1f} ms  (points held: {int(held.sum())}, hits {len(r.tets)})")
    report("igl AABB+in_element", t_igl, t_kdet, found, r, held)
    if vtk is None:
        print("VTK: not installed (pip install vtk)")
        return
    t_vtk, found_vtk = best_of(args.runs, lambda: vtk_locate(vertices, tets, points))
    report("vtk StaticCellLocator", t_vtk, t_kdet, found_vtk, r, held)


def report(name, t_peer, t_kdet, found, r, held):
    peer_held = found >= 0
    mismatched = 0
    for p in np.nonzero(peer_held)[0]:
        if found[p] not in r.tets[r.offsets[p]:r.offsets[p + 1]]:
            mismatched += 1
    only_kdet = int(np.sum(held & ~peer_held))
    print(f"{name:22s}{t_peer * 1e3:9.1f} ms  (points held: {int(peer_held.sum())}); ratio peer/kdet {t_peer / t_kdet:.2f}; "
          f"its tet not among kdet's: {mismatched}; held by kdet only: {only_kdet}")


def vtk_locate(vertices, tets, points):
    """The tet VTK's static cell locator finds for each point (FindCell, through a probe), or -1."""
    vtk.vtkSMPTools.SetBackend("Sequential")
    grid = vtk.vtkUnstructuredGrid()
    vtk_points = vtk.vtkPoints()
    vtk_points.SetData(numpy_support.numpy_to_vtk(vertices, deep=True))
    grid.SetPoints(vtk_points)
    cells = vtk.vtkCellArray()
    offsets = np.arange(0, 4 * len(tets) + 1, 4, dtype=np.int64)
    cells.SetData(numpy_support.numpy_to_vtkIdTypeArray(offsets, deep=True),
                  numpy_support.numpy_to_vtkIdTypeArray(tets.astype(np.int64).ravel(), deep=True))
    grid.SetCells(vtk.VTK_TETRA, cells)
    ids = numpy_support.numpy_to_vtk(np.arange(len(tets), dtype=np.float64), deep=True)
    ids.SetName("tet")
    grid.GetCellData().AddArray(ids)
    source = vtk.vtkPolyData()
    query = vtk.vtkPoints()
    query.SetData(numpy_support.numpy_to_vtk(points, deep=True))
    source.SetPoints(query)
    probe = vtk.vtkProbeFilter()
    probe.SetInputData(source)
    probe.SetSourceData(grid)
    # SetCellLocator replaced SetCellLocatorPrototype in VTK 9.7.
    set_locator = getattr(probe, "SetCellLocator", None) or probe.SetCellLocatorPrototype
    set_locator(vtk.vtkStaticCellLocator())
    probe.PassCellArraysOff()
    probe.Update()
    out = probe.GetOutput().GetPointData()
    tet = numpy_support.vtk_to_numpy(out.GetArray("tet")).astype(np.int64)
    valid = numpy_support.vtk_to_numpy(out.GetArray(probe.GetValidPointMaskArrayName())).astype(bool)
    return np.where(valid, tet, -1)


if __name__ == "__main__":
    main()
