"""The package reports the same pairs as the C++ command `kdet collide` on the models, for every
method, narrow-phase test and hash (brute force on the small model only), and self-collisions."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import numpy as np
import pytest

import kdet
from helpers import cli_pairs, extent, moved, union

PAIR_METHODS = [m for m in kdet.METHODS if m != "kdet_no_pairs"]


@pytest.fixture(scope="module")
def octopus_files(models: Path, tmp_path_factory: pytest.TempPathFactory) -> list[Path]:
    """The octopus and a turned, shifted copy, written as files that both the command and Python read."""
    folder = tmp_path_factory.mktemp("octopus")
    octopus = kdet.read_tet_mesh(models / "octopus-low.mesh")
    other = moved(octopus, 0.3, (0.1 * extent(octopus), 0.0, 0.0))
    kdet.write_tet_mesh(other, folder / "moved.mesh")
    kdet.write_tet_mesh(union(octopus, other), folder / "both.vtk", binary=True)
    return [models / "octopus-low.mesh", folder / "moved.mesh", folder / "both.vtk"]


def test_the_names_are_the_library_table():
    assert "kdet" in kdet.METHODS and "sat" in kdet.TESTS and "djb2" in kdet.HASHES and "cpu" in kdet.BACKENDS
    assert len(set(kdet.METHODS + kdet.TESTS + kdet.HASHES + kdet.BACKENDS)) == sum(
        map(len, (kdet.METHODS, kdet.TESTS, kdet.HASHES, kdet.BACKENDS))
    )


@pytest.mark.parametrize("test", kdet.TESTS)
def test_every_method_and_hash_matches_the_command(cli, tmp_path, octopus_files, test):
    a_file, b_file, _ = octopus_files
    expected = cli_pairs(cli, tmp_path, [a_file, b_file], "--test", test)
    assert len(expected) > 100
    a, b = kdet.read_tet_mesh(a_file), kdet.read_tet_mesh(b_file)
    for method in PAIR_METHODS:
        for hash in kdet.HASHES:
            pairs = kdet.collide(a, b, method=method, test=test, hash=hash)
            assert pairs.dtype == np.uint32 and pairs.shape == expected.shape, (method, hash)
            np.testing.assert_array_equal(pairs, expected, err_msg=f"{method} {hash}")
    # The thesis's old method builds no pairs but flags the same tets.
    detector = kdet.Detector(method="kdet_no_pairs", test=test)
    detector.add_object(a)
    detector.add_object(b)
    flags = detector.detect().colliding
    np.testing.assert_array_equal(np.flatnonzero(flags[0]), np.unique(expected[:, 0]))
    np.testing.assert_array_equal(np.flatnonzero(flags[1]), np.unique(expected[:, 1]))


@pytest.mark.parametrize("test", kdet.TESTS)
def test_self_collision_matches_the_command(cli, tmp_path, octopus_files, test):
    both = octopus_files[2]
    expected = cli_pairs(cli, tmp_path, [both], "--self", "--test", test)
    mesh = kdet.read_tet_mesh(both)
    assert len(expected) > 100 and np.all(expected[:, 0] < expected[:, 1])
    for method in ("kdet", "brute_force_pairs"):
        np.testing.assert_array_equal(kdet.collide_self(mesh, method=method, test=test), expected, err_msg=method)


@pytest.mark.parametrize(
    "model, other, options",
    [
        ("bunny.mesh", "bunny.mesh", {}),
        ("hand.mesh", "hand.msh", {"test": "gjk", "hash": "morton", "threads": 1}),
    ],
)
def test_larger_models_match_the_command(cli, models, tmp_path, model, other, options):
    a = kdet.read_tet_mesh(models / model)
    b = moved(kdet.read_tet_mesh(models / other), 0.5, (0.05 * extent(a), 0.02 * extent(a), 0.0))
    kdet.write_tet_mesh(b, tmp_path / "b.msh", binary=True)
    flags = [f"--{name}={value}" for name, value in options.items()]
    expected = cli_pairs(cli, tmp_path, [models / model, tmp_path / "b.msh"], *flags)
    assert len(expected) > 1000
    np.testing.assert_array_equal(kdet.collide(a, kdet.read_tet_mesh(tmp_path / "b.msh"), **options), expected)


def test_the_thesis_spellings_work(octopus_files):
    a, b = (kdet.read_tet_mesh(f) for f in octopus_files[:2])
    np.testing.assert_array_equal(
        kdet.collide(a, b, method="GPU_NO_LOOP", test="SAT-MTV", hash="fnv_1a"),
        kdet.collide(a, b, method="brute_force_pairs", test="sat_mtv", hash="fnv-1a"),
    )


def test_contacts_match_the_command(cli, tmp_path, octopus_files):
    a_file, b_file, _ = octopus_files
    out = tmp_path / "contacts.txt"
    subprocess.run([str(cli), "collide", str(a_file), str(b_file), "--contacts", str(out)], check=True, capture_output=True)
    expected = np.loadtxt(out, ndmin=2)
    detector = kdet.Detector(contacts=True)
    detector.add_object(kdet.read_tet_mesh(a_file))
    detector.add_object(kdet.read_tet_mesh(b_file))
    result = detector.detect()
    np.testing.assert_array_equal(result.pairs[:, [1, 3]], expected[:, :2].astype(np.uint32))
    assert result.contacts.dtype == np.float32 and result.contacts.shape == (len(expected), 4)
    np.testing.assert_array_equal(result.contacts, expected[:, 2:].astype(np.float32))
    np.testing.assert_allclose(np.linalg.norm(result.contacts[:, 1:], axis=1), 1.0, rtol=1e-5)


def test_counts_match_the_command_json(cli, octopus_files):
    a_file, b_file, _ = octopus_files
    printed = json.loads(subprocess.run([str(cli), "collide", str(a_file), str(b_file), "--json"], check=True,
                                        capture_output=True, text=True).stdout)
    detector = kdet.Detector()
    detector.add_object(kdet.read_tet_mesh(a_file))
    detector.add_object(kdet.read_tet_mesh(b_file))
    counts = detector.detect().counts.as_dict()
    shared = [key for key in printed if key in counts]
    assert {"candidates", "narrow_phase_candidates", "colliding_pairs", "colliding_tets"} <= set(shared)
    for key in shared:
        assert counts[key] == printed[key], key
    assert set(detector.detect().times.as_dict()) >= set(printed["times_ms"]) | {"total"}
