"""Shared fixtures of the Python package's tests.

The tests compare kdet's pairs with those of the C++ command `kdet collide` on the models of
../shared/models. Where they are found:
  KDET_DATA_DIR   the models (default: ../shared/models from the repository root)
  KDET_CLI        the kdet command (default: build/kdet of the repository); scripts/test.sh sets it,
                  and then a missing command fails the tests instead of skipping them.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def models() -> Path:
    folder = Path(os.environ.get("KDET_DATA_DIR", REPO.parent / "shared" / "models"))
    if not (folder / "octopus-low.mesh").exists():
        pytest.fail(f"the models are not in {folder} (set KDET_DATA_DIR)")
    return folder


@pytest.fixture(scope="session")
def cli() -> Path:
    given = os.environ.get("KDET_CLI")
    path = Path(given) if given else REPO / "build" / "kdet"
    if not path.exists():
        if given:
            pytest.fail(f"KDET_CLI={given} does not exist")
        pytest.skip(f"the kdet command is not built ({path}); build it or set KDET_CLI")
    return path
