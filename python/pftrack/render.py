"""Pictures people would rather look at than read: annotated video and trajectory plots (OpenCV)."""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path

import cv2
import numpy as np
from numpy.typing import NDArray

from pftrack._typing import PathLike
from pftrack.io.atomic import atomic_path
from pftrack.io.mot import group_by_frame

__all__ = ["colour_of", "draw_tracks", "plot_trajectories", "write_annotated_video"]


def colour_of(track_id: int) -> tuple[int, int, int]:
    """A stable, distinct BGR colour for an id (golden-ratio hue steps)."""
    hue = int((track_id * 0.618033988749895 % 1.0) * 179)
    hsv = np.array([[[hue, 220, 255]]], dtype=np.uint8)
    b, g, r = cv2.cvtColor(hsv, cv2.COLOR_HSV2BGR)[0, 0]
    return int(b), int(g), int(r)


def draw_tracks(
    frame: NDArray[np.uint8], rows: NDArray[np.float64], label: str = ""
) -> NDArray[np.uint8]:
    """Draw MOT rows (k, 6+) of one frame on a copy of `frame`: boxes and ids (dashed if filled)."""
    out: NDArray[np.uint8] = frame.copy()
    for r in rows:
        tid = int(r[1])
        x, y, w, h = (int(round(v)) for v in r[2:6])
        c = colour_of(tid)
        cv2.rectangle(out, (x, y), (x + w, y + h), c, 1 if len(r) > 7 and r[7] == 1 else 2)
        cv2.putText(
            out, str(tid), (x, max(10, y - 3)), cv2.FONT_HERSHEY_SIMPLEX, 0.4, c, 1, cv2.LINE_AA
        )
    if label:
        cv2.putText(
            out, label, (5, 15), cv2.FONT_HERSHEY_SIMPLEX, 0.45, (255, 255, 255), 1, cv2.LINE_AA
        )
    return out


def write_annotated_video(
    path: PathLike,
    frames: Iterable[NDArray[np.uint8]],
    rows: NDArray[np.float64],
    fps: float = 10.0,
) -> Path:
    """Write `frames` with the tracks of `rows` (MOT, 1-based frames) drawn on, atomically.

    The container follows the extension (``.mp4`` uses the ``mp4v`` codec, ``.avi`` MJPG).
    """
    target = Path(path)
    fourcc = cv2.VideoWriter.fourcc(*("MJPG" if target.suffix.lower() == ".avi" else "mp4v"))
    by_frame = group_by_frame(rows)
    with atomic_path(target) as tmp:
        writer = None
        try:
            for k, frame in enumerate(frames, start=1):
                if writer is None:
                    h, w = frame.shape[:2]
                    writer = cv2.VideoWriter(str(tmp), fourcc, float(fps), (w, h))
                    if not writer.isOpened():
                        raise ValueError(
                            f"OpenCV cannot write video {target} (codec for {target.suffix!r}?)"
                        )
                empty = np.zeros((0, 10))
                writer.write(draw_tracks(frame, by_frame.get(k, empty), f"frame {k}"))
        finally:
            if writer is not None:
                writer.release()
    return target


def plot_trajectories(
    path: PathLike,
    rows: NDArray[np.float64],
    background: NDArray[np.uint8] | None = None,
    size: tuple[int, int] | None = None,
    truth: NDArray[np.float64] | None = None,
    title: str = "",
) -> Path:
    """Draw each track's foot-point path (bottom centre of its box) as a PNG, atomically.

    Parameters
    ----------
    path : str or os.PathLike
        Output image (``.png``).
    rows : (M, 6+) ndarray
        MOT rows of the tracks.
    background : (H, W, 3) ndarray of uint8, optional
        Image to draw on (e.g. the first frame), dimmed.
    size : (W, H), optional
        Canvas size when there is no background.
    truth : (M, 6+) ndarray, optional
        Ground truth, drawn thin and grey under the tracks.
    title : str
        Caption.
    """
    if background is not None:
        canvas = (background.astype(np.float32) * 0.45).astype(np.uint8)
    else:
        w, h = size or (int(np.nanmax(rows[:, 2] + rows[:, 4], initial=320)) + 10,
                        int(np.nanmax(rows[:, 3] + rows[:, 5], initial=240)) + 10)  # fmt: skip
        canvas = np.full((h, w, 3), 30, np.uint8)

    def paths(r: NDArray[np.float64]) -> dict[int, NDArray[np.int32]]:
        out = {}
        for tid in np.unique(r[:, 1]).astype(int):
            t = r[r[:, 1] == tid]
            t = t[np.argsort(t[:, 0])]
            pts = np.column_stack([t[:, 2] + t[:, 4] / 2, t[:, 3] + t[:, 5]])
            out[tid] = np.round(pts).astype(np.int32)
        return out

    if truth is not None and len(truth):
        for pts in paths(truth).values():
            cv2.polylines(canvas, [pts.reshape(-1, 1, 2)], False, (170, 170, 170), 1, cv2.LINE_AA)
    for tid, pts in paths(rows).items() if len(rows) else []:
        c = colour_of(tid)
        cv2.polylines(canvas, [pts.reshape(-1, 1, 2)], False, c, 2, cv2.LINE_AA)
        cv2.circle(canvas, tuple(int(v) for v in pts[-1]), 3, c, -1)
        cv2.putText(
            canvas,
            str(tid),
            tuple(int(v) for v in pts[0]),
            cv2.FONT_HERSHEY_SIMPLEX,
            0.4,
            c,
            1,
            cv2.LINE_AA,
        )
    if title:
        cv2.putText(
            canvas, title, (5, 15), cv2.FONT_HERSHEY_SIMPLEX, 0.45, (255, 255, 255), 1, cv2.LINE_AA
        )
    target = Path(path)
    with atomic_path(target) as tmp:
        if not cv2.imwrite(str(tmp), canvas):
            raise ValueError(f"OpenCV cannot write image {target}")
    return target
