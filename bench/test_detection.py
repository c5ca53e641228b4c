"""Detection speed: the fused C++ pass (with and without HSV bins) vs OpenCV's MOG2 vs the
NumPy reference, same frames;
the blob pass, the size model's Theil-Sen line and the light measures (`mean_and_gain`) in C++
vs their Python references.

pytest bench/test_detection.py --benchmark-only --benchmark-group-by=group
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import pytest
from numpy.typing import NDArray
from pytest_benchmark.fixture import BenchmarkFixture

from pftrack import _core
from pftrack.detection import make_detector
from pftrack.io.opencv_io import opencv_name
from tests.reference.blobs import blob_boxes as blob_reference
from tests.reference.blobs import theil_sen as theil_sen_reference
from tests.reference.detection import BackgroundReference

SIZES = {"480x360": (480, 360), "768x576": (768, 576)}
N_FRAMES = 60

Frame = NDArray[np.uint8]
Frames = tuple[str, list[Frame]]  # (size name, frames)


def load_frames(data: Path, size: tuple[int, int]) -> tuple[list[Frame], bool]:
    """60 PETS09-S2L1 frames resized to `size`, or synthetic ones without the data (a block
    moving over smooth noise: another workload); and whether they are PETS09's."""
    video = data / "pets09-s2l1" / "video.avi"
    frames: list[Frame] = []
    if video.is_file():
        with opencv_name(video) as name:  # any name (pftrack.io.opencv_io)
            cap = cv2.VideoCapture(name)
        while len(frames) < N_FRAMES:
            ok, f = cap.read()
            if not ok:
                break
            if f.shape[1::-1] != size:
                f = cv2.resize(f, size, interpolation=cv2.INTER_LINEAR)
            frames.append(np.asarray(f, dtype=np.uint8))
        cap.release()
    if len(frames) < N_FRAMES:
        rng = np.random.default_rng(0)
        small = rng.integers(0, 256, (size[1] // 8, size[0] // 8, 3), dtype=np.uint8)
        bg = np.asarray(cv2.resize(small, size), dtype=np.uint8)
        frames = []
        for k in range(N_FRAMES):
            frame = bg.copy()
            frame[100:180, 10 + 6 * k : 40 + 6 * k] = (40, 60, 200)
            frames.append(frame)
        return frames, False
    return frames, True


@pytest.fixture(scope="module", params=list(SIZES))
def frames(request: pytest.FixtureRequest, data_dir: Path) -> Frames:
    """The size's name, ``"480x360 [synthetic frames]"`` without PETS09's (every group built
    on it then says so), and its frames."""
    frames, pets = load_frames(data_dir, SIZES[request.param])
    return request.param + ("" if pets else " [synthetic frames]"), frames


def cycle_apply(fn: Callable[[Frame], Any], frames: list[Frame]) -> Callable[[], Any]:
    """A no-argument call of `fn` on the next frame, round and round (what is timed)."""
    it = itertools.cycle(frames)
    return lambda: fn(next(it))


def test_core_background_pass(benchmark: BenchmarkFixture, frames: Frames) -> None:
    name, fr = frames
    benchmark.group = f"per-pixel pass {name}"
    m = _core.BackgroundModel()
    m.apply(fr[0])
    benchmark(cycle_apply(m.apply, fr[1:]))


def test_core_background_pass_without_bins(benchmark: BenchmarkFixture, frames: Frames) -> None:
    """The pass as ``PaperDetector.detect`` runs it: no bins (its foreground is binned after)."""
    name, fr = frames
    benchmark.group = f"per-pixel pass {name}"
    m = _core.BackgroundModel()
    m.apply(fr[0])
    benchmark(cycle_apply(lambda f: m.apply(f, bins=False), fr[1:]))


@pytest.fixture(params=[1, 0], ids=["1 thread", "cv2 threads"])
def cv2_threads(request: pytest.FixtureRequest) -> Iterator[int]:
    """OpenCV on one thread (like the C++ pass) or on its default pool."""
    before = cv2.getNumThreads()
    cv2.setNumThreads(request.param if request.param else -1)
    yield request.param
    cv2.setNumThreads(before)


def test_opencv_mog2_apply(benchmark: BenchmarkFixture, frames: Frames, cv2_threads: int) -> None:
    name, fr = frames
    benchmark.group = f"per-pixel pass {name}"
    sub = cv2.createBackgroundSubtractorMOG2(detectShadows=True)
    for f in fr:
        sub.apply(f)
    benchmark(cycle_apply(sub.apply, fr))


def test_numpy_reference(benchmark: BenchmarkFixture, frames: Frames) -> None:
    name, fr = frames
    benchmark.group = f"per-pixel pass {name}"
    ref = BackgroundReference()
    ref.apply(fr[0])
    benchmark.pedantic(cycle_apply(ref.apply, fr[1:]), rounds=10, iterations=1)


@pytest.mark.parametrize("detector", ["paper", "mog2", "knn"])
def test_whole_detector(benchmark: BenchmarkFixture, frames: Frames, detector: str) -> None:
    name, fr = frames
    benchmark.group = f"whole detect() {name}"
    det = make_detector(detector)
    for f in fr:
        det.detect(f)
    benchmark(cycle_apply(det.detect, fr))


@pytest.fixture(scope="module")
def ghost_case(frames: Frames) -> tuple[str, Any, Frame, Frame, Any]:
    """A primed model after 30 frames, and the last frame's mask and blob boxes."""
    name, fr = frames
    det = make_detector("paper")
    det.prime(fr[::2])
    for f in fr[:30]:
        d = det.detect(f)
    return name, det.model, fr[29], d.mask, d.boxes


def test_ghost_test_core(benchmark: BenchmarkFixture, ghost_case: Any) -> None:
    name, model, frame, mask, boxes = ghost_case
    benchmark.group = f"ghost test {name}"
    benchmark.extra_info["boxes"] = len(boxes)
    benchmark(model.edge_support, frame, mask, boxes)


def test_ghost_test_opencv(benchmark: BenchmarkFixture, ghost_case: Any) -> None:
    from pftrack.detection.ghost import edge_support

    name, model, frame, mask, boxes = ghost_case
    benchmark.group = f"ghost test {name}"
    # the detector's earlier path: the background copied out, then the OpenCV version
    benchmark(lambda: edge_support(frame, model.background, mask, boxes))


def test_prime_median_core(benchmark: BenchmarkFixture, frames: Frames) -> None:
    name, fr = frames
    benchmark.group = f"prime median of 30 frames {name}"
    benchmark(_core.median_frames, fr[:30])


def test_prime_median_numpy(benchmark: BenchmarkFixture, frames: Frames) -> None:
    name, fr = frames
    benchmark.group = f"prime median of 30 frames {name}"
    benchmark(lambda: np.median(np.stack(fr[:30]), axis=0).astype(np.float32))


@pytest.fixture(scope="module")
def blob_masks(frames: Frames) -> tuple[str, list[NDArray[np.uint8]], NDArray[np.float64]]:
    """The cleaned masks of the 60 frames (primed detector) and a size model's lines."""
    name, fr = frames
    det = make_detector("paper")
    det.prime(fr[::2])
    masks = [det.foreground(f)[0] for f in fr]
    rows = fr[0].shape[0]
    lines = np.array([[0.25, 0.0], [0.09, 0.0]]) * (1.0, rows / 360)  # a PETS-like person
    return name, masks, lines


BLOB_ARGS = (0.0015, 0.25, 0.25, 6.0, 0.2, 2.8)  # BlobConfig's defaults: area, aspect, fill


@pytest.mark.parametrize("model", ["aspect split", "size model"])
def test_blob_pass_core(benchmark: BenchmarkFixture, blob_masks: Any, model: str) -> None:
    name, masks, lines = blob_masks
    benchmark.group = f"blob pass ({model}) {name}"
    size = lines if model == "size model" else None
    benchmark(cycle_apply(lambda m: _core.blob_boxes(m, *BLOB_ARGS, size, 1.6, 1.5, 1.2), masks))


@pytest.mark.parametrize("model", ["aspect split", "size model"])
def test_blob_pass_reference(benchmark: BenchmarkFixture, blob_masks: Any, model: str) -> None:
    name, masks, lines = blob_masks
    benchmark.group = f"blob pass ({model}) {name}"
    size = lines if model == "size model" else None
    benchmark(cycle_apply(lambda m: blob_reference(m, *BLOB_ARGS, size, 1.6, 1.5, 1.2), masks))


@pytest.fixture(scope="module")
def size_samples() -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """200 foot rows and heights (the size model's full ring buffer), one in ten an outlier."""
    rng = np.random.default_rng(0)
    y = rng.uniform(100, 360, 200)
    h = 0.25 * y + rng.normal(0, 3, 200)
    h[::10] *= 1.8
    return y, h


def test_theil_sen_core(benchmark: BenchmarkFixture, size_samples: Any) -> None:
    benchmark.group = "Theil-Sen line, 200 samples"
    benchmark(_core.theil_sen, *size_samples)


def test_theil_sen_numpy(benchmark: BenchmarkFixture, size_samples: Any) -> None:
    benchmark.group = "Theil-Sen line, 200 samples"
    benchmark(theil_sen_reference, *size_samples)


@pytest.mark.parametrize("path", ["avx2", "portable"])
def test_mean_and_gain_core(benchmark: BenchmarkFixture, frames: Frames, path: str) -> None:
    """The detector's every-frame light measures at its step (8 up to 640x480): the sampled
    pixels 4 a step by AVX2 gathers (stop 74) or one by one (`_set_avx2(False)`)."""
    name, fr = frames
    benchmark.group = f"mean and gain at step 8 {name}"
    m = _core.BackgroundModel()
    m.apply(fr[0])
    before = _core._set_avx2(path == "avx2")
    try:
        benchmark(cycle_apply(lambda f: m.mean_and_gain(f, 8), fr[1:]))
    finally:
        _core._set_avx2(before)


def test_mean_and_gain_numpy(benchmark: BenchmarkFixture, frames: Frames) -> None:
    from pftrack.detection.light import frame_gain

    name, fr = frames
    benchmark.group = f"mean and gain at step 8 {name}"
    m = _core.BackgroundModel()
    m.apply(fr[0])
    bg = np.asarray(m.background)
    benchmark(cycle_apply(lambda f: (f[::8, ::8].mean(), frame_gain(f, bg, 8)), fr[1:]))


@pytest.fixture(scope="module")
def raw_masks(frames: Frames) -> tuple[str, list[NDArray[np.uint8]], Any]:
    """The raw masks with shadows (0/127/255) of the 60 frames (primed detector), and the
    detector's (opening, closing) elements for this size."""
    from pftrack.detection.base import BlobConfig, BlobExtractor

    name, fr = frames
    det: Any = make_detector("paper")
    det.prime(fr[::2])
    masks: list[NDArray[np.uint8]] = []
    clean = det._blobs.clean  # recorded as `detect` cleans each frame's raw mask
    det._blobs.clean = lambda raw: (masks.append(raw.copy()), clean(raw))[1]
    for f in fr:
        det.detect(f)
    return name, masks, BlobExtractor(BlobConfig())._elements(fr[0].shape[0])


@pytest.mark.parametrize("path", ["packed", "bytes", "opencv"])
def test_clean_mask(benchmark: BenchmarkFixture, raw_masks: Any, path: str) -> None:
    """The opening and closing of a raw mask: bit planes (0/127/255), the byte path (the same
    masks with one pixel of a third level, 200), and OpenCV's two morphologyEx calls."""
    name, masks, (k_open, k_close) = raw_masks
    benchmark.group = f"clean mask {name}"
    if path == "bytes":
        masks = [m.copy() for m in masks]
        for m in masks:
            m[0, 0] = 200  # a third non-zero level: not two planes
    if path == "opencv":

        def run(m: NDArray[np.uint8]) -> Any:
            opened = cv2.morphologyEx(m, cv2.MORPH_OPEN, k_open)
            return cv2.morphologyEx(opened, cv2.MORPH_CLOSE, k_close)

        benchmark(cycle_apply(run, masks))
    else:
        benchmark(cycle_apply(lambda m: _core.clean_mask(m, k_open, k_close), masks))
