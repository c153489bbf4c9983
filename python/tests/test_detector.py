"""The frame-by-frame Detector: moving objects, switches, flags, results that outlive the next frame,
results in the backend's memory through DLPack, the GIL released during detect(), and the stubs."""

from __future__ import annotations

import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import kdet
from helpers import extent, moved


@pytest.fixture(scope="module")
def octopus(models: Path) -> kdet.TetMesh:
    return kdet.read_tet_mesh(models / "octopus-low.mesh")


def test_frames_follow_the_positions(octopus):
    detector = kdet.Detector()
    ia = detector.add_object(octopus)
    ib = detector.add_object(octopus.vertices + [10.0, 0.0, 0.0], octopus.tets)
    assert (ia, ib) == (0, 1) and detector.object_count == 2 and detector.tet_count(ib) == octopus.num_tets
    far = detector.detect()
    assert far.pairs.shape == (0, 4) and not far.colliding[0].any()
    shift = (0.1 * extent(octopus), 0.0, 0.0)
    near_mesh = moved(octopus, 0.3, shift)
    detector.set_positions(ib, near_mesh.vertices.astype(np.float32))
    near = detector.detect()
    np.testing.assert_array_equal(near.pairs[:, [1, 3]], kdet.collide(octopus, near_mesh))
    assert np.all(near.pairs[:, 0] == ia) and np.all(near.pairs[:, 2] == ib)
    # Flags: a tet is flagged exactly when it is in a pair.
    for obj, column in ((ia, 1), (ib, 3)):
        flags = near.colliding[obj]
        assert flags.dtype == np.bool_ and flags.shape == (octopus.num_tets,)
        np.testing.assert_array_equal(np.flatnonzero(flags), np.unique(near.pairs[:, column]))
    assert near.counts.colliding_pairs == len(near.pairs)
    assert near.counts.colliding_tets == sum(int(f.sum()) for f in near.colliding)
    assert near.times.total > 0 and near.memory_bytes >= near.grid_bytes + near.candidate_bytes > 0
    # A result stays valid after the next frame.
    kept = near.pairs.copy()
    detector.set_positions(ib, octopus.vertices + [10.0, 0.0, 0.0])
    assert len(detector.detect().pairs) == 0
    np.testing.assert_array_equal(near.pairs, kept)


def test_switches(octopus):
    other = moved(octopus, 0.3, (0.1 * extent(octopus), 0.0, 0.0))
    detector = kdet.Detector()
    ia, ib = detector.add_object(octopus), detector.add_object(other)
    assert len(detector.detect().pairs) > 0
    detector.set_pair_collision(ia, ib, False)
    assert len(detector.detect().pairs) == 0
    # One object made of both meshes collides with itself; its own adjacent tets are never reported.
    both = detector.add_object(np.vstack([octopus.vertices, other.vertices]), np.vstack([octopus.tets, other.tets + 452]))
    detector.set_pair_collision(ia, both, False)
    detector.set_pair_collision(ib, both, False)
    assert len(detector.detect().pairs) == 0
    detector.set_self_collision(both)
    pairs = detector.detect().pairs
    assert np.all(pairs[:, 0] == both) and np.all(pairs[:, 2] == both)
    np.testing.assert_array_equal(pairs[:, [1, 3]], kdet.collide_self((np.vstack([octopus.vertices, other.vertices]),
                                                                        np.vstack([octopus.tets, other.tets + 452]))))
    detector.set_self_collision(both, False)
    assert len(detector.detect().pairs) == 0


def test_device_results_on_the_cpu_backend_are_dlpack_arrays(octopus):
    other = moved(octopus, 0.3, (0.1 * extent(octopus), 0.0, 0.0))
    detector = kdet.Detector(contacts=True, results_to_host=False)
    ia, ib = detector.add_object(octopus), detector.add_object(other)
    result = detector.detect(device_results=True)
    assert result.pair_keys.__dlpack_device__() == (1, 0)  # kDLCPU
    keys = np.from_dlpack(result.pair_keys)
    assert keys.dtype == np.uint64 and len(keys) == result.counts.colliding_pairs > 0
    expected = kdet.collide(octopus, other)
    np.testing.assert_array_equal(keys >> np.uint64(32), expected[:, 0] + detector.first_tet(ia))
    np.testing.assert_array_equal(keys & np.uint64(0xFFFFFFFF), expected[:, 1] + detector.first_tet(ib))
    colliding = np.from_dlpack(result.colliding)
    assert colliding.shape == (2 * octopus.num_tets,)
    assert set(np.flatnonzero(colliding)) == set(expected[:, 0]) | set(expected[:, 1] + octopus.num_tets)
    assert np.from_dlpack(result.contacts).shape == (len(keys), 4)


def test_detect_async_then_finish_gives_detect_s_result_with_one_wait(octopus):
    other = moved(octopus, 0.3, (0.1 * extent(octopus), 0.0, 0.0))
    detector, reference = kdet.Detector(), kdet.Detector()
    for d in (detector, reference):
        d.add_object(octopus)
        d.add_object(other)
    detector.detect()  # the first frame sizes the buffers
    expected = reference.detect()
    detector.detect_async()
    result = detector.finish()
    np.testing.assert_array_equal(result.pairs, expected.pairs)
    assert result.counts.host_waits == 1
    device_detector = kdet.Detector(results_to_host=False)
    device_detector.add_object(octopus)
    device_detector.add_object(other)
    device_detector.detect_async()
    keys = np.from_dlpack(device_detector.finish(device_results=True).pair_keys)
    assert len(keys) == len(expected.pairs) > 0
    with pytest.raises(kdet.Error, match="finish: this detector keeps its results on the device"):
        device_detector.finish()


def test_detect_releases_the_gil(models):
    bunny = kdet.read_tet_mesh(models / "bunny.mesh")
    detector = kdet.Detector(threads=1)
    detector.add_object(bunny)
    detector.add_object(moved(bunny, 0.4, (0.05 * extent(bunny), 0.0, 0.0)))
    window: list[float] = []

    def detect() -> None:
        window.append(time.perf_counter())
        detector.detect()
        window.append(time.perf_counter())

    ticks = []
    interval = sys.getswitchinterval()
    sys.setswitchinterval(0.0005)
    try:
        worker = threading.Thread(target=detect)
        worker.start()
        while worker.is_alive():
            ticks.append(time.perf_counter())
        worker.join()
    finally:
        sys.setswitchinterval(interval)
    begin, end = window
    # With the GIL held for the whole call this thread could not run inside it at all; give the call's
    # start and end a margin far above the switch interval.
    middle = [t for t in ticks if begin + 0.25 * (end - begin) < t < end - 0.25 * (end - begin)]
    assert end - begin > 0.02, "the frame is too small to tell"
    assert len(middle) > 10


def test_detectors_in_threads_agree(octopus):
    other = moved(octopus, 0.3, (0.1 * extent(octopus), 0.0, 0.0))
    expected = kdet.collide(octopus, other)
    results = []

    def work() -> None:
        results.append(kdet.collide(octopus, other, threads=1))

    threads = [threading.Thread(target=work) for _ in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert len(results) == 4
    for pairs in results:
        np.testing.assert_array_equal(pairs, expected)


def test_bucket_capacity_is_chosen_or_kept(octopus):
    # 0 (the default) lets each frame's grid plan choose the ids per bucket; a number is kept.
    counts = {}
    for capacity in (0, 32):
        detector = kdet.Detector(bucket_capacity=capacity)
        detector.add_object(octopus)
        detector.add_object(moved(octopus, 0.3, (0.1 * extent(octopus), 0.0, 0.0)))
        counts[capacity] = detector.detect().counts
    assert counts[0].grid_bucket_capacity in (4, 8, 16, 32)
    assert counts[32].grid_bucket_capacity == 32
    assert counts[0].colliding_pairs == counts[32].colliding_pairs > 0


def test_reprs_and_options():
    detector = kdet.Detector(method="GPU", test="sat-mtv", threads=2)
    assert detector.options["method"] == "brute_force_loop" and detector.options["test"] == "sat_mtv"
    assert detector.options["threads"] == 2
    assert repr(detector).startswith("Detector(backend='cpu', method='brute_force_loop'")
    assert kdet.version().startswith(kdet.__version__)
    assert isinstance(kdet.cuda_available(), bool)
    assert detector.device_name


def test_type_stubs_ship_with_the_package():
    folder = Path(kdet.__file__).parent
    assert (folder / "py.typed").exists()
    stub = (folder / "_kdet.pyi").read_text()
    for name in ("class Detector", "def set_positions", "class FrameResult", "def read_tet_mesh", "class Error(ValueError)"):
        assert name in stub, name
