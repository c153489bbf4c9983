#!/usr/bin/env python3
"""Draws the figures of the thesis's chapter 6 from the CSV files that `kdet bench` writes.

usage: python3 python/kdet_plot.py FOLDER [--out DIR]      (default DIR: FOLDER/plots)

Figures ("_self" in the name: with self-collisions); times are device times in ms:
  frame_times[_self].png             time per frame, one line per method, scenes x resolutions (6.10, 6.15)
  stages_<method>[_self].png         stacked time per pipeline stage over the frames (6.14, 6.20)
  boxplot_<method>[_self].png        frame times per scene and resolution (6.17, 6.18)
  penetration_<scene>.png            time and unique candidates against the bounding-box overlap
                                     along x, the thesis's penetration depth, with a cubic fit (6.13);
                                     cases whose overlap never changes are left out
  memory[_self].png                  peak detector memory per scene and resolution (6.22)
  run_spread_<method>[_self].png     mean, min-max range and standard deviation over the runs (6.2)
  host_vs_device_<method>[_self].png wall-clock time of detect() against its own total (6.4)
  total_time.png                     frame times summed over all benchmarks per method (6.21)
Needs matplotlib (python/requirements.txt).
"""

from __future__ import annotations

import argparse
import os
import sys
from collections import defaultdict
from typing import Callable

import matplotlib

matplotlib.use("Agg")  # files only, no display
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.ticker import MaxNLocator  # noqa: E402
import numpy as np  # noqa: E402

from kdet_csv import BenchFile, read_folder  # noqa: E402

STAGES = [
    ("bbox time", "bounding boxes"),
    ("populate time", "populate grid"),
    ("find candidates time", "find candidates"),
    ("sort unique time", "sort + unique"),
    ("narrow phase time", "narrow phase"),
]
# Parameters that tell apart two files of the same method in one figure.
DISTINGUISHING_KEYS = ["self collisions", "overlap test", "hashing algorithm", "block size", "threads", "backend", "first frame", "#frames"]


def series_label(bench: BenchFile, others: list[BenchFile]) -> str:
    """The method, plus whatever parameters differ from the other files of that method."""
    same = [o for o in others if o.algorithm == bench.algorithm]
    extra = [f"{key} {bench.header.get(key)}" for key in DISTINGUISHING_KEYS
             if len({o.header.get(key) for o in same}) > 1]
    if len({o.total_tets for o in same}) > 1:
        extra.append(f"{bench.total_tets} tets")
    return ", ".join([bench.algorithm] + extra)


def case_label(bench: BenchFile, files: list[BenchFile]) -> str:
    """"scene - resolution", with the tet count when the files hold several sizes of that case."""
    label = f"{bench.scene} - {bench.resolution}"
    sizes = {f.total_tets for f in files if (f.scene, f.resolution) == (bench.scene, bench.resolution)}
    return label + (f" ({bench.total_tets} tets)" if len(sizes) > 1 else "")


def suffix(self_collisions: bool) -> str:
    return "_self" if self_collisions else ""


def setting(bench: BenchFile, files: list[BenchFile]) -> tuple[tuple[str, str], ...]:
    """What tells a file apart from the others of its method and self-collision setting in one case (scene
    and resolution): (name, value) of the parameters of DISTINGUISHING_KEYS, and the tet count, that vary
    within a case."""
    same = [f for f in files if (f.algorithm, f.self_collisions) == (bench.algorithm, bench.self_collisions)]
    cases: dict[tuple[str, int], list[BenchFile]] = defaultdict(list)
    for f in same:
        cases[(f.scene, f.resolution)].append(f)
    values = [(key, lambda f, key=key: f.header.get(key)) for key in DISTINGUISHING_KEYS]
    values.append(("tets", lambda f: str(f.total_tets)))
    return tuple((name, value(bench)) for name, value in values
                 if any(len({value(f) for f in case}) > 1 for case in cases.values()))


def by_setting(files: list[BenchFile]) -> dict[tuple[str, bool], tuple[str, list[BenchFile]]]:
    """Files grouped by method, self-collisions and the parameters that set them apart within a case, so
    that each group has one file per panel: (name for file names, self-collisions) -> (label, files)."""
    groups: dict[tuple, list[BenchFile]] = defaultdict(list)
    for bench in files:
        groups[(bench.algorithm, bench.self_collisions, setting(bench, files))].append(bench)
    named: dict[tuple[str, bool], tuple[str, list[BenchFile]]] = {}
    for (method, self_collisions, values), members in groups.items():
        label = ", ".join([method] + [f"{name} {value}" for name, value in values])
        name = label.replace(", ", "_").replace(" ", "-").replace("#", "")
        named[(name, self_collisions)] = (label, members)
    return named


def save(fig, path: str, written: list[str]) -> None:
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    written.append(path)


def grid_figure(files: list[BenchFile], draw: Callable, title: str, path: str, written: list[str]) -> None:
    """One panel per scene (rows) and resolution (columns); `draw(ax, files_of_panel, files)` fills a panel."""
    scenes = sorted({f.scene for f in files})
    resolutions = sorted({f.resolution for f in files})
    fig, axes = plt.subplots(len(scenes), len(resolutions), squeeze=False,
                             figsize=(4.8 * len(resolutions), 3.4 * len(scenes) + 0.6))
    for row, scene in enumerate(scenes):
        for col, resolution in enumerate(resolutions):
            ax = axes[row][col]
            panel = [f for f in files if f.scene == scene and f.resolution == resolution]
            if not panel:
                ax.axis("off")
                continue
            draw(ax, panel, files)
            ax.set_title(f"{scene} - {resolution}", fontsize=10)
            ax.set_xlabel("frame")
            ax.xaxis.set_major_locator(MaxNLocator(integer=True))
            ax.grid(alpha=0.3)
    fig.suptitle(title)
    save(fig, path, written)


# One colour per method in every panel and figure where the files hold one setting of it; the settings
# of a method run several ways take the other colours, none of them a method's.
METHOD_COLORS = {"kdet": "tab:red", "kdet_no_pairs": "tab:green", "gpu": "tab:orange", "gpu_no_loop": "tab:blue"}
SETTING_COLORS = ["tab:purple", "tab:brown", "tab:pink", "tab:gray", "tab:olive", "tab:cyan", "black", "gold"]


def method_color(bench: BenchFile, files: list[BenchFile]) -> str:
    """The colour of a file's series, the same in every panel that draws it among `files`."""
    labels = sorted({series_label(f, files) for f in files})
    same_method = sorted({series_label(f, files) for f in files if f.algorithm == bench.algorithm})
    if len(same_method) == 1 and bench.algorithm in METHOD_COLORS:
        return METHOD_COLORS[bench.algorithm]
    return SETTING_COLORS[labels.index(series_label(bench, files)) % len(SETTING_COLORS)]


def single_frame_marker(bench: BenchFile) -> str | None:
    """A marker where a series has one frame, which a line alone would not show."""
    return "o" if len(bench.rows) == 1 else None


def draw_frame_times(ax, panel: list[BenchFile], files: list[BenchFile]) -> None:
    for bench in panel:
        ax.plot(bench.column("frame"), bench.column("device time"), label=series_label(bench, panel), linewidth=1.2,
                color=method_color(bench, files), marker=single_frame_marker(bench))
    ax.set_ylabel("frame time (ms)")
    ax.legend(fontsize=7)


def draw_stages(ax, panel: list[BenchFile], files: list[BenchFile]) -> None:
    bench = panel[0]  # one setting per figure (by_setting), so one file per panel
    stages = [bench.column(c) for c, _ in STAGES]
    ax.stackplot(bench.column("frame"), *stages, labels=[n for _, n in STAGES])
    ax.set_ylabel("time (ms)")
    # Room above the stack for the legend, which a filled area leaves nowhere else.
    ax.set_ylim(0, 1.45 * max(max(map(sum, zip(*stages))), 1e-9))
    ax.legend(fontsize=7, loc="upper left", ncol=2)


def draw_host_vs_device(ax, panel: list[BenchFile], files: list[BenchFile]) -> None:
    bench = panel[0]
    marker = single_frame_marker(bench)
    ax.plot(bench.column("frame"), bench.column("host time"), label="host", linewidth=1.2, marker=marker)
    ax.plot(bench.column("frame"), bench.column("device time"), label="device", linewidth=1.0, linestyle="--", marker=marker)
    ax.set_ylabel("time (ms)")
    ax.legend(fontsize=7)


def draw_run_spread(ax, panel: list[BenchFile], files: list[BenchFile]) -> None:
    bench = panel[0]
    per_frame: dict[float, list[float]] = defaultdict(list)
    for frame, time in zip(bench.column("frame"), bench.column("device time")):
        per_frame[frame].append(time)
    frames = sorted(per_frame)
    times = [np.array(per_frame[f]) for f in frames]
    mean = np.array([t.mean() for t in times])
    std = np.array([t.std() for t in times])
    ax.fill_between(frames, mean - std, mean + std, color="tab:orange", alpha=0.6, label="standard deviation")
    ax.fill_between(frames, [t.min() for t in times], [t.max() for t in times], color="tab:green", alpha=0.3,
                    label="range")
    ax.plot(frames, mean, color="tab:blue", linewidth=1.0, label=f"mean of {bench.header.get('total runs')} runs")
    ax.set_ylabel("frame time (ms)")
    ax.legend(fontsize=7)


def boxplot_figure(files: list[BenchFile], title: str, path: str, written: list[str]) -> None:
    ordered = sorted(files, key=lambda f: (f.resolution, f.scene, f.total_tets, f.path))
    fig, ax = plt.subplots(figsize=(max(6.0, 1.1 * len(ordered) + 2), 4.5))
    ax.boxplot([f.column("device time") for f in ordered])
    ax.set_xticks(range(1, len(ordered) + 1), [case_label(f, files) for f in ordered], rotation=35,
                  ha="right", fontsize=8)
    ax.set_ylabel("frame time (ms)")
    ax.grid(axis="y", alpha=0.3)
    ax.set_title(title)
    save(fig, path, written)


def penetration_figure(scene: str, files: list[BenchFile], path: str, written: list[str]) -> None:
    """Frames whose object boxes overlap along x; no figure when there are none, and no series for a
    case whose overlap is the same in every frame (a single column says nothing about depth)."""
    fig, (time_ax, pairs_ax) = plt.subplots(1, 2, figsize=(11, 4.2))
    drawn = False
    for bench in sorted(files, key=lambda f: (f.resolution, f.algorithm)):
        points = [(d, t, c) for d, t, c in zip(bench.column("bbox overlap x"), bench.column("device time"),
                                               bench.column("unique candidates")) if d >= 0]
        if not points or np.ptp([d for d, _, _ in points]) == 0:
            continue
        drawn = True
        depth, time, candidates = (np.array(v) for v in zip(*points))
        label = f"{series_label(bench, files)} - r{bench.resolution}"
        color = method_color(bench, files) if len({f.resolution for f in files}) == 1 else None
        dots = time_ax.scatter(depth, time, s=10, label=label, color=color)
        if bench.header.get("hashing algorithm") != "none":  # the grid methods, as in the thesis
            pairs_ax.scatter(depth, candidates, s=10, label=label, color=dots.get_facecolor()[0])
            if len(depth) >= 4 and np.ptp(depth) > 0:
                fit = np.polyfit(depth, candidates, 3)
                line = np.linspace(depth.min(), depth.max(), 100)
                pairs_ax.plot(line, np.polyval(fit, line), linewidth=1.0, linestyle="--", color=dots.get_facecolor()[0])
    if not drawn:
        plt.close(fig)
        return
    time_ax.set(xlabel="bounding-box overlap along x", ylabel="frame time (ms)", title="(a) frame time")
    pairs_ax.set(xlabel="bounding-box overlap along x", ylabel="unique candidate pairs",
                 title="(b) potential pairs, cubic fit dashed")
    for ax in (time_ax, pairs_ax):
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle(f"{scene}: penetration depth (box overlap along x), without self-collisions")
    save(fig, path, written)


def memory_figure(files: list[BenchFile], title: str, path: str, written: list[str]) -> None:
    case_of = {(f.resolution, f.scene, f.total_tets): f for f in files}
    cases = sorted(case_of)
    series = sorted({series_label(f, files) for f in files})
    height = 0.8 / len(series)
    fig, ax = plt.subplots(figsize=(8, 1.0 + 0.45 * len(cases) * len(series)))
    for m, label in enumerate(series):
        of_series = [f for f in files if series_label(f, files) == label]
        mib = []
        for case in cases:
            match = [f for f in of_series if (f.resolution, f.scene, f.total_tets) == case]
            mib.append(max(int(f.header.get("peak memory bytes", "0")) for f in match) / 2**20 if match else 0.0)
        ax.barh(np.arange(len(cases)) + m * height, mib, height=height, label=label, color=method_color(of_series[0], files))
    ax.set_yticks(np.arange(len(cases)) + 0.4 - height / 2, [case_label(case_of[c], files) for c in cases],
                  fontsize=8)
    ax.set_xlabel("peak detector memory (MiB)")
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    ax.grid(axis="x", alpha=0.3)
    ax.set_title(title)
    save(fig, path, written)


def total_time_figure(files: list[BenchFile], path: str, written: list[str]) -> None:
    methods = sorted({f.algorithm for f in files})
    fig, ax = plt.subplots(figsize=(7, 4))
    labels = {"no": "without self-collisions", "yes": "with self-collisions",
              "scene": "self-collisions the scene marks"}
    settings = [s for s in labels if any(f.self_setting == s for f in files)]
    width = 0.8 / len(settings)
    for s, setting in enumerate(settings):
        totals = [sum(sum(f.column("device time")) for f in files
                      if f.algorithm == m and f.self_setting == setting) for m in methods]
        ax.bar(np.arange(len(methods)) + width * s, totals, width=width, label=labels[setting])
    ax.set_xticks(np.arange(len(methods)) + 0.4 - width / 2, methods)
    ax.set_ylabel("summed frame times (ms)")
    ax.set_title("Total time over all benchmarks")
    ax.legend(fontsize=8)
    ax.grid(axis="y", alpha=0.3)
    save(fig, path, written)


def plot_folder(folder: str, out: str) -> list[str]:
    """Writes every figure the files of `folder` allow into `out`; returns the paths written."""
    averages, raw = read_folder(folder)
    if not averages:
        raise ValueError(f"{folder}: no kdet bench CSV files")
    os.makedirs(out, exist_ok=True)
    written: list[str] = []
    for self_collisions in (False, True):
        files = [f for f in averages if f.self_collisions == self_collisions]
        if not files:
            continue
        with_self = " with self-collisions" if self_collisions else ""
        grid_figure(files, draw_frame_times, "Frame times" + with_self,
                    os.path.join(out, f"frame_times{suffix(self_collisions)}.png"), written)
        memory_figure(files, "Detector memory" + with_self,
                      os.path.join(out, f"memory{suffix(self_collisions)}.png"), written)
    for (setting_name, self_collisions), (label, files) in sorted(by_setting(averages).items()):
        name = f"{setting_name}{suffix(self_collisions)}"
        with_self = ", with self-collisions" if self_collisions else ""
        grid_figure(files, draw_stages, f"Time per stage: {label}{with_self}",
                    os.path.join(out, f"stages_{name}.png"), written)
        grid_figure(files, draw_host_vs_device, f"Host vs device time: {label}{with_self}",
                    os.path.join(out, f"host_vs_device_{name}.png"), written)
        boxplot_figure(files, f"Frame times: {label}{with_self}", os.path.join(out, f"boxplot_{name}.png"), written)
    for (setting_name, self_collisions), (label, files) in sorted(by_setting(raw).items()):
        with_self = ", with self-collisions" if self_collisions else ""
        grid_figure(files, draw_run_spread, f"Spread over the runs: {label}{with_self}",
                    os.path.join(out, f"run_spread_{setting_name}{suffix(self_collisions)}.png"), written)
    # The box overlap along x is that of a scene's first two objects: a depth only where there are two.
    for scene in sorted({f.scene for f in averages if int(f.header.get("#objects", "2")) == 2}):
        files = [f for f in averages if f.scene == scene and not f.self_collisions]
        penetration_figure(scene, files, os.path.join(out, f"penetration_{scene}.png"), written)
    total_time_figure(averages, os.path.join(out, "total_time.png"), written)
    return written


class OneLineParser(argparse.ArgumentParser):
    """Usage mistakes in one line and exit 2, as every kdet command reports them."""

    def error(self, message: str):
        self.exit(2, f"{self.prog}: {message} (see '{self.prog} --help')\n")


def main() -> int:
    parser = OneLineParser(prog="kdet plot", description="Figures from the CSV files of kdet bench.")
    parser.add_argument("folder", help="folder with the CSV files of kdet bench")
    parser.add_argument("--out", help="folder for the PNG files (default: FOLDER/plots)")
    args = parser.parse_args()
    try:
        written = plot_folder(args.folder, args.out or os.path.join(args.folder, "plots"))
    except (OSError, ValueError) as error:
        print(f"kdet plot: {error}", file=sys.stderr)
        return 1
    for path in written:
        print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
