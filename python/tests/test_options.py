"""The option table walked entry by entry: Detector() accepts a valid value of every keyword and
refuses an invalid one; a name refused reads as `kdet collide` and `kdet bench` word it, with the
keyword in place of the flag (tests/test_option_table.cpp walks the command line)."""

from __future__ import annotations

import subprocess
from pathlib import Path

import numpy as np
import pytest

import kdet

NAMES = sorted(kdet.OPTIONS)


@pytest.fixture(scope="module")
def octopus(models: Path) -> kdet.TetMesh:
    return kdet.read_tet_mesh(models / "octopus-low.mesh")


def valid(entry):
    if entry["type"] == "choice":
        return entry["choices"][-1]
    if entry["type"] == "integer":
        return entry["range"][1] if entry["range"][1] < 2**40 else entry["range"][0]
    if entry["type"] == "real":
        return 0.25
    return not entry["default"]


def test_the_table_is_detectors_keywords():
    assert kdet.OPTIONS["test"]["choices"] == kdet.TESTS
    assert kdet.OPTIONS["method"]["choices"] == kdet.METHODS
    assert kdet.OPTIONS["test"]["bench_flag"] == "-o" and kdet.OPTIONS["test"]["flag"] == "--test"
    defaults = kdet.Detector().options
    for name, entry in kdet.OPTIONS.items():
        assert defaults[name] == entry["default"], name
        assert entry["help"] or entry["type"] == "choice", name


@pytest.mark.parametrize("name", NAMES)
def test_every_keyword_takes_a_valid_value_and_refuses_an_invalid_one(name):
    entry = kdet.OPTIONS[name]
    value = valid(entry)
    if name == "backend" and not kdet.cuda_available():
        value = entry["default"]
    assert kdet.Detector(**{name: value}).options[name] == value
    if entry["type"] == "choice":
        with pytest.raises(kdet.Error) as refused:
            kdet.Detector(**{name: "nope"})
        assert str(refused.value) == f"invalid value 'nope' for {name}: expected " + (
            ", ".join(entry["choices"][:-1]) + " or " + entry["choices"][-1])
    elif entry["type"] == "integer":
        low, high = entry["range"]
        with pytest.raises(kdet.Error, match=f"^{name}: expected "):
            kdet.Detector(**{name: low - 1})
        if high < 2**40:
            with pytest.raises(kdet.Error, match=rf"out of range \[{low}, {high}\]"):
                kdet.Detector(**{name: high + 1})
    elif entry["type"] == "real":
        for bad in (-1.0, float("nan"), float("inf"), 1e39):
            with pytest.raises(kdet.Error, match=f"^{name}: expected a finite number >= 0, got "):
                kdet.Detector(**{name: bad})
    with pytest.raises(TypeError, match=f"^{name}: expected"):
        kdet.Detector(**{name: object()})


@pytest.mark.parametrize("name", [n for n in NAMES if kdet.OPTIONS[n]["type"] != "choice"])
def test_every_keyword_takes_numpys_scalars_of_its_kind(name):
    # What indexing or reducing a NumPy array gives (np.float32, np.int64, np.bool_) reads as Python's own
    # scalar of that kind; a bool is still no number, nor a number a bool.
    entry = kdet.OPTIONS[name]
    value = valid(entry)
    if entry["type"] == "boolean":
        scalars, other_kind = [np.bool_(value)], np.int64(1)
    elif entry["type"] == "integer":
        scalars, other_kind = [np.int64(value), np.uint32(value)], np.True_
    else:
        scalars, other_kind = [np.float32(value), np.float64(value), np.int16(1)], np.True_
    for scalar in scalars:
        assert kdet.Detector(**{name: scalar}).options[name] == scalar, type(scalar).__name__
    with pytest.raises(TypeError, match=f"^{name}: expected "):
        kdet.Detector(**{name: other_kind})


@pytest.mark.parametrize("name", [n for n in NAMES if kdet.OPTIONS[n]["type"] == "choice"])
def test_a_refused_name_reads_as_on_the_command_line(name, cli: Path):
    entry = kdet.OPTIONS[name]
    with pytest.raises(kdet.Error) as refused:
        kdet.Detector(**{name: "nope"})
    for command, flag in (("collide", entry["flag"]), ("bench", entry["bench_flag"])):
        run = subprocess.run([str(cli), command, flag, "nope"], capture_output=True, text=True)
        assert run.returncode == 2
        assert run.stderr == f"kdet {command}: " + str(refused.value).replace(f" for {name}:", f" for {flag}:") + "\n"


def test_collide_takes_the_same_keywords(octopus):
    with pytest.raises(TypeError, match="unexpected keyword argument 'tests'"):
        kdet.collide(octopus, octopus, tests="sat")
    with pytest.raises(kdet.Error, match="invalid value 'x' for test: expected sat, "):
        kdet.collide_self(octopus, test="x")
