"""Every public class that takes settings, probed with the wrong types a user gives.

Developer trial, 6 December: for each argument with a default of the configs, ``Tracker``,
the filters and samplers, the detectors, the recovery models and the batch entries, text for
a number, None where None is not taken, a list for a number, a bool for an int and an int for
a flag must be a one-line TypeError or ValueError naming the argument (never pybind11's list of
signatures, a comparison's ``'<' not supported``, NumPy's ``ufunc 'isfinite'`` or an
AttributeError), and a NumPy scalar of the default's type must be taken. Were wrong:
``AssociationConfig``, ``LifecycleConfig``, ``MotionConfig`` and ``RefineConfig`` took None for
a plain number and failed at a comparison naming nothing; ``SizeModelConfig`` refused
``np.int64(30)`` and took ``True`` for ``refit_every``; ``ColourParticleFilter(velocity=None)``
was taken; the detectors took text for their config and failed with an AttributeError.
"""

from __future__ import annotations

import dataclasses
import inspect
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import pftrack
from pftrack import batch, detection, particle_filter, recovery, tracking
from pftrack.detection.size_model import SizeModelConfig

_REF = np.ones(110)
_BOX = (30.0, 20.0, 10.0, 20.0)

#: name -> (the class, the positional arguments it needs)
CLASSES: dict[str, tuple[Callable[..., Any], tuple[Any, ...]]] = {
    # configs
    "FilterConfig": (particle_filter.FilterConfig, ()),
    "Ar2Model": (particle_filter.Ar2Model, ()),
    "HsvBinning": (particle_filter.HsvBinning, ()),
    "RJMCMCConfig": (particle_filter.RJMCMCConfig, ()),
    "TrackerConfig": (tracking.TrackerConfig, ()),
    "AssociationConfig": (tracking.AssociationConfig, ()),
    "CameraConfig": (tracking.CameraConfig, ()),
    "CrossingConfig": (tracking.CrossingConfig, ()),
    "LifecycleConfig": (tracking.LifecycleConfig, ()),
    "MotionConfig": (tracking.MotionConfig, ()),
    "RefineConfig": (tracking.RefineConfig, ()),
    "BlobConfig": (detection.BlobConfig, ()),
    "KnnConfig": (detection.KnnConfig, ()),
    "Mog2Config": (detection.Mog2Config, ()),
    "PaperConfig": (detection.PaperConfig, ()),
    "SizeModelConfig": (SizeModelConfig, ()),
    "TrackOptions": (batch.TrackOptions, ()),
    "RecoverOptions": (batch.RecoverOptions, ()),
    "SmoothOptions": (batch.SmoothOptions, ()),
    # the trackers
    "Tracker": (pftrack.Tracker, ()),
    "MultiObjectTracker": (tracking.MultiObjectTracker, ()),
    "BoxSmoother": (tracking.BoxSmoother, ()),
    # filters and samplers
    "ColourParticleFilter": (particle_filter.ColourParticleFilter, (_BOX, _REF)),
    "MHColourParticleFilter": (particle_filter.MHColourParticleFilter, (_BOX, _REF)),
    "RJMCMCFilter": (particle_filter.RJMCMCFilter, ()),
    # detectors
    "PaperDetector": (detection.PaperDetector, ()),
    "KnnDetector": (detection.KnnDetector, ()),
    "Mog2Detector": (detection.Mog2Detector, ()),
    # recovery models
    "LinkConfig": (recovery.LinkConfig, ()),
    "GdtModel": (recovery.GdtModel, ()),
}


def _takes_none(p: inspect.Parameter) -> bool:
    return p.default is None or "None" in str(p.annotation)


def _wrong(p: inspect.Parameter) -> list[tuple[str, object]]:
    """The wrong values a user gives for `p`, by the type of its default."""
    d = p.default
    out: list[tuple[str, object]] = []
    if not isinstance(d, str):
        out.append(("text", "x"))
    if not _takes_none(p):
        out.append(("None", None))
    if isinstance(d, (int, float)) and not isinstance(d, bool):
        out.append(("list", [1, 2]))
    if isinstance(d, int) and not isinstance(d, bool):
        out.append(("bool", True))
    if isinstance(d, bool):
        out.append(("int", 2))
    return out


def _numpy(p: inspect.Parameter) -> list[tuple[str, object]]:
    """NumPy scalars of the default's type, which must be taken."""
    d = p.default
    if isinstance(d, bool) or not isinstance(d, (int, float)):
        return []
    if isinstance(d, int):
        return [("np.int64", np.int64(d))]
    return [("np.float64", np.float64(d))]


def _settings(cls: Callable[..., Any]) -> list[inspect.Parameter]:
    return [
        p
        for p in inspect.signature(cls).parameters.values()
        if p.default is not inspect.Parameter.empty
        and p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD)
        and not dataclasses.is_dataclass(p.default)
    ]


WRONG = [
    pytest.param(name, p.name, value, id=f"{name}({p.name}={kind})")
    for name, (cls, _) in CLASSES.items()
    for p in _settings(cls)
    for kind, value in _wrong(p)
]
TAKEN = [
    pytest.param(name, p.name, value, id=f"{name}({p.name}={kind})")
    for name, (cls, _) in CLASSES.items()
    for p in _settings(cls)
    for kind, value in _numpy(p)
]


def _make(name: str, **kwargs: object) -> object:
    cls, args = CLASSES[name]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a setting's own advice is not what is probed
        return cls(*args, **kwargs)


def _one_line_naming(error: BaseException, argument: str) -> None:
    message = str(error)
    assert "\n" not in message, message
    assert "incompatible function arguments" not in message, message
    assert "not supported" not in message, message  # a comparison's or a ufunc's
    assert argument in message, message


def test_the_probe_covers_every_class_it_names() -> None:
    """Each class of the list has settings probed (a signature change cannot empty it)."""
    probed = {p.values[0] for p in WRONG}
    assert probed == set(CLASSES)
    assert len(WRONG) > 300 and len(TAKEN) > 150


@pytest.mark.parametrize(("name", "argument", "value"), WRONG)
def test_a_wrong_type_is_refused_in_one_line_naming_the_argument(
    name: str, argument: str, value: object
) -> None:
    with pytest.raises((TypeError, ValueError)) as e:
        _make(name, **{argument: value})
    _one_line_naming(e.value, argument)


@pytest.mark.parametrize(("name", "argument", "value"), TAKEN)
def test_a_numpy_scalar_of_the_default_type_is_taken(
    name: str, argument: str, value: object
) -> None:
    made = _make(name, **{argument: value})
    for method in ("close", "stop"):
        if hasattr(made, method):
            getattr(made, method)()


BATCH = {"track_many": batch.track_many, "recover_many": batch.recover_many,
         "smooth_many": batch.smooth_many}  # fmt: skip


@pytest.fixture(scope="module")
def inputs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, list[Path]]:
    import cv2

    root = tmp_path_factory.mktemp("batch_probe")
    tracks = root / "t.txt"
    tracks.write_text("1,1,10,10,5,5,1,-1,-1,-1\n3,1,12,10,5,5,1,-1,-1,-1\n")
    seq = root / "seq"
    seq.mkdir()
    for i in range(1, 4):
        cv2.imwrite(str(seq / f"{i:06d}.jpg"), np.full((32, 32, 3), 90, np.uint8))
    return {"track_many": [seq], "recover_many": [tracks], "smooth_many": [tracks]}


def _batch_wrong(p: inspect.Parameter) -> list[tuple[str, object]]:
    text = str(p.annotation)
    out: list[tuple[str, object]] = [("list", [1, 2]), ("float", 2.5)]
    if "str" not in text:
        out.append(("text", "x"))
    if "bool" not in text:
        out.append(("bool", True))
    if "None" not in text:
        out.append(("None", None))
    return out


BATCH_WRONG = [
    pytest.param(name, p.name, value, id=f"{name}({p.name}={kind})")
    for name, fn in BATCH.items()
    for p in inspect.signature(fn).parameters.values()
    if p.default is not inspect.Parameter.empty
    for kind, value in _batch_wrong(p)
]


@pytest.mark.parametrize(("name", "argument", "value"), BATCH_WRONG)
def test_a_batch_entry_refuses_a_wrong_type_before_any_work(
    name: str, argument: str, value: object, inputs: dict[str, list[Path]], tmp_path: Path
) -> None:
    with pytest.raises((TypeError, ValueError)) as e:
        BATCH[name](inputs[name], tmp_path / "out", **{argument: value})
    _one_line_naming(e.value, argument)
    assert not (tmp_path / "out").exists()
