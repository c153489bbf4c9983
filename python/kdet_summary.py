#!/usr/bin/env python3
"""Writes a markdown table of `kdet bench` results: median and maximum frame time (device time, ms)
per scene, resolution, method and self-collision setting.

usage: python3 python/kdet_summary.py FOLDER [--out FILE]   (default FILE: FOLDER/summary.md)

Needs only the standard library. Lines of FOLDER/skipped.txt (written by
scripts/run-thesis-matrix.sh for runs that could not be done) are listed under the table.
"""

from __future__ import annotations

import argparse
import os
import sys

from kdet_csv import BenchFile, median, read_folder

METHOD_ORDER = ["kdet", "kdet_no_pairs", "gpu", "gpu_no_loop"]


def sort_key(bench: BenchFile) -> tuple:
    method = METHOD_ORDER.index(bench.algorithm) if bench.algorithm in METHOD_ORDER else len(METHOD_ORDER)
    return (bench.scene, bench.resolution, bench.self_setting, method, bench.path)


def summary_markdown(averages: list[BenchFile], skipped: list[str]) -> str:
    """The whole document: machine, table, skipped runs."""
    lines = ["# kdet benchmark summary", ""]
    if averages:
        first = averages[0].header
        for key in ("device", "backend", "threads", "compiler", "compiler flags", "kdet version", "total runs"):
            lines.append(f"- {key}: {first.get(key, '?')}")
        lines.append("")
    lines.append("| scene | res | tets | method | self | frames | median ms | max ms | max pairs | peak MiB |")
    lines.append("|---|---:|---:|---|---|---:|---:|---:|---:|---:|")
    for bench in sorted(averages, key=sort_key):
        times = bench.column("device time")
        pairs = max(bench.column("collision pairs"), default=0)
        memory = int(bench.header.get("peak memory bytes", "0")) / 2**20
        lines.append(
            f"| {bench.scene} | {bench.resolution} | {bench.total_tets} | {bench.algorithm} | "
            f"{bench.self_setting} | {len(times)} | {median(times):.3f} | "
            f"{max(times):.3f} | {pairs:.0f} | {memory:.1f} |")
    if skipped:
        lines += ["", "## Not run", ""] + [f"- {line}" for line in skipped]
    return "\n".join(lines) + "\n"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folder", help="folder with the CSV files of kdet bench")
    parser.add_argument("--out", help="markdown file to write (default: FOLDER/summary.md)")
    args = parser.parse_args()
    try:
        averages, _ = read_folder(args.folder)
    except (OSError, ValueError) as error:
        print(f"kdet_summary: {error}", file=sys.stderr)
        return 1
    skipped_path = os.path.join(args.folder, "skipped.txt")
    skipped = []
    if os.path.exists(skipped_path):
        with open(skipped_path, encoding="utf-8") as text:
            skipped = [line.strip() for line in text if line.strip()]
    out = args.out or os.path.join(args.folder, "summary.md")
    with open(out, "w", encoding="utf-8") as text:
        text.write(summary_markdown(averages, skipped))
    print(f"wrote {out} ({len(averages)} benchmarks)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
