"""Reads the CSV files that `kdet bench` writes (thesis appendix A.1.4).

A file holds `key, value` header lines, then a column line that starts with `frame` (per-frame
averages) or `run` (every run), then one row of numbers per frame. Values may contain commas, so
a header line splits at its first ", " only.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field


@dataclass
class BenchFile:
    """One benchmark file: its header, its column names and its rows (all numbers)."""

    path: str
    header: dict[str, str]
    columns: list[str]
    rows: list[list[float]] = field(default_factory=list)

    def column(self, name: str) -> list[float]:
        """The values of one column, one per row."""
        index = self.columns.index(name)
        return [row[index] for row in self.rows]

    @property
    def is_raw(self) -> bool:
        """True for the `_runs.csv` files (every run), false for the per-frame averages."""
        return self.columns[0] == "run"

    @property
    def scene(self) -> str:
        """The scene's name, with `kdet bench`'s file-name suffix for --rings, --filters off and --margin,
        so that such runs are told apart from the plain ones in tables and plots."""
        name = self.header.get("scene name", "?")
        rings = self.header.get("exclusion rings", "0")
        if rings != "0":
            name += f"_rings{rings}"
        if self.header.get("collision filters", "on") == "off":
            name += "_filters-off"
        margin = self.header.get("margin", "0")
        if margin != "0":
            name += f"_margin{margin}"
        return name

    @property
    def resolution(self) -> int:
        return int(self.header.get("resolution", "1"))

    @property
    def algorithm(self) -> str:
        return self.header.get("algorithm", "?")

    @property
    def self_collisions(self) -> bool:
        return self.self_setting != "no"

    @property
    def self_setting(self) -> str:
        """`kdet bench -s`: "no", "yes" (every object) or "scene" (the objects the scene marks)."""
        return self.header.get("self collisions", "no")

    @property
    def total_tets(self) -> int:
        if "#tets" in self.header:  # every object's; files from before it name only the first two
            return int(self.header["#tets"])
        return int(self.header.get("#tetsA", "0")) + int(self.header.get("#tetsB", "0"))


def read_bench_file(path: str) -> BenchFile:
    """Parses one file; raises ValueError naming the file and line when it is not a bench file."""
    header: dict[str, str] = {}
    columns: list[str] = []
    rows: list[list[float]] = []
    with open(path, encoding="utf-8") as text:
        for number, line in enumerate(text, start=1):
            line = line.rstrip("\n")
            if not line:
                continue
            fields = [f.strip() for f in line.split(",")]
            if not columns and fields[0] in ("frame", "run"):
                columns = fields
            elif not columns:
                key, _, value = line.partition(", ")
                header[key] = value
            else:
                try:
                    rows.append([float(f) for f in fields])
                except ValueError:
                    raise ValueError(f"{path}:{number}: expected numbers, got '{line}'") from None
                if len(rows[-1]) != len(columns):
                    raise ValueError(f"{path}:{number}: {len(rows[-1])} values for {len(columns)} columns")
    if not columns:
        raise ValueError(f"{path}: no column line (a line starting with 'frame' or 'run')")
    return BenchFile(path, header, columns, rows)


def read_folder(folder: str) -> tuple[list[BenchFile], list[BenchFile]]:
    """All bench files of a folder (not recursive): (per-frame averages, raw runs), sorted by name."""
    averages: list[BenchFile] = []
    raw: list[BenchFile] = []
    for name in sorted(os.listdir(folder)):
        if not name.endswith(".csv"):
            continue
        bench = read_bench_file(os.path.join(folder, name))
        (raw if bench.is_raw else averages).append(bench)
    return averages, raw


def median(values: list[float]) -> float:
    """The middle value (the mean of the two middle ones for an even count)."""
    ordered = sorted(values)
    middle = len(ordered) // 2
    return ordered[middle] if len(ordered) % 2 else (ordered[middle - 1] + ordered[middle]) / 2
