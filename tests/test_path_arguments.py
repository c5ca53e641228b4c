"""A path argument given something that is not a path is refused naming the argument.

Each call here failed inside pathlib or os with ``expected str, bytes or os.PathLike object,
not NoneType``, naming neither the function nor the argument (``write_mot(None, rows)``,
``read_mot(frame_number)``, arguments swapped: ``VideoWriter(25.0, "out.mp4")``).
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

import pftrack

ROWS = np.array([[1, 1, 10, 10, 5, 5, 1, -1, -1, -1.0]])
FRAME = np.zeros((8, 8, 3), np.uint8)

CALLS: dict[str, Callable[[object], object]] = {
    "read_mot": lambda p: pftrack.read_mot(p),  # type: ignore[arg-type]
    "write_mot": lambda p: pftrack.write_mot(p, ROWS),  # type: ignore[arg-type]
    "load_detections": lambda p: pftrack.load_detections(p),  # type: ignore[arg-type]
    "read_seqinfo": lambda p: pftrack.read_seqinfo(p),  # type: ignore[arg-type]
    "VideoWriter": lambda p: pftrack.VideoWriter(p, 10.0),  # type: ignore[arg-type]
    "TrackRenderer": lambda p: pftrack.TrackRenderer(p, 10.0),  # type: ignore[arg-type]
    "plot_trajectories": lambda p: pftrack.plot_trajectories(p, ROWS),  # type: ignore[arg-type]
    "write_annotated_video": lambda p: pftrack.write_annotated_video(  # type: ignore[arg-type]
        p, [FRAME], ROWS
    ),
}


# ids the same in every process (pytest-xdist's workers must collect the same names): an
# object()'s repr holds its address
@pytest.mark.parametrize(
    "value",
    [None, 3, 2.5, ROWS, ["a.txt"], object()],
    ids=lambda v: "object()" if type(v) is object else repr(v),
)
@pytest.mark.parametrize("name", list(CALLS))
def test_a_path_of_the_wrong_type_is_named(name: str, value: object) -> None:
    with pytest.raises(TypeError) as info:
        CALLS[name](value)
    message = str(info.value)
    assert message.startswith(f"{name}: path must be a str or os.PathLike, got "), message
    assert type(value).__name__ in message
    assert "\n" not in message


@pytest.mark.parametrize("name", ["write_mot", "plot_trajectories", "VideoWriter"])
def test_bytes_str_and_path_name_the_same_file(name: str, tmp_path: Path) -> None:
    suffix = {"write_mot": ".txt", "plot_trajectories": ".png", "VideoWriter": ".avi"}[name]
    for k, make in enumerate((str, Path, lambda p: str(p).encode())):
        target = tmp_path / f"out{k}{suffix}"
        out = CALLS[name](make(target))
        if isinstance(out, pftrack.VideoWriter):
            out.write(FRAME)
            out.close()
        assert target.is_file()
