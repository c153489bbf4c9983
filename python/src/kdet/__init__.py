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

Two tets collide when their closed sets share a point; tets of one object that share a vertex are
adjacent and never reported. Option names are those of BACKENDS, METHODS, TESTS and HASHES (any
case, '-' or '_'). Bad input raises kdet.Error (a ValueError) with the library's one-line message;
wrong types raise TypeError naming the argument.
"""

from __future__ import annotations

from typing import Any, Tuple, Union

import numpy as np

from ._kdet import (
    BACKENDS,
    HASHES,
    METHODS,
    TESTS,
    Detector,
    DeviceFrameResult,
    Error,
    FrameCounts,
    FrameResult,
    StageTimes,
    TetMesh,
    __version__,
    cuda_available,
    cuda_unavailable_reason,
    from_meshio,
    read_tet_mesh,
    version,
    write_tet_mesh,
)

__all__ = [
    "BACKENDS",
    "HASHES",
    "METHODS",
    "TESTS",
    "Detector",
    "DeviceFrameResult",
    "Error",
    "FrameCounts",
    "FrameResult",
    "StageTimes",
    "TetMesh",
    "__version__",
    "collide",
    "collide_self",
    "cuda_available",
    "cuda_unavailable_reason",
    "from_meshio",
    "read_tet_mesh",
    "version",
    "write_tet_mesh",
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


def _tet_pairs(detector: Detector) -> np.ndarray:
    if detector.options["method"] == "kdet_no_pairs":
        raise Error("method 'kdet_no_pairs' only flags colliding tets and builds no pairs; use Detector.detect().colliding")
    # Columns 1 and 3 of (object_a, tet_a, object_b, tet_b): the tet indices in each mesh's own order.
    return np.ascontiguousarray(detector.detect().pairs[:, [1, 3]])


def collide(a: MeshLike, b: MeshLike, **options: Any) -> np.ndarray:
    """All colliding pairs (i in a, j in b) as a (k, 2) uint32 array, sorted.

    options are Detector's keyword arguments (backend, method, test, hash, threads, ...)."""
    mesh_a, mesh_b = _as_tet_mesh(a, "a"), _as_tet_mesh(b, "b")
    detector = Detector(**options)
    detector.add_object(mesh_a)
    detector.add_object(mesh_b)
    return _tet_pairs(detector)


def collide_self(mesh: MeshLike, **options: Any) -> np.ndarray:
    """All colliding pairs i < j inside one mesh (self-collision) as a (k, 2) uint32 array, sorted.

    Tets that share a vertex are adjacent and never reported. options are Detector's keyword arguments."""
    tet_mesh = _as_tet_mesh(mesh, "mesh")
    detector = Detector(**options)
    detector.set_self_collision(detector.add_object(tet_mesh))
    return _tet_pairs(detector)

