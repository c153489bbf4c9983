#!/usr/bin/env python3
"""Moves mesh B through mesh A over a number of frames and prints the colliding tet pairs of each frame.

usage: python3 moving_meshes.py [A] [B] [--frames N] [--method M] [--test T]
       (default A and B: octopus-low.mesh from $KDET_DATA_DIR, else ../shared/models)
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numpy as np

import kdet


def default_model(name: str) -> Path:
    return Path(os.environ.get("KDET_DATA_DIR", "../shared/models")) / name


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("a", nargs="?", type=Path, default=default_model("octopus-low.mesh"))
    parser.add_argument("b", nargs="?", type=Path, default=default_model("octopus-low.mesh"))
    parser.add_argument("--frames", type=int, default=10)
    defaults = kdet.Detector().options  # the library's own defaults
    parser.add_argument("--method", default=defaults["method"], choices=kdet.METHODS)
    parser.add_argument("--test", default=defaults["test"], choices=kdet.TESTS)
    args = parser.parse_args()

    a, b = kdet.read_tet_mesh(args.a), kdet.read_tet_mesh(args.b)
    detector = kdet.Detector(method=args.method, test=args.test)
    detector.add_object(a)
    moving = detector.add_object(b)

    # B travels along x from fully left of A to fully right of it.
    width_a = np.ptp(a.vertices[:, 0])
    width_b = np.ptp(b.vertices[:, 0])
    start = a.vertices[:, 0].min() - b.vertices[:, 0].max() - 0.1 * width_b
    travel = width_a + width_b + 0.2 * width_b
    offset = np.zeros(3)
    for frame in range(args.frames):
        offset[0] = start + travel * frame / max(args.frames - 1, 1)
        detector.set_positions(moving, b.vertices + offset)
        began = time.perf_counter()
        result = detector.detect()
        wall_ms = 1e3 * (time.perf_counter() - began)
        tets = result.pairs[:, [1, 3]]
        shown = ", ".join(f"({i}, {j})" for i, j in tets[:4]) + (", ..." if len(tets) > 4 else "")
        print(f"frame {frame:3d}  x {offset[0]:+8.3f}  {len(tets):7d} pairs  {result.times.total:8.2f} ms "
              f"({wall_ms:.2f} ms in Python)  {shown}")


if __name__ == "__main__":
    main()
