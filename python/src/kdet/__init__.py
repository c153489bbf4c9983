"""kdet: every colliding pair of tetrahedra between deforming tet meshes, and inside one.

One-off queries::

    import kdet
    a = kdet.read_tet_mesh("bunny.mesh")
    b = kdet.read_tet_mesh("hand.mesh")
    pairs = kdet.collide(a, b)            # (k, 2) uint32: tet of a, tet of b
    inner = kdet.collide_self(a)          # (k, 2) uint32: i < j

Frame by frame (buffers persist between frames)::

    detector = kdet.Detector(method="kdet", test="sat")
    ia, ib = detector.add_object(a), detector.add_object(b)
    for positions in frames:              # (n, 3) float32 or float64, NumPy or GPU arrays
        detector.set_positions(ib, positions)
        result = detector.detect()        # releases the GIL
        result.pairs                      # (k, 4) uint32: object_a, tet_a, object_b, tet_b

The benchmark scenes of `kdet bench` (scene_names(): tearing, heap, drape, ...), played as it plays them::

    scene = kdet.open_scene("tearing", resolution=1)
    for frame, result in kdet.run_scene(scene, self_collision=False):
        len(result.pairs)                 # the CSV's "collision pairs" of `kdet bench tearing`

Two tets collide when their closed sets share a point; tets of one object that share a vertex are
adjacent and never reported. OPTIONS describes every keyword of Detector (and of collide()): its
type, default, choices or range, help, its flags on the command line, and whether locate() reads
it. Names are those of BACKENDS, METHODS, TESTS and HASHES (any case, '-' or '_'). Bad input raises
kdet.Error (a ValueError) with the library's one-line message; wrong types raise TypeError naming
the argument.
"""

from __future__ import annotations

from typing import Any, Tuple, Union

import numpy as np

from . import _kdet
from ._kdet import (
    BACKENDS,
    HASHES,
    METHODS,
    OPTIONS,
    TESTS,
    Detector,
    DeviceFrameResult,
    Error,
    FrameCounts,
    FrameResult,
    LocateResult,
    Scene,
    StageTimes,
    TetMesh,
    __version__,
    add_scene_objects,
    cuda_available,
    cuda_unavailable_reason,
    from_meshio,
    open_scene,
    read_points,
    read_surface,
    read_tet_mesh,
    scene_names,
    validate_tet_mesh,
    version,
    write_gmsh,
    write_recording,
    write_tet_mesh,
    write_vtk,
)
from ._scenes import run_scene

__all__ = [
    "BACKENDS",
    "HASHES",
    "METHODS",
    "OPTIONS",
    "TESTS",
    "Detector",
    "DeviceFrameResult",
    "Error",
    "FrameCounts",
    "FrameResult",
    "LocateResult",
    "Scene",
    "StageTimes",
    "TetMesh",
    "__version__",
    "add_scene_objects",
    "collide",
    "collide_self",
    "cuda_available",
    "cuda_unavailable_reason",
    "from_meshio",
    "locate",
    "open_scene",
    "read_points",
    "read_surface",
    "read_tet_mesh",
    "run_scene",
    "scene_names",
    "validate_tet_mesh",
    "version",
    "write_gmsh",
    "write_recording",
    "write_tet_mesh",
    "write_vtk",
]

# What collide() and collide_self() take as a mesh: a TetMesh, a meshio.Mesh, or (vertices, tets).
MeshLike = Union[TetMesh, Any, Tuple[Any, Any]]


def _as_tet_mesh(mesh: MeshLike, name: str) -> TetMesh:
    if isinstance(mesh, TetMesh):
        return mesh
    if hasattr(mesh, "points") and hasattr(mesh, "cells"):
        return from_meshio(mesh)
    if isinstance(mesh, (tuple, list)) and len(mesh) == 2:
        return TetMesh(mesh[0], mesh[1])
    raise TypeError(f"{name}: expected a kdet.TetMesh, a meshio.Mesh or a (vertices, tets) pair, got {type(mesh).__name__}")


def collide(a: MeshLike, b: MeshLike, **options: Any) -> np.ndarray:
    """All colliding pairs (i in a, j in b) as a (k, 2) uint32 array, sorted.

    options are Detector's keyword arguments (backend, method, test, hash, threads, ...)."""
    return _kdet.collide(_as_tet_mesh(a, "a"), _as_tet_mesh(b, "b"), **options)


def collide_self(mesh: MeshLike, **options: Any) -> np.ndarray:
    """All colliding pairs i < j inside one mesh (self-collision) as a (k, 2) uint32 array, sorted.

    Tets that share a vertex are adjacent and never reported. options are Detector's keyword arguments."""
    return _kdet.collide_self(_as_tet_mesh(mesh, "mesh"), **options)



def locate(mesh: MeshLike, points: Any, within: Union[float, None] = None, **options: Any) -> LocateResult:
    """For each point ((n, 3) float32 or float64), every tet of mesh whose closed set holds it, with its
    barycentric coordinates, decided exactly for the float32 coordinates; with within=d a point that no
    tet holds gets the nearest tet at distance <= d. The hits of point p are rows
    offsets[p]:offsets[p + 1] of the result's arrays (tets, barycentrics, closest_points, distances).

    options are the keyword arguments of Detector that point location reads, those OPTIONS marks
    "locate": {keywords}. A detection frame's (margin, method, ...) raise a TypeError."""
    return _kdet.locate(_as_tet_mesh(mesh, "mesh"), points, within, **options)


if locate.__doc__:  # None under python -OO
    locate.__doc__ = locate.__doc__.format(keywords=", ".join(n for n, entry in OPTIONS.items() if entry["locate"]))
