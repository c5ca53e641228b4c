"""Fuzz targets: the main Python API (offline pass, linking, recovery, MOT files, tracker)."""

from __future__ import annotations

import tempfile
import warnings
from pathlib import Path
from typing import Any

import numpy as np
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from tests.fuzz.harness import SPECIAL, Target, call, fl, floats_array, ints, layout, maybe


@st.composite
def mot_rows(draw: st.DrawFn) -> np.ndarray:
    """Track rows (M, 6..10): mostly sane, sometimes odd ids, frames, columns or values."""
    m = draw(st.integers(0, 30))
    cols = draw(st.sampled_from([10, 10, 10, 6, 7, 9, 5, 11, 2]))
    rows = np.zeros((m, cols))
    n_ids = draw(st.integers(1, 4))
    ids = np.asarray(draw(st.lists(st.integers(1, n_ids), min_size=m, max_size=m)), float)
    frames = np.asarray(draw(st.lists(st.integers(1, 60), min_size=m, max_size=m)), float)
    if cols >= 2:
        rows[:, 0], rows[:, 1] = frames, ids
    if cols >= 6:
        rows[:, 2:4] = draw(floats_array((m, 2), 0, 400))
        rows[:, 4:6] = draw(floats_array((m, 2), 1, 80))
    if cols >= 7:
        rows[:, 6] = 1.0
    if m and draw(st.integers(0, 4)) == 0:  # an odd value somewhere
        k, c = draw(st.integers(0, m - 1)), draw(st.integers(0, cols - 1))
        rows[k, c] = draw(st.sampled_from([*SPECIAL, 2.5, 1e19, -3.0, 2.0**53]))
    # one row per (frame, id): duplicates are an input error the API must report, not crash on
    if cols >= 2 and m and draw(st.booleans()):
        _, keep = np.unique(rows[:, :2], axis=0, return_index=True)
        rows = rows[np.sort(keep)]
    out: np.ndarray = draw(layout(rows))
    return out


def _smooth(rows: Any, smoother: Any, link: Any) -> Any:
    from pftrack.tracking import smooth_tracks

    return smooth_tracks(rows, smoother=smoother, link=_as_link_config(link))


def _box_smoother(params: dict[str, Any], rows: Any) -> Any:
    from pftrack.tracking import BoxSmoother

    s = BoxSmoother(**params)
    r = np.asarray(rows, dtype=float)
    return s.smooth(r[:, 0], r[:, 2:6], np.ones(len(r), bool)) if r.ndim == 2 else None


def _link(rows: Any, config: Any) -> Any:
    from pftrack.recovery import link_tracklets

    return link_tracklets(rows, _as_link_config(config))


def _fill(rows: Any, method: Any, max_gap: Any) -> Any:
    from pftrack.recovery import fill_gaps

    return fill_gaps(rows, method, max_gap)[0]


def _recover_gap(a: Any, b: Any, frames: Any, method: Any) -> Any:
    from pftrack.recovery import recover_gap

    return recover_gap(a, b, frames, method)


def _baseline(name: str) -> Any:
    """``pftrack.recovery.baselines.<name>(seg_a, seg_b, frames)``, the public checked one."""

    def run(a: Any, b: Any, frames: Any) -> Any:
        from pftrack.recovery import baselines

        return getattr(baselines, name)(a, b, frames)

    run.__name__ = name
    return run


def _mot_roundtrip(rows: Any) -> Any:
    from pftrack.io.mot import read_mot, write_mot

    with tempfile.TemporaryDirectory() as d:
        write_mot(Path(d) / "t.txt", rows)
        return read_mot(Path(d) / "t.txt")


def _read_mot_text(lines: list[str]) -> Any:
    from pftrack.io.mot import read_mot

    with tempfile.TemporaryDirectory() as d:
        (Path(d) / "t.txt").write_text("\n".join(lines))
        return read_mot(Path(d) / "t.txt")


def _tracker(frames: list[Any], dets: list[Any], particles: Any) -> Any:
    from dataclasses import replace

    from pftrack.tracking import MultiObjectTracker, TrackerConfig

    base = TrackerConfig()
    tracker = MultiObjectTracker(replace(base, filter=replace(base.filter, n_particles=particles)),
                                 rng=0)  # fmt: skip
    out = []
    with warnings.catch_warnings():
        # boxes outside the frame are dropped with a warning by design (tested elsewhere)
        warnings.filterwarnings("ignore", message=r".*outside the .* frame", category=UserWarning)
        # scores above 1 are said once by design (tested in tests/tracking)
        warnings.filterwarnings("ignore", message=r"a detection score is", category=UserWarning)
        for f, d in zip(frames, dets, strict=False):
            out.append([t.box_xywh.tolist() for t in tracker.update(f, d)])
    return out


def _api_tracker(dets: list[Any], options: dict[str, Any]) -> Any:
    import pftrack

    tracker = pftrack.Tracker(**options)
    frame = np.zeros((24, 32, 3), np.uint8)
    with warnings.catch_warnings():
        # by design: boxes outside the frame are dropped, and an empty run says so
        warnings.filterwarnings("ignore", message=r".*outside the .* frame", category=UserWarning)
        warnings.filterwarnings("ignore", message=r"no track over", category=RuntimeWarning)
        warnings.filterwarnings("ignore", message=r"a detection score is", category=UserWarning)
        # boxes without area or inverted are dropped with a warning by design (tests/tracking)
        warnings.filterwarnings("ignore", message=r".* without area", category=UserWarning)
        warnings.filterwarnings("ignore", message=r".* with x2 < x1", category=UserWarning)
        # None after detections runs the built-in detector and says so once (tests/tracking)
        warnings.filterwarnings("ignore", message=r"frame \d+: dets=None", category=UserWarning)
        # a placeholder frame: its warning is tested in tests/tracking/test_api_tracker.py
        warnings.filterwarnings("ignore", message=r"frame 1 is blank", category=UserWarning)
        out = [tracker.update(d, frame) for d in dets]
        out.append(tracker.finalize())
    return out


def _tracker_options() -> st.SearchStrategy[dict[str, Any]]:
    return st.fixed_dictionaries({}, optional={
        "particles": maybe(ints(1, 50)), "max_coast": maybe(fl(0, 5)),
        "min_conf": maybe(fl(0, 1)), "birth_score": maybe(fl(0, 1)), "prime": maybe(fl(0, 3)),
        "frame_rate": maybe(fl(0.1, 100)), "birth_quantile": maybe(fl(0, 1)),
        "sampler": st.sampled_from(["sis", "mh", "rjmcmc"]), "mh_iter": maybe(ints(1, 3)),
        "burn_in": maybe(ints(0, 60)), "moves": maybe(st.tuples(*[fl(0, 1)] * 4)),
        "mh_proposal": maybe(st.sampled_from(["dynamics", "random_walk"])),
        "mh_rw_sigma": maybe(st.tuples(*[fl(0, 20)] * 3)),
    })  # fmt: skip


def _evaluate(gt: Any, result: Any, iou: Any, scale: Any, size: Any) -> Any:
    from pftrack.eval import evaluate_mot

    with warnings.catch_warnings():
        # random rows often match nothing: said since stop 71 (one line), not the fuzz's subject
        warnings.filterwarnings("ignore", message=r"evaluate_mot: none of", category=UserWarning)
        m = evaluate_mot(gt, result, iou_threshold=iou, scale=scale, image_size=size)
    return {k: v for k, v in vars(m).items() if isinstance(v, int | float)}


def _resample(name: str) -> Any:
    from pftrack import particle_filter

    fn = getattr(particle_filter, name)

    def run(weights: Any) -> Any:
        return fn(weights, rng=0)

    run.__name__ = name
    return run


@st.composite
def segment(draw: st.DrawFn, first: int) -> np.ndarray:
    n = draw(st.integers(0, 6))
    f = first + np.arange(n, dtype=float)
    return np.column_stack([f, draw(floats_array((n, 2), 0, 500))])


def _link_config() -> st.SearchStrategy[Any]:
    """LinkConfig's arguments; the config is built inside the call (its checks are fuzzed)."""
    return st.fixed_dictionaries(
        {"max_gap": maybe(ints(1, 100)), "max_distance": maybe(fl(0, 500))}
    )


def _as_link_config(params: Any) -> Any:
    from pftrack.recovery import LinkConfig

    return None if params is None else LinkConfig(**params)


def _box_params() -> st.SearchStrategy[dict[str, Any]]:
    return st.fixed_dictionaries({}, optional={
        "accel": maybe(fl(1e-6, 10)), "noise": maybe(fl(1e-6, 10)),
        "size_accel": maybe(fl(1e-6, 10)), "size_noise": maybe(fl(1e-6, 10)),
    })  # fmt: skip


def _smoother_or_none() -> st.SearchStrategy[Any]:
    from pftrack.tracking import BoxSmoother

    return st.one_of(st.none(), _box_params().map(lambda p: _try(BoxSmoother, p)))


def _try(cls: Any, params: dict[str, Any]) -> Any:
    try:
        return cls(**params)
    except (ValueError, TypeError):
        return cls()


tracker_frames = st.lists(
    hnp.arrays(np.uint8, (24, 32, 3), elements=st.integers(0, 255)), min_size=1, max_size=3
)
tracker_dets = st.lists(st.one_of(st.none(), floats_array((2, 4), -40, 60),
                                  floats_array((1, 5), 0, 30), maybe(floats_array((0, 4)))),
                        min_size=1, max_size=3)  # fmt: skip

TARGETS: list[Target] = [
    Target(
        "smooth_tracks",
        call(_smooth, mot_rows(), _smoother_or_none(), st.one_of(st.none(), _link_config())),
    ),
    Target("BoxSmoother", call(_box_smoother, _box_params(), mot_rows())),
    Target("link_tracklets", call(_link, mot_rows(), _link_config())),
    Target(
        "fill_gaps",
        call(
            _fill,
            mot_rows(),
            maybe(st.sampled_from(["linear", "cubic", "gsi", "rts", "gdt"])),
            maybe(ints(1, 40)),
        ),
    ),  # fmt: skip
    Target(
        "recover_gap",
        call(
            _recover_gap,
            maybe(segment(1)),
            maybe(segment(20)),
            st.one_of(st.none(), maybe(floats_array((3,), 7, 19))),
            maybe(st.sampled_from(["linear", "cubic", "gdt", "gsi", "rts"])),
        ),
    ),
    *[
        Target(
            f"baselines.{n}",
            call(
                _baseline(n),
                maybe(segment(1)),
                maybe(segment(20)),
                st.one_of(st.none(), maybe(floats_array((3,), 7, 19))),
            ),
        )
        for n in ("linear", "cubic", "bspline", "gsi", "rts", "interpolate_sizes")
    ],  # fmt: skip
    Target("write_mot/read_mot", call(_mot_roundtrip, mot_rows())),
    Target(
        "read_mot",
        call(
            _read_mot_text,
            st.lists(
                st.text(alphabet=st.sampled_from("0123456789.,-e naNinf\t"), max_size=40),
                max_size=5,
            ),
        ),
    ),
    Target(
        "MultiObjectTracker.update",
        call(_tracker, tracker_frames, tracker_dets, maybe(ints(1, 30))),
    ),  # fmt: skip
    Target(
        "Tracker",
        call(
            _api_tracker,
            st.lists(
                st.one_of(
                    st.none(), floats_array((2, 5), -40, 60), maybe(floats_array((1, 4), 0, 30))
                ),
                min_size=1,
                max_size=3,
            ),
            _tracker_options(),
        ),
    ),  # fmt: skip
    Target(
        "evaluate_mot",
        call(
            _evaluate,
            mot_rows(),
            mot_rows(),
            maybe(fl(0.01, 1)),
            maybe(fl(0.1, 10)),
            st.one_of(st.none(), maybe(st.tuples(ints(1, 2000), ints(1, 2000)))),
        ),
        finite=False,  # MOTA, IDF1, ... are NaN by definition when nothing is scored
    ),  # fmt: skip
    *[
        Target(
            f"particle_filter.{n}",
            call(
                _resample(n), st.integers(0, 8).flatmap(lambda k: maybe(floats_array((k,), 0, 5)))
            ),
        )
        for n in (
            "systematic_resample",
            "stratified_resample",
            "multinomial_resample",
            "residual_resample",
        )
    ],  # fmt: skip
]
