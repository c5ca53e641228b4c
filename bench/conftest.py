"""Shared fixtures of the benchmarks: where the data is, and PETS09-S2L1 frames.

The data folder is the experiments' (:func:`experiments._common.data_root`: ``$PFTRACK_DATA``
or ``../shared/data``); a benchmark that needs a real sequence skips when it is absent. The frame
fixtures fall back to a random-noise frame, another workload (the histogram kernels run ~4x
slower on it than on PETS09's frame): :func:`frame_source` names the frame they hold, and the
benchmarks that use them put it in their group's name and in ``extra_info["frame"]``.
"""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest
from numpy.typing import NDArray
from pytest_benchmark.fixture import BenchmarkFixture

from bench.recovery_file import synthetic_tracks
from experiments._common import data_root
from pftrack.io.opencv_io import opencv_name


@pytest.fixture(scope="session")
def data_dir() -> Path:
    """The folder holding ``pets09-s2l1/`` and ``tud-campus/`` (it may not exist)."""
    return data_root()


@pytest.fixture(scope="session")
def pets_dir(data_dir: Path) -> Path:
    """The PETS09-S2L1 folder; skips the benchmark when it is absent."""
    folder = data_dir / "pets09-s2l1"
    if not folder.is_dir():
        pytest.skip(f"PETS09-S2L1 not found at {folder}")
    return folder


#: :func:`frame_source` of PETS09-S2L1's frame 100 (the frame fixtures' own frame).
PETS_FRAME = "PETS09-S2L1 frame 100"


def pets_frame(data: Path, size: tuple[int, int]) -> tuple[NDArray[np.uint8], str]:
    """Frame 100 of PETS09-S2L1 resized to `size` (W, H), or a random-noise frame; and its name.

    The name is :data:`PETS_FRAME`, or ``"random noise (...)"`` saying why the video's frame
    was not read: a benchmark on it measures another workload and must say so.
    """
    video = data / "pets09-s2l1" / "video.avi"
    frame = None
    source = f"random noise (no PETS09-S2L1 video at {video})"
    if video.is_file():
        with opencv_name(video) as name:  # any name (pftrack.io.opencv_io)
            cap = cv2.VideoCapture(name)
        cap.set(cv2.CAP_PROP_POS_FRAMES, 100)
        ok, frame = cap.read()
        cap.release()
        frame = frame if ok else None
        source = PETS_FRAME if ok else f"random noise ({video} has no frame 100)"
    if frame is None:
        rng = np.random.default_rng(0)
        frame = rng.integers(0, 256, (360, 480, 3), dtype=np.uint8)
    resized = cv2.resize(frame, size, interpolation=cv2.INTER_LINEAR)
    return np.asarray(resized, dtype=np.uint8), source


@pytest.fixture(scope="session")
def frame_480(data_dir: Path) -> NDArray[np.uint8]:
    return pets_frame(data_dir, (480, 360))[0]


@pytest.fixture(scope="session")
def frame_720(data_dir: Path) -> NDArray[np.uint8]:
    return pets_frame(data_dir, (1280, 720))[0]


@pytest.fixture(scope="session")
def frame_source(data_dir: Path) -> str:
    """What `frame_480` and `frame_720` show: :data:`PETS_FRAME` or ``"random noise (why)"``."""
    return pets_frame(data_dir, (48, 36))[1]


def label_frame(benchmark: BenchmarkFixture, group: str, source: str) -> None:
    """Set `benchmark`'s group, marked ``[random-noise frame]`` unless `source` is PETS09's,
    and ``extra_info["frame"]``: a group never holds another frame under the same name."""
    tag = "" if source == PETS_FRAME else " [random-noise frame]"
    benchmark.group = group + tag
    benchmark.extra_info["frame"] = source


@pytest.fixture(scope="session")
def track_boxes() -> list[tuple[NDArray[np.float64], NDArray[np.bool_]]]:
    """Per track of the 500-track file (`bench/recovery_file.py`): the (T, 4) centre-and-size
    rows over its frame span (NaN in its holes) and which frames are observed, as the offline
    pass builds them (`test_recovery.py` and `test_stonesoup.py` smooth the same tracks)."""
    rows = synthetic_tracks(500, seed=0)
    out = []
    for tid in np.unique(rows[:, 1]):
        r = rows[rows[:, 1] == tid]
        f = (r[:, 0] - r[0, 0]).astype(int)
        z = np.full((f[-1] + 1, 4), np.nan)
        z[f] = np.column_stack([r[:, 2:4] + r[:, 4:6] / 2, r[:, 4:6]])
        has = np.zeros(len(z), bool)
        has[f] = True
        out.append((z, has))
    return out


#: The roles that are not pftrack in a group: a benchmark's ratios are baseline / pftrack.
BASELINES = ("numpy", "filterpy", "stonesoup", "every_pixel")
_MEDIANS: dict[str, dict[str, float]] = {}  # group -> role -> median seconds, this run


def ratios(benchmark: BenchmarkFixture, role: str) -> dict[tuple[str, str], float]:
    """Keep this benchmark's median as `role` of its group, and compare it with the group's.

    Each (pftrack role, baseline) pair of the group measured so far in this run (any bench
    file: Stone Soup's rows join the groups of test_kernels.py and test_recovery.py) gets
    ``baseline / pftrack`` in ``extra_info["x_<baseline>"]`` of the later benchmark
    (``"x_<baseline>_<role>"`` when the later one is the baseline's). Returns those ratios by
    (pftrack role, baseline); none with ``--benchmark-disable`` (no timing).
    """
    if not benchmark.stats:
        return {}
    medians = _MEDIANS.setdefault(benchmark.group, {})
    medians[role] = benchmark.stats.stats.median
    ours = [r for r in medians if r not in BASELINES] if role in BASELINES else [role]
    bases = [role] if role in BASELINES else [b for b in BASELINES if b in medians]
    out = {}
    for base in bases:
        for r in ours:
            out[r, base] = medians[base] / medians[r]
            key = f"x_{base}" if role not in BASELINES else f"x_{base}_{r}"
            benchmark.extra_info[key] = round(out[r, base], 1)
    return out
