#!/usr/bin/env python3
"""Moves mesh B toward mesh A and prints, per frame, the tet pairs within a contact margin, how many of
them overlap, and the closest pair with its distance and points: what a simulator with an alarm
distance (SOFA) or a barrier width (IPC's dhat) reads before the meshes touch.

usage: python3 contact_margin.py [A] [B] [--frames N] [--margin D]
       (default A and B: bunny.mesh from $KDET_DATA_DIR, else ../shared/models; D: a fifth of
       A's median edge length)

B starts three margins from A, to its right, and moves toward it by half a margin a frame, so the
first frame with pairs holds only pairs that are close but apart (distance > 0): the margin warns
before the contact.
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path

import numpy as np

import kdet


def default_model(name: str) -> Path:
    return Path(os.environ.get("KDET_DATA_DIR", "../shared/models")) / name


def median_edge_length(mesh: kdet.TetMesh) -> float:
    corners = mesh.vertices[mesh.tets]
    edges = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]
    return float(np.median(np.concatenate([np.linalg.norm(corners[:, i] - corners[:, j], axis=1) for i, j in edges])))


def point_text(p: np.ndarray) -> str:
    return "(" + ", ".join(f"{float(x):.4f}" for x in p) + ")"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("a", nargs="?", type=Path, default=default_model("bunny.mesh"))
    parser.add_argument("b", nargs="?", type=Path, default=default_model("bunny.mesh"))
    parser.add_argument("--frames", type=int, default=12)
    parser.add_argument("--margin", type=float, default=None)
    args = parser.parse_args()
    if args.frames < 1:
        parser.error("--frames must be at least 1")

    a, b = kdet.read_tet_mesh(args.a), kdet.read_tet_mesh(args.b)
    margin = args.margin if args.margin is not None else median_edge_length(a) / 5
    if not margin > 0:
        parser.error("--margin must be a positive distance")
    detector = kdet.Detector(margin=margin, distances=True)
    detector.add_object(a)
    moving = detector.add_object(b)

    # B just right of A's box, then a detector with a wider margin each time until it finds a pair
    # measures the gap between the tets and where it is smallest. B then moves along the line from
    # its closest point to A's, starting 3 margins away.
    clear = b.vertices + [a.vertices[:, 0].max() - b.vertices[:, 0].min() + 3 * margin, 0.0, 0.0]
    probe_margin = 3 * margin
    while True:
        probe = kdet.Detector(margin=probe_margin, distances=True)
        probe.add_object(a)
        probe.add_object(clear, b.tets)
        measured = probe.detect()
        if len(measured.pairs):
            break
        probe_margin *= 1.5
    k = int(np.argmin(measured.distances))
    gap = float(measured.distances[k])
    on_a, on_b = measured.closest_points[k].astype(np.float64)
    direction = (on_a - on_b) / np.linalg.norm(on_a - on_b)
    start = clear + (gap - 3 * margin) * direction
    print(f"margin {margin:.6g} ({len(a.tets)} and {len(b.tets)} tets); B starts {3 * margin:.6g} from A and moves "
          f"{margin / 2:.6g} toward it a frame")
    for frame in range(args.frames):
        positions = start + frame * margin / 2 * direction
        detector.set_positions(moving, positions)
        r = detector.detect()
        overlapping = int(np.count_nonzero(r.distances == 0))
        line = f"frame {frame}: {len(r.pairs)} pairs within the margin, {overlapping} overlapping"
        if len(r.pairs):
            assert r.distances.max() <= margin * (1 + 1e-6)  # each reported distance, rounded to float32
            k = int(np.argmin(r.distances))
            _, tet_a, _, tet_b = r.pairs[k]
            on_a, on_b = r.closest_points[k]
            line += (f"; closest: tet {tet_a} of A and tet {tet_b} of B at {r.distances[k]:.4g}, "
                     f"points {point_text(on_a)} and {point_text(on_b)}")
        print(line)

    # The one-off call gives the last frame's pairs.
    last = kdet.collide(a, kdet.TetMesh(positions, b.tets), margin=margin)
    same = np.array_equal(last, r.pairs[:, [1, 3]][np.lexsort((r.pairs[:, 3], r.pairs[:, 1]))])
    print(f"kdet.collide(a, b, margin={margin:.6g}): {len(last)} pairs, {'the same' if same else 'NOT the same'} as the last frame")


if __name__ == "__main__":
    main()
