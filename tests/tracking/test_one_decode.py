"""A video file decoded once by a threaded run: one pass held for the bootstrap and tracking.

The spread bootstrap wants 30 frames spread over the whole file, and a file whose frames
predict one another (H.264, MPEG-4) decodes whole for them; the tracking pass then decoded it
again. With threads, :func:`pftrack.tracking.run.track_frames` now holds the frames of one
pass for both when they fit :func:`pftrack.tracking.run.hold_budget`
(:meth:`pftrack.io.video.FrameSource.held_frames`): the same rows, warnings and frames, one
decode. A pass that finds what the two passes read otherwise (frames that fail to decode) is
undone, and the run reads as before.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from pftrack.cli import main
from pftrack.io.video import FrameSource
from pftrack.synthetic import make_scene
from pftrack.tracking.run import HOLD_VARIABLE, hold_budget, track_frames
from tests.io.encode import encode
from tests.tracking.test_damaged_start import _damaged_start


def _walk(tmp_path: Path) -> Path:
    """An H.264 walk of 40 frames of 160x120, key frames every 10, B-frames (2.3 MB decoded)."""
    scene = make_scene(n_frames=40, width=160, height=120, rng=0)
    return encode(tmp_path / "walk.mp4", scene.frames, options={"g": "10", "bf": "2"})


class _Passes:
    """Counts the passes over a FrameSource's file: iterations and ``frames_at`` reads."""

    def __init__(self, monkeypatch: pytest.MonkeyPatch) -> None:
        self.iterated = 0
        self.picked = 0
        iterate, pick = FrameSource._iter_stored, FrameSource.frames_at

        def counted_iterate(source: FrameSource) -> Iterator[np.ndarray]:
            self.iterated += 1
            return iterate(source)

        def counted_pick(source: FrameSource, *args: Any, **kwargs: Any) -> list[np.ndarray]:
            self.picked += 1
            return pick(source, *args, **kwargs)

        monkeypatch.setattr(FrameSource, "_iter_stored", counted_iterate)
        monkeypatch.setattr(FrameSource, "frames_at", counted_pick)


def _said(fn: Callable[[], Any]) -> tuple[Any, list[str]]:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        out = fn()
    return out, [str(w.message) for w in caught]


def test_a_threaded_run_decodes_the_file_once_with_the_same_rows(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = _walk(tmp_path)
    passes = _Passes(monkeypatch)
    held = track_frames(path, threads=True).rows
    assert (passes.iterated, passes.picked) == (1, 0)  # was (1, 1): bootstrap, then tracking
    monkeypatch.setenv(HOLD_VARIABLE, "0")  # never hold: the two passes of before
    twice = track_frames(path, threads=True).rows
    assert (passes.iterated, passes.picked) == (2, 1)
    serial = track_frames(path, threads=False).rows  # never held on one thread
    assert (passes.iterated, passes.picked) == (3, 2)
    assert len(held) and held.tobytes() == twice.tobytes() == serial.tobytes()


def test_frames_past_the_budget_are_not_held(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = _walk(tmp_path)  # 40 * 160 * 120 * 3 bytes: 2.2 MB
    monkeypatch.setenv(HOLD_VARIABLE, "2")
    assert hold_budget() == 2 << 20
    source = FrameSource(path)
    assert source.held_frames(40 * 160 * 120 * 3 - 1) is None
    frames = source.held_frames(40 * 160 * 120 * 3)
    assert frames is not None
    passes = _Passes(monkeypatch)
    track_frames(path, threads=True)
    assert (passes.iterated, passes.picked) == (1, 1)  # two decodes, as before
    # the frames held are those a pass gives, pixel for pixel
    again = list(FrameSource(path))
    assert len(frames) == len(again) == 40
    assert all(np.array_equal(a, b) for a, b in zip(frames, again, strict=True))


def test_image_folders_are_not_held(tmp_path: Path) -> None:
    import cv2

    folder = tmp_path / "img1"
    folder.mkdir()
    for k, frame in enumerate(make_scene(n_frames=5, width=64, height=64, rng=0).frames, 1):
        cv2.imwrite(str(folder / f"{k:06d}.png"), frame)
    assert FrameSource(folder).held_frames(1 << 30) is None  # only the chosen images are read


@pytest.mark.parametrize("value", ["lots", "-1", "1.5"])
def test_a_bad_budget_is_refused_in_one_line(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], value: str
) -> None:
    path = _walk(tmp_path)
    monkeypatch.setenv(HOLD_VARIABLE, value)
    message = rf"^PFTRACK_HOLD_MB is '{value}', expected an int >= 0 \(MB of decoded frames"
    with pytest.raises(ValueError, match=message):
        track_frames(path, threads=True)
    assert main(["track", str(path), "--out", str(tmp_path / "t.txt")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "PFTRACK_HOLD_MB is" in err[0], err
    assert not (tmp_path / "t.txt").exists()


def test_a_pass_that_finds_damage_is_undone_and_read_as_before(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    damaged = _damaged_start(tmp_path)  # frames 1-10 do not decode: black stand-ins
    passes = _Passes(monkeypatch)
    run, said = _said(lambda: track_frames(damaged, threads=True))
    assert passes.picked == 1  # the bootstrap's own pass, after the held one was undone
    monkeypatch.setenv(HOLD_VARIABLE, "0")
    before, said_before = _said(lambda: track_frames(damaged, threads=True))
    assert said == said_before  # the warning the undone pass held is said, once, as before
    assert len([m for m in said if "could not be decoded" in m]) == 1, said
    assert run.rows.tobytes() == before.rows.tobytes()
