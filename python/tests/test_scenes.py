"""The benchmark scenes from Python (kdet.open_scene, kdet.run_scene): each of issue 46's scenes gives,
frame by frame, the pairs `kdet bench` finds in it (its CSV's "collision pairs"), the torn slab's
pairs equal brute force on its tets of the frame, and heap's filtered pairs equal brute force with the
same filters."""

from __future__ import annotations

import subprocess
from pathlib import Path

import numpy as np
import pytest

import kdet


def bench_pair_counts(cli: Path, tmp_path: Path, scene: str, *flags: str) -> dict[int, int]:
    """Frame -> "collision pairs" of `kdet bench SCENE FLAGS -n 1`."""
    out = tmp_path / "bench"
    subprocess.run([str(cli), "bench", scene, *flags, "-n", "1", "--quiet", "-d", str(out)], check=True, capture_output=True)
    (csv,) = [p for p in out.glob("*.csv") if not p.name.endswith("_runs.csv")]
    lines = csv.read_text().splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("frame,"))
    columns = [c.strip() for c in lines[start].split(",")]
    frame, pairs = columns.index("frame"), columns.index("collision pairs")
    rows = [[c.strip() for c in line.split(",")] for line in lines[start + 1 :] if line.strip()]
    return {int(r[frame]): int(r[pairs]) for r in rows}


def scene_pair_counts(scene: kdet.Scene, first: int, last: int, self_collision: bool) -> dict[int, int]:
    runs = kdet.run_scene(scene, self_collision=self_collision, first_frame=first, last_frame=last, test="sat")
    return {frame: len(result.pairs) for frame, result in runs}


@pytest.mark.parametrize(
    "name, resolution, first, last, self_collision",
    [
        ("tearing", 1, 40, 43, False),
        ("tearing", 1, 60, 62, True),
        ("heap", 1, 100, 102, False),
        ("drape", 1, 80, 81, True),
        ("graded", 1, 59, 60, False),
        ("pass_through_deep", 2, 60, 61, False),
    ],
)
def test_scene_frames_match_kdet_bench(cli, models, tmp_path, monkeypatch, name, resolution, first, last, self_collision):
    monkeypatch.setenv("KDET_DATA_DIR", str(models))
    scene = kdet.open_scene(name, resolution=resolution)
    assert scene.name == name
    assert name in kdet.scene_names()
    counts = scene_pair_counts(scene, first, last, self_collision)
    resolution_flags = ["-r", str(resolution)] if scene.resolution else []  # tearing has none
    expected = bench_pair_counts(
        cli, tmp_path, name, *resolution_flags, "--frames", f"{first}:{last}", "-s", "yes" if self_collision else "no"
    )
    assert counts == expected
    assert any(counts.values()), f"{name} frames {first}-{last} have pairs"


def test_torn_slab_pairs_equal_brute_force_on_the_frames_tets():
    scene = kdet.open_scene("tearing")
    assert scene.changes_tets
    whole = scene.rest_mesh(0).tets
    results = {frame: result.pairs.copy() for frame, result in kdet.run_scene(scene, first_frame=47, last_frame=50)}
    for frame in (47, 50):
        tets = scene.tets(0, frame)
        assert len(tets) < len(whole), "the slab has lost tets"
        reference = kdet.Detector(method="brute_force_loop")
        for o in range(scene.num_objects):
            mesh = scene.rest_mesh(o)
            reference.add_object(kdet.TetMesh(mesh.vertices, scene.tets(o, frame)))
            reference.set_positions(o, scene.positions(o, frame))
        np.testing.assert_array_equal(results[frame], reference.detect().pairs)
        assert len(results[frame]) > 0


def test_heap_filters_equal_brute_force_with_the_same_filters():
    scene = kdet.open_scene("heap")
    assert scene.is_static(0) and not scene.is_static(1)
    groups = {scene.collision_filter(o)[0] for o in range(1, scene.num_objects)}
    assert groups == {2, 4}, "two layer groups"
    last = scene.num_frames - 1
    (_, filtered), = list(kdet.run_scene(scene, first_frame=last))
    filtered = filtered.pairs.copy()
    (_, brute), = list(kdet.run_scene(scene, first_frame=last, method="brute_force_loop"))
    np.testing.assert_array_equal(filtered, brute.pairs)
    # Without the filters, bodies side by side in a layer collide too.
    unfiltered = kdet.Detector()
    for o in range(scene.num_objects):
        unfiltered.add_object(scene.rest_mesh(o))
        unfiltered.set_positions(o, scene.positions(o, last))
    every = unfiltered.detect().pairs
    group = np.array([scene.collision_filter(o)[0] for o in range(scene.num_objects)])
    same_layer = (every[:, 0] != 0) & (group[every[:, 0]] == group[every[:, 2]])
    assert same_layer.any()
    np.testing.assert_array_equal(filtered, every[~same_layer])


def test_a_recorded_heap_plays_back_as_the_heap(tmp_path):
    heap = kdet.open_scene("heap")
    kdet.write_recording(heap, tmp_path / "heap.kdetrec")
    played = kdet.open_scene(tmp_path / "heap.kdetrec")
    assert played.name == "heap" and played.num_frames == heap.num_frames
    for o in range(heap.num_objects):
        assert played.is_static(o) == heap.is_static(o)
        assert played.collision_filter(o) == heap.collision_filter(o)
    last = heap.num_frames - 1
    (_, recorded), = list(kdet.run_scene(played, first_frame=last))
    (_, built), = list(kdet.run_scene(heap, first_frame=last))
    assert len(built.pairs) > 0
    np.testing.assert_array_equal(recorded.pairs, built.pairs)
    with pytest.raises(kdet.Error, match="scene tearing changes its tets from frame to frame"):
        kdet.write_recording(kdet.open_scene("tearing"), tmp_path / "tearing.kdetrec")


def test_self_collision_of_the_objects_the_scene_marks():
    drape = kdet.open_scene("drape")
    assert drape.checks_self(1) and not drape.checks_self(0)  # the sheet, not the static ball
    last = drape.num_frames - 1
    (_, marked), = list(kdet.run_scene(drape, self_collision="scene", first_frame=last))
    marked = marked.pairs.copy()
    (_, none), = list(kdet.run_scene(drape, first_frame=last))
    assert len(marked) > len(none.pairs), "the folded sheet's self pairs"
    assert ((marked[:, 0] == 1) & (marked[:, 2] == 1)).any()
    with pytest.raises(kdet.Error, match=r"^self_collision: 'yes' is not a choice \(True, False or 'scene'\)$"):
        kdet.add_scene_objects(kdet.Detector(), drape, "yes")


def test_scene_bad_input():
    scene = kdet.open_scene("tearing")
    with pytest.raises(kdet.Error, match=r"^scene tearing: object 5 out of range \(2 objects\)$"):
        scene.positions(5, 0)
    with pytest.raises(kdet.Error, match=r"^scene tearing: frame 120 out of range \(120 frames\)$"):
        scene.tets(0, 120)
    with pytest.raises(kdet.Error, match="unknown scene 'nope'"):
        kdet.open_scene("nope")
    for name in ("tearing", "procedural", "pass_through_armadillos"):
        with pytest.raises(kdet.Error, match=rf"^{name}: resolution -1000000 out of range \[1, 4\]$"):
            kdet.open_scene(name, resolution=-1000000)
    with pytest.raises(kdet.Error, match="^tets: -5 is negative$"):
        kdet.open_scene("procedural", tets=-5)
    with pytest.raises(kdet.Error, match="missing.scene: cannot open scene file"):
        kdet.open_scene(Path("missing.scene"))  # paths as os.PathLike, as the mesh functions take them
    with pytest.raises(ValueError, match="frames 5 to 200 out of range"):
        next(kdet.run_scene(scene, first_frame=5, last_frame=200))
