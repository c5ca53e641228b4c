"""``TrackerConfig(detector=PaperConfig(...))``: every setting of the built-in detector.

``TrackerConfig`` handed the built-in detector a name and two of its settings (``open_size``,
``hold_frames``, each a field of its own); the others (``alpha_fg``, ``k_noise``, ``blobs``'
area limits, MOG2's ``var_threshold``) were out of reach of a tracker. ``detector`` takes the
detector's settings as well as its name now (apinames, 6 December): the same name's defaults
give the same tracks, byte for byte.
"""

from __future__ import annotations

import pickle

import numpy as np
import pytest

from pftrack.detection import (
    BlobConfig,
    KnnConfig,
    KnnDetector,
    Mog2Config,
    PaperConfig,
    PaperDetector,
    detector_from,
)
from pftrack.particle_filter import HsvBinning
from pftrack.synthetic import make_scene
from pftrack.tracking import MultiObjectTracker, TrackerConfig
from pftrack.tracking.run import track_frames


@pytest.fixture(scope="module")
def frames() -> list[np.ndarray]:
    return make_scene(n_frames=40, n_walkers=3, rng=2).frames


def _rows(frames: list[np.ndarray], config: TrackerConfig) -> np.ndarray:
    return track_frames(frames, config=config, rng=0, prime_frames=10, threads=False).rows


@pytest.mark.parametrize(
    ("settings", "by_name"),
    [
        (PaperConfig(), TrackerConfig()),
        (PaperConfig(hold_frames=1000), TrackerConfig(hold_frames=1000)),
        (PaperConfig(blobs=BlobConfig(open_size=3)), TrackerConfig(open_size=3)),
        (Mog2Config(), TrackerConfig(detector="mog2")),
        (KnnConfig(), TrackerConfig(detector="knn")),  # its seed: the same draw of the rng
    ],
    ids=["paper", "paper-hold", "paper-open", "mog2", "knn"],
)
def test_settings_equal_to_a_names_give_its_tracks_byte_for_byte(
    frames: list[np.ndarray], settings: object, by_name: TrackerConfig
) -> None:
    config = TrackerConfig(detector=settings)  # type: ignore[arg-type]
    assert config.detector_name == by_name.detector_name
    np.testing.assert_array_equal(_rows(frames, config), _rows(frames, by_name))


def test_a_setting_no_name_reaches_is_the_detectors(frames: list[np.ndarray]) -> None:
    settings = PaperConfig(alpha_fg=0.01, blobs=BlobConfig(min_area=0.0005))
    tracker = MultiObjectTracker(TrackerConfig(detector=settings, open_size=5), rng=0)
    detector = tracker.detector
    assert isinstance(detector, PaperDetector)
    assert detector.config.alpha_fg == 0.01 and detector.config.blobs.min_area == 0.0005
    assert detector.config.blobs.open_size == 5  # TrackerConfig's, on top
    assert not np.array_equal(
        _rows(frames, TrackerConfig(detector=PaperConfig(k_noise=9.0))),
        _rows(frames, TrackerConfig()),
    )


def test_the_detector_bins_as_the_tracker() -> None:
    binning = HsvBinning(n_h=8, n_s=8, n_v=8)
    tracker = MultiObjectTracker(TrackerConfig(detector=PaperConfig(), binning=binning), rng=0)
    assert tracker.detector.config.hsv == binning  # type: ignore[attr-defined]
    TrackerConfig(detector=PaperConfig(hsv=binning), binning=binning)  # the same: taken


def test_a_config_with_settings_is_a_config_still() -> None:
    config = TrackerConfig(detector=KnnConfig(history=100))
    assert config == TrackerConfig(detector=KnnConfig(history=100)) != TrackerConfig(detector="knn")
    assert hash(config) == hash(TrackerConfig(detector=KnnConfig(history=100)))
    assert pickle.loads(pickle.dumps(config)) == config
    assert isinstance(detector_from(config.detector_settings(), seed=3), KnnDetector)  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("kwargs", "error", "message"),
    [
        ({"detector": BlobConfig()}, TypeError,
         r"^TrackerConfig: detector must be 'paper', 'mog2' or 'knn', or a PaperConfig, "
         r"Mog2Config or KnnConfig, got BlobConfig"),
        ({"detector": "nonesuch"}, ValueError,
         r"^TrackerConfig: detector is 'nonesuch', expected 'paper', 'mog2' or 'knn' \(or"),
        ({"detector": PaperConfig(hsv=HsvBinning(n_h=8))}, ValueError,
         r"^TrackerConfig: detector's hsv is .*bins colour as the tracker does: set binning="),
        ({"detector": PaperConfig(blobs=BlobConfig(open_size=3)), "open_size": 5}, ValueError,
         r"^TrackerConfig: open_size is 5 and detector's blobs.open_size is 3: give it once"),
        ({"detector": PaperConfig(hold_frames=50), "hold_frames": 1000}, ValueError,
         r"^TrackerConfig: hold_frames is 1000 and detector's hold_frames is 50: give it once"),
        ({"detector": Mog2Config(), "hold_frames": 1000}, ValueError,
         r"^TrackerConfig: hold_frames 1000 needs detector 'paper' .* got detector 'mog2'"),
    ],
    ids=["not-settings", "unknown-name", "hsv", "open-twice", "hold-twice", "hold-mog2"],
)  # fmt: skip
def test_settings_that_cannot_be_the_detectors_are_refused_in_one_line(
    kwargs: dict[str, object], error: type[Exception], message: str
) -> None:
    with pytest.raises(error, match=message) as e:
        TrackerConfig(**kwargs)  # type: ignore[arg-type]
    assert "\n" not in str(e.value)


def test_the_same_value_given_twice_is_taken() -> None:
    TrackerConfig(detector=PaperConfig(hold_frames=1000), hold_frames=1000)
    TrackerConfig(detector=PaperConfig(blobs=BlobConfig(open_size=5)), open_size=5)


def test_tracker_takes_the_detectors_settings_as_its_annotation_says(
    frames: list[np.ndarray],
) -> None:
    """``pftrack.Tracker(detector=PaperConfig(...))`` was taken, but annotated and documented
    as a name only (a typed script was refused by mypy for a call that worked)."""
    import typing

    import pftrack

    hint = typing.get_type_hints(pftrack.Tracker.__init__)["detector"]
    assert {PaperConfig, Mog2Config, KnnConfig} <= set(typing.get_args(hint))
    by_name, by_settings = pftrack.Tracker(), pftrack.Tracker(detector=PaperConfig())
    for frame in frames[:15]:
        assert np.array_equal(by_name.update(None, frame), by_settings.update(None, frame))


def test_tracker_refuses_a_detectors_hsv_without_naming_a_setting_it_lacks() -> None:
    """TrackerConfig's message says ``set binning=...``: ``Tracker`` has no `binning`."""
    import pftrack

    with pytest.raises(ValueError, match=r"^detector's hsv is .*Tracker\.from_config$") as e:
        pftrack.Tracker(detector=PaperConfig(hsv=HsvBinning(n_h=8)))
    assert "set binning" not in str(e.value)
