"""An earlier run's output of each kind, as pftrack writes it, for the tests of outputs kept.

Every output option replaces only a file of its kind that pftrack wrote (docs/io.md, "What an
output may replace"): a test that checks an earlier output is kept, or replaced, needs one
that the output check takes for pftrack's (a user's file is refused before any work).
"""

from __future__ import annotations

import json
from pathlib import Path

import cv2
import numpy as np

from pftrack.io.marks import json_marked, mark_image

#: An earlier run's tracks (MOTChallenge rows: anyone's are replaced).
TRACKS = b"1,1,10,10,5,5,1,-1,-1,-1\n"


def earlier(suffix: str) -> bytes:
    """An earlier pftrack output of the kind `suffix` names (``.txt``, ``.json``, ...)."""
    suffix = suffix.lower()
    if suffix in (".png", ".jpg", ".jpeg"):
        return mark_image(cv2.imencode(suffix, np.full((4, 4, 3), 9, np.uint8))[1].tobytes())
    if suffix == ".json":
        return json.dumps(json_marked({"earlier": True}, "eval"), indent=2).encode() + b"\n"
    if suffix == ".csv":
        return b"sequence,hota,det_a\nearlier,0.5,0.4\n"
    return TRACKS


def write_earlier(path: Path) -> bytes:
    """Write :func:`earlier` of `path`'s kind at `path` (a video: a pftrack render); its bytes."""
    if path.suffix.lower() in (".mp4", ".avi"):
        from pftrack.io.video_writer import VideoWriter

        with VideoWriter(path, fps=5) as writer:
            writer.write(np.zeros((16, 16, 3), np.uint8))
        return path.read_bytes()
    data = earlier(path.suffix)
    path.write_bytes(data)
    return data
