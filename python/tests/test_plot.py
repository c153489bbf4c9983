"""`kdet plot` on the CSV files of `kdet bench`: the figures it promises are written, runs that differ in
a setting are drawn apart, and a case whose box overlap along x never changes gets no penetration
figure (one column of dots says nothing)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

pytest.importorskip("matplotlib", reason="kdet plot needs matplotlib")


def run(command: list[str], models: Path | None = None) -> subprocess.CompletedProcess:
    # `kdet plot` runs `python3` from PATH: the interpreter of these tests, which has matplotlib.
    env = dict(os.environ, PATH=f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}")
    if models is not None:
        env["KDET_DATA_DIR"] = str(models)
    return subprocess.run(command, capture_output=True, text=True, env=env, timeout=300)


@pytest.fixture(scope="module")
def bench_folder(cli: Path, models: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("bench")
    # The armadillos move along x (their overlap grows frame by frame); the tearing scene's box moves
    # along y and z only.
    for scene, frames in (("pass_through_armadillos", "100:103"), ("tearing", "0:3")):
        done = run([str(cli), "bench", scene, "-n", "1", "--frames", frames, "-d", str(folder),
                    "--quiet"], models=models)
        assert done.returncode == 0, done.stderr
    return folder


def test_plot_writes_the_figures_it_lists(cli: Path, bench_folder: Path) -> None:
    done = run([str(cli), "plot", str(bench_folder)])
    assert done.returncode == 0, done.stderr
    written = {Path(line.split(" ", 1)[1]).name for line in done.stdout.splitlines() if line.startswith("wrote ")}
    expected = {"frame_times.png", "memory.png", "stages_kdet.png", "host_vs_device_kdet.png", "boxplot_kdet.png",
                "run_spread_kdet.png", "total_time.png", "penetration_pass_through_armadillos.png"}
    assert expected <= written
    for name in written:
        png = bench_folder / "plots" / name
        assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", name


def test_no_penetration_figure_when_the_overlap_never_changes(cli: Path, bench_folder: Path) -> None:
    done = run([str(cli), "plot", str(bench_folder), "--out", str(bench_folder / "again")])
    assert done.returncode == 0, done.stderr
    assert (bench_folder / "again" / "penetration_pass_through_armadillos.png").exists()
    assert not (bench_folder / "again" / "penetration_tearing.png").exists()


def test_runs_that_differ_in_a_setting_get_figures_of_their_own(cli: Path, models: Path, tmp_path: Path) -> None:
    # Two tests of one method, and a margin (its own case, as in the file names): no figure draws one of
    # them in place of the others.
    for extra in (["-o", "sat"], ["-o", "exact"], ["-o", "sat", "--margin", "0.01"]):
        done = run([str(cli), "bench", "tearing", "-n", "1", "--frames", "0:1", "-d", str(tmp_path), "--quiet"] + extra,
                   models=models)
        assert done.returncode == 0, done.stderr
    done = run([str(cli), "plot", str(tmp_path)])
    assert done.returncode == 0, done.stderr
    written = {Path(line.split(" ", 1)[1]).name for line in done.stdout.splitlines() if line.startswith("wrote ")}
    for figure in ("stages", "host_vs_device", "boxplot", "run_spread"):
        assert {f"{figure}_kdet_overlap-test-sat.png", f"{figure}_kdet_overlap-test-exact.png"} <= written, figure
        assert f"{figure}_kdet.png" not in written, figure


def test_plot_of_a_folder_without_csv_files_fails_with_one_line(cli: Path, tmp_path: Path) -> None:
    done = run([str(cli), "plot", str(tmp_path)])
    assert done.returncode != 0
    assert done.stderr.strip() == f"kdet plot: {tmp_path}: no kdet bench CSV files"


@pytest.mark.parametrize("arguments", [[], ["FOLDER", "--frobnicate"], ["FOLDER", "--out"]])
def test_plot_usage_mistakes_give_one_line_and_exit_2(cli: Path, tmp_path: Path, arguments: list[str]) -> None:
    done = run([str(cli), "plot"] + [str(tmp_path) if a == "FOLDER" else a for a in arguments])
    assert done.returncode == 2
    assert len(done.stderr.splitlines()) == 1, done.stderr
    assert done.stderr.startswith("kdet plot: ") and done.stderr.rstrip().endswith("(see 'kdet plot --help')")


def test_plot_help_names_the_command(cli: Path) -> None:
    done = run([str(cli), "plot", "--help"])
    assert done.returncode == 0
    assert done.stdout.startswith("usage: kdet plot ")
