#!/usr/bin/env python3
"""Cost of the Python binding per frame on the CPU backend: the wall time of Detector.detect() seen from
Python against the library's own time for the same call (FrameResult.times.total), frame by frame in one
process, on two tet grids of about 100k tets together, one moving through the other. The difference is
everything the binding adds (argument handling, the GIL, copying the results into the FrameResult that
Python keeps) plus the library's upload of the new positions, which its total leaves out.
set_positions() is timed against one NumPy copy of the same array.

usage: python3 bench/python_overhead.py [--tets 100000] [--frames 30] [--threads N] [--out FILE.md]
(needs the package: pip install .)
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import sys
import time

import numpy as np

import kdet


def tet_grid(cells: tuple[int, int, int]) -> kdet.TetMesh:
    """A box of unit cubes, each split into six tets around its main diagonal."""
    nx, ny, nz = cells
    grid = np.stack(np.meshgrid(np.arange(nx + 1), np.arange(ny + 1), np.arange(nz + 1), indexing="ij"), axis=-1)
    vertices = grid.reshape(-1, 3).astype(np.float64)
    index = np.arange(len(vertices)).reshape(nx + 1, ny + 1, nz + 1)
    # Corner c of a cube: +x when bit 1 is set, +y for bit 2, +z for bit 4.
    corners = np.stack([index[(c & 1):nx + (c & 1), (c >> 1 & 1):ny + (c >> 1 & 1), (c >> 2 & 1):nz + (c >> 2 & 1)].ravel()
                        for c in range(8)], axis=1)
    paths = [(1, 3), (1, 5), (2, 3), (2, 6), (4, 5), (4, 6)]  # corner 0 -> one axis -> two axes -> corner 7
    tets = np.concatenate([corners[:, [0, a, b, 7]] for a, b in paths]).astype(np.uint32)
    return kdet.TetMesh(vertices, tets)


def turned(vertices: np.ndarray, angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return vertices @ np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]).T


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--tets", type=int, default=100_000, help="tets of both grids together")
    parser.add_argument("--frames", type=int, default=30)
    parser.add_argument("--threads", type=int)
    parser.add_argument("--test", default=kdet.Detector().options["test"], help="narrow-phase test (kdet.TESTS)")
    parser.add_argument("--out", help="also write the report to this Markdown file")
    args = parser.parse_args()

    side = max(2, round((args.tets / 2 / 6 / 2) ** (1 / 3)))  # each grid: side x side x 2 side cubes
    grid = tet_grid((side, side, 2 * side))
    a_vertices = turned(grid.vertices, 0.3)
    b_rest = turned(grid.vertices, -0.2) + [0.5 * side + 0.37, 0.21, 0.0]  # half of B beside A
    detector = kdet.Detector(threads=args.threads, test=args.test)
    detector.add_object(a_vertices, grid.tets)
    moving = detector.add_object(b_rest, grid.tets)
    tets = 2 * grid.num_tets

    load_before = os.getloadavg()[0]
    rows = []
    for frame in range(args.frames + 3):
        # B slides along z through A, half way in at the middle frame.
        positions = (b_rest + [0.0, 0.0, side * (frame / args.frames - 0.5)]).astype(np.float32)
        start = time.perf_counter()
        detector.set_positions(moving, positions)
        middle = time.perf_counter()
        result = detector.detect()
        end = time.perf_counter()
        copy_start = time.perf_counter()
        np.copyto(np.empty_like(positions), positions)
        copy_end = time.perf_counter()
        if frame >= 3:  # the first frames size the buffers
            rows.append((1e3 * (end - middle), result.times.total, 1e3 * (middle - start), 1e3 * (copy_end - copy_start),
                         len(result.pairs)))

    load_after = os.getloadavg()[0]
    wall = [r[0] for r in rows]
    library = [r[1] for r in rows]
    overhead = [r[0] - r[1] for r in rows]
    share = [100 * (r[0] - r[1]) / r[1] for r in rows]
    report = [
        "# Python binding overhead per detect(), CPU backend",
        "",
        f"- Machine: {detector.device_name}, {os.cpu_count()} cores, {platform.platform()}; "
        f"Python {platform.python_version()}, NumPy {np.__version__}; load average (1 min) {load_before:.1f} before, "
        f"{load_after:.1f} after (the second counts this benchmark's own threads).",
        f"- kdet {kdet.version()}; detector threads: {detector.options['threads'] or 'all'}.",
        f"- Command: `python3 {' '.join(sys.argv)}` (bench/python_overhead.py, package built by `pip install .`).",
        f"- Workload: two tet grids of {grid.num_tets:,} tets each ({tets:,} in all), one sliding through the "
        f"other over {args.frames} frames (3 warm-up frames dropped); float32 positions; method {detector.options['method']}, "
        f"test {detector.options['test']}. Both times are taken for the same call, frame after frame, in this process.",
        "",
        "| per frame | median | min | max |",
        "|---|---:|---:|---:|",
        f"| library time, FrameResult.times.total | {statistics.median(library):.2f} ms | {min(library):.2f} ms | {max(library):.2f} ms |",
        f"| wall time of detect() in Python | {statistics.median(wall):.2f} ms | {min(wall):.2f} ms | {max(wall):.2f} ms |",
        f"| binding overhead (wall - library) | {statistics.median(overhead):.3f} ms | {min(overhead):.3f} ms | {max(overhead):.3f} ms |",
        f"| overhead / library time | {statistics.median(share):.2f} % | {min(share):.2f} % | {max(share):.2f} % |",
        f"| set_positions() | {statistics.median(r[2] for r in rows):.3f} ms | {min(r[2] for r in rows):.3f} ms | {max(r[2] for r in rows):.3f} ms |",
        f"| one NumPy copy of the positions | {statistics.median(r[3] for r in rows):.3f} ms | {min(r[3] for r in rows):.3f} ms | {max(r[3] for r in rows):.3f} ms |",
        f"| colliding pairs | {statistics.median(r[4] for r in rows):,.0f} | {min(r[4] for r in rows):,} | {max(r[4] for r in rows):,} |",
    ]
    text = "\n".join(report) + "\n"
    print(text)
    if args.out:
        with open(args.out, "w") as out:
            out.write(text)


if __name__ == "__main__":
    main()
