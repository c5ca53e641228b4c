"""Box refinement cleans the foreground mask at the given boxes only (BlobExtractor.only_regions):
the tracker's rows are those of the whole cleaning, byte for byte, and ``last_mask`` is the whole
cleaned mask, on demand."""

from __future__ import annotations

import hashlib

import numpy as np
import pytest

import pftrack
from pftrack.detection.base import BlobExtractor
from pftrack.detection.paper import PaperDetector, foreground_only
from pftrack.synthetic import make_scene
from pftrack.tracking.tracker import MultiObjectTracker


@pytest.fixture(scope="module")
def scene_dets() -> tuple[list[np.ndarray], list[np.ndarray]]:
    """A synthetic scene of 8 walkers; the truth's boxes as detections (x1, y1, x2, y2, conf)."""
    scene = make_scene(n_frames=40, n_walkers=8, rng=4, occluder=False)
    frames, dets = list(scene.frames), []
    for n in range(1, len(frames) + 1):
        r = scene.truth[scene.truth[:, 0] == n]
        dets.append(np.column_stack([r[:, 2:4], r[:, 2:4] + r[:, 4:6], np.full(len(r), 0.9)]))
    return frames, dets


def _run(
    frames: list[np.ndarray],
    dets: list[np.ndarray],
    masks: list[np.ndarray] | None = None,
    read: list[np.ndarray] | None = None,
) -> tuple[str, int]:
    """The rows' md5 of a fresh tracker, and how many frames were cleaned at the boxes only.

    Appends each frame's ``last_mask`` to `masks`, and the mask refinement read (before
    ``last_mask`` cleans the whole) to `read`.
    """
    tracker = pftrack.Tracker(seed=0, prime=0)
    digest, partial = hashlib.md5(), 0
    for d, f in zip(dets, frames, strict=True):
        digest.update(tracker.update(d, f).tobytes())
        inner: MultiObjectTracker = tracker.tracker
        partial += inner._unclean is not None
        if read is not None:
            assert inner._mask is not None
            read.append(foreground_only(inner._mask))
        if masks is not None:
            masks.append(tracker.tracker.last_mask)
    return digest.hexdigest(), partial


def test_rows_and_last_mask_are_the_whole_cleanings(
    scene_dets: tuple[list[np.ndarray], list[np.ndarray]], monkeypatch: pytest.MonkeyPatch
) -> None:
    frames, dets = scene_dets
    masks: list[np.ndarray] = []
    read: list[np.ndarray] = []
    rows, partial = _run(frames, dets, masks, read)
    assert partial > len(frames) // 2  # the regions path ran (the crops cover less than the frame)
    # the whole mask, cleaned on every frame: only_regions made a no-op
    monkeypatch.setattr(BlobExtractor, "only_regions", lambda self, regions: None)
    whole_masks: list[np.ndarray] = []
    whole_rows, none = _run(frames, dets, whole_masks)
    assert none == 0
    assert rows == whole_rows
    # the same masks as a detector of its own run over the frames, with every pixel cleaned
    detector = PaperDetector()
    for f, d, got, part, want in zip(frames, dets, masks, read, whole_masks, strict=True):
        own, _ = detector.foreground(f, shadows=True, bins=False)
        np.testing.assert_array_equal(got, want)
        np.testing.assert_array_equal(got, foreground_only(own))
        # what refinement read: the whole mask's bytes in every box, 0 or those bytes elsewhere
        assert np.all((part == 0) | (part == want))
        for x1, y1, x2, y2 in np.round(d[:, :4]).astype(int):
            inside = (slice(max(y1, 0), max(y2, 0)), slice(max(x1, 0), max(x2, 0)))
            np.testing.assert_array_equal(part[inside], want[inside])


def test_last_mask_before_and_after_a_region_frame(
    scene_dets: tuple[list[np.ndarray], list[np.ndarray]],
) -> None:
    """Read on some frames only: each read is that frame's whole mask; the rows do not change."""
    frames, dets = scene_dets
    plain, _ = _run(frames, dets)
    tracker = pftrack.Tracker(seed=0, prime=0)
    detector = PaperDetector()
    digest = hashlib.md5()
    for k, (d, f) in enumerate(zip(dets, frames, strict=True)):
        digest.update(tracker.update(d, f).tobytes())
        own, _ = detector.foreground(f, bins=False)
        if k % 3 == 0:
            np.testing.assert_array_equal(tracker.tracker.last_mask, own)
            np.testing.assert_array_equal(tracker.tracker.last_mask, own)
    assert digest.hexdigest() == plain
