"""The examples in python/examples run and say what they should."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def run(script: str, models: Path, *args: str) -> str:
    environment = dict(os.environ, KDET_DATA_DIR=str(models))
    done = subprocess.run([sys.executable, str(EXAMPLES / script), *args], env=environment, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return done.stdout


def test_moving_meshes_prints_each_frame(models):
    lines = run("moving_meshes.py", models, "--frames", "5").splitlines()
    pairs = [int(re.search(r"(\d+) pairs", line).group(1)) for line in lines]
    assert len(pairs) == 5
    # B starts and ends clear of A and passes through it in the middle.
    assert pairs[0] == pairs[-1] == 0 and pairs[2] > 100


def test_draw_collisions_writes_a_picture(models, tmp_path):
    pytest.importorskip("matplotlib", reason="the drawing example needs matplotlib")
    out = tmp_path / "collisions.png"
    printed = run("draw_collisions.py", models, "--out", str(out))
    assert re.match(r"\d+ colliding pairs", printed) and int(printed.split()[0]) > 100
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_embed_surface_carries_every_point(models):
    lines = run("embed_surface.py", models).splitlines()
    embedded, total = map(int, re.match(r"(\d+) of (\d+) surface points embedded", lines[0]).groups())
    # The bunny's surface vertices are vertices of its tet mesh: each is held, most by several tets.
    assert embedded == total == 3485
    shared = int(re.search(r"\((\d+) on faces", lines[0]).group(1))
    assert shared > total // 2
    deviation = float(re.search(r"mapped point (\S+)", lines[1]).group(1))
    assert deviation < 1e-6


def test_contact_margin_warns_before_the_contact(models):
    lines = run("contact_margin.py", models).splitlines()
    frames = [tuple(map(int, re.search(r"(\d+) pairs within the margin, (\d+) overlapping", line).groups()))
              for line in lines if line.startswith("frame")]
    assert len(frames) == 12 and frames[0] == (0, 0)
    first = next(i for i, (pairs, _) in enumerate(frames) if pairs)
    # Close but apart first (the margin warns), then overlapping.
    assert frames[first][1] == 0 < frames[first][0]
    assert frames[-1][1] > 0
    assert lines[-1].endswith("the same as the last frame")
