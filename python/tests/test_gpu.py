"""The CUDA backend from Python: positions handed over in GPU memory (__cuda_array_interface__ and
__dlpack__) never pass through the host and give the CPU backend's pairs; detect(device_results=True)
returns DLPack arrays on the GPU. GPU memory is made with the CUDA runtime through ctypes, so no GPU
array library is needed; PyTorch and CuPy are used too when installed. Skipped, with the reason, where
the CUDA backend cannot run."""

from __future__ import annotations

import ctypes
import ctypes.util
from pathlib import Path

import numpy as np
import pytest

import kdet
from helpers import extent, moved

pytestmark = pytest.mark.skipif(not kdet.cuda_available(), reason=f"CUDA backend unavailable: {kdet.cuda_unavailable_reason()}")

HOST_TO_DEVICE, DEVICE_TO_HOST = 1, 2


def cuda_runtime() -> ctypes.CDLL:
    for name in ("libcudart.so", ctypes.util.find_library("cudart"), "libcudart.so.13", "libcudart.so.12"):
        if name:
            try:
                return ctypes.CDLL(name)
            except OSError:
                continue
    pytest.fail("the CUDA backend runs but libcudart cannot be loaded")


class CudaArray:
    """A copy of a host array in GPU memory, seen through __cuda_array_interface__ (strides kept)."""

    def __init__(self, host: np.ndarray):
        self.runtime = cuda_runtime()
        self.pointer = ctypes.c_void_p()
        # Enough memory for the array's whole extent, strides included.
        base = host.base if host.base is not None else host
        span = np.ascontiguousarray(base)
        assert self.runtime.cudaMalloc(ctypes.byref(self.pointer), ctypes.c_size_t(span.nbytes)) == 0
        assert self.runtime.cudaMemcpy(self.pointer, span.ctypes.data_as(ctypes.c_void_p), ctypes.c_size_t(span.nbytes),
                                       HOST_TO_DEVICE) == 0
        offset = host.ctypes.data - base.ctypes.data
        self.__cuda_array_interface__ = {
            "shape": host.shape,
            "typestr": host.dtype.str,
            "data": (self.pointer.value + offset, False),
            "strides": None if host.flags.c_contiguous else host.strides,
            "version": 3,
            "stream": 1,
        }

    def __del__(self):
        self.runtime.cudaFree(self.pointer)


def to_host(array, dtype, shape) -> np.ndarray:
    """Copies a DLPack GPU array of the package to the host through its capsule."""
    assert array.__dlpack_device__()[0] == 2  # kDLCUDA

    class DLTensor(ctypes.Structure):
        _fields_ = [("data", ctypes.c_void_p), ("device_type", ctypes.c_int32), ("device_id", ctypes.c_int32),
                    ("ndim", ctypes.c_int32), ("code", ctypes.c_uint8), ("bits", ctypes.c_uint8),
                    ("lanes", ctypes.c_uint16), ("shape", ctypes.POINTER(ctypes.c_int64)),
                    ("strides", ctypes.POINTER(ctypes.c_int64)), ("byte_offset", ctypes.c_uint64)]

    capsule = array.__dlpack__()
    get = ctypes.pythonapi.PyCapsule_GetPointer
    get.restype, get.argtypes = ctypes.c_void_p, [ctypes.py_object, ctypes.c_char_p]
    tensor = DLTensor.from_address(get(capsule, b"dltensor"))
    host = np.empty(shape, dtype)
    if host.nbytes:
        assert cuda_runtime().cudaMemcpy(host.ctypes.data_as(ctypes.c_void_p), ctypes.c_void_p(tensor.data + tensor.byte_offset),
                                         ctypes.c_size_t(host.nbytes), DEVICE_TO_HOST) == 0
    return host


@pytest.fixture(scope="module")
def scene(models: Path):
    bunny = kdet.read_tet_mesh(models / "bunny.mesh")
    other = moved(bunny, 0.4, (0.05 * extent(bunny), 0.0, 0.0))
    return bunny, other, kdet.collide(bunny, other)


def gpu_detector(bunny: kdet.TetMesh, **options) -> tuple[kdet.Detector, int]:
    detector = kdet.Detector(backend="cuda", **options)
    detector.add_object(bunny)
    return detector, detector.add_object(bunny)


@pytest.mark.parametrize("layout", ["float32", "float64", "float32 column slice", "float64 every other row",
                                    "float64 fortran", "float32 rows reversed"])
def test_gpu_positions_give_the_cpu_pairs(scene, layout):
    bunny, other, expected = scene
    v = other.vertices
    wide = np.zeros((len(v), 5))
    wide[:, 1:4] = v
    host = {
        "float32": v.astype(np.float32),
        "float64": v,
        "float32 column slice": wide.astype(np.float32)[:, 1:4],
        "float64 every other row": np.repeat(v, 2, axis=0)[::2],
        # Views of a C-contiguous array, which CudaArray copies whole.
        "float64 fortran": np.ascontiguousarray(v.T).T,
        "float32 rows reversed": np.ascontiguousarray(v[::-1], dtype=np.float32)[::-1],
    }[layout]
    detector, moving = gpu_detector(bunny)
    device_positions = CudaArray(host)
    detector.set_positions(moving, device_positions)
    np.testing.assert_array_equal(detector.detect().pairs[:, [1, 3]], expected)


def test_the_detector_runs_on_the_callers_stream(scene):
    bunny, other, expected = scene
    runtime = cuda_runtime()
    stream = ctypes.c_void_p()
    assert runtime.cudaStreamCreateWithFlags(ctypes.byref(stream), 1) == 0  # cudaStreamNonBlocking
    try:
        detector, moving = gpu_detector(bunny, cuda_stream=stream.value)
        assert detector.options["cuda_stream"] == stream.value
        # float64 with strides: the library's gather kernel runs too, and must run on that stream.
        for frame in range(3):
            detector.set_positions(moving, CudaArray(np.repeat(other.vertices, 2, axis=0)[::2]))
            np.testing.assert_array_equal(detector.detect().pairs[:, [1, 3]], expected, err_msg=f"frame {frame}")
    finally:
        runtime.cudaStreamDestroy(stream)


def test_device_results_stay_on_the_gpu(scene):
    bunny, other, expected = scene
    detector, moving = gpu_detector(bunny, contacts=True, results_to_host=False)
    detector.set_positions(moving, CudaArray(other.vertices.astype(np.float32)))
    result = detector.detect(device_results=True)
    keys = to_host(result.pair_keys, np.uint64, (result.counts.colliding_pairs,))
    np.testing.assert_array_equal(keys >> np.uint64(32), expected[:, 0] + detector.first_tet(0))
    np.testing.assert_array_equal(keys & np.uint64(0xFFFFFFFF), expected[:, 1] + detector.first_tet(moving))
    contacts = to_host(result.contacts, np.float32, (len(keys), 4))
    np.testing.assert_allclose(np.linalg.norm(contacts[:, 1:], axis=1), 1.0, rtol=1e-5)


def test_non_finite_gpu_positions_are_rejected(scene):
    bunny, other, _ = scene
    detector, moving = gpu_detector(bunny)
    positions = other.vertices.astype(np.float32)
    positions[5, 1] = np.nan
    before = detector.detect().pairs
    detector.set_positions(moving, CudaArray(positions))  # checked on the GPU by the next frame
    with pytest.raises(kdet.Error, match="vertex 5 of the positions given on the device has a non-finite"):
        detector.detect()
    np.testing.assert_array_equal(detector.detect().pairs, before)


def test_torch_and_cupy_arrays(scene):
    bunny, other, expected = scene
    libraries = []
    try:
        import torch

        libraries.append(lambda a: torch.from_numpy(a).cuda())
    except ImportError:
        pass
    try:
        import cupy

        libraries.append(cupy.asarray)
    except ImportError:
        pass
    if not libraries:
        pytest.skip("neither PyTorch nor CuPy is installed")
    for to_gpu in libraries:
        detector, moving = gpu_detector(bunny)
        detector.set_positions(moving, to_gpu(np.ascontiguousarray(other.vertices)))
        np.testing.assert_array_equal(detector.detect().pairs[:, [1, 3]], expected)
