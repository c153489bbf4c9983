"""kdet.run_scene(): plays a benchmark scene into a Detector frame by frame, as `kdet bench` does."""

from __future__ import annotations

from typing import Any, Iterator, Optional, Tuple, Union

import numpy as np

from ._kdet import Detector, FrameResult, Scene, add_scene_objects


def run_scene(
    scene: Scene,
    detector: Optional[Detector] = None,
    *,
    self_collision: Union[bool, str] = False,
    first_frame: int = 0,
    last_frame: Optional[int] = None,
    **options: Any,
) -> Iterator[Tuple[int, FrameResult]]:
    """Yields (frame, result) for frames first_frame to last_frame (default: the scene's last), inclusive.

    The scene's objects are added to `detector` (a new Detector(**options) when None) with
    add_scene_objects() (self_collision: True, False or 'scene', as `kdet bench -s`); every frame, the tets of an object whose tets changed are set (set_tets), the
    positions of every moving object are set, and the detector detects. A static object's positions are
    given at the first frame only: it stays placed, as `kdet bench` keeps it."""
    if detector is None:
        detector = Detector(**options)
    elif options:
        raise TypeError("run_scene: give either a detector or its options, not both")
    last = scene.num_frames - 1 if last_frame is None else last_frame
    if not 0 <= first_frame <= last < scene.num_frames:
        raise ValueError(f"run_scene: frames {first_frame} to {last} out of range (the scene has {scene.num_frames})")
    first_id = detector.object_count
    add_scene_objects(detector, scene, self_collision)
    objects = range(scene.num_objects)
    tets = [scene.rest_mesh(o).tets for o in objects] if scene.changes_tets else []
    for frame in range(first_frame, last + 1):
        for o in range(len(tets)):
            now = scene.tets(o, frame)
            if not np.array_equal(now, tets[o]):
                detector.set_tets(first_id + o, now)
                tets[o] = now
        for o in objects:
            if frame == first_frame or not scene.is_static(o):
                detector.set_positions(first_id + o, scene.positions(o, frame))
        yield frame, detector.detect()
