"""The work of one batch task: track one sequence, or recover or smooth one tracks file.

These functions run on Dask workers (or in the calling process with ``n_workers=0``). They
read their inputs by path (workers must see the same paths: a shared or copied folder) and
write nothing: they return the rows, any extra file as bytes, and a JSON-ready summary, and the
client writes the outputs (:mod:`pftrack.batch.engine`). Workers on other machines therefore
need no access to the output folder. Nothing here imports Dask.
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
import socket
import tempfile
import threading
import time
import traceback
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from pftrack._check import brief, flag, instance, number, option, shown
from pftrack._text import error_line
from pftrack._threads import tracking_threads
from pftrack._typing import F64, BenchmarkName, FillMode, PathLike, RecoveryMethod
from pftrack._warn import warn
from pftrack.batch.inputs import SequenceInput

if TYPE_CHECKING:  # importing pftrack.tracking loads the whole tracker; recover needs none of it
    from pftrack.io.mot import MotFile
    from pftrack.tracking.config import TrackerConfig

__all__ = [
    "RecoverOptions",
    "SmoothOptions",
    "TaskCancelled",
    "TaskResult",
    "TrackOptions",
    "missing_detections",
    "read_tracks",
    "recover_file",
    "reporting_frames",
    "running_task",
    "sequence_length",
    "sequence_metrics",
    "smooth_file",
    "track_sequence",
]


#: Per thread, where the task running on it reports the frames it has tracked (``report``:
#: ``report(n)``) and what it calls every :data:`STOP_CHECK_EVERY` frames, which raises
#: :class:`TaskCancelled` to stop it (``stop``): set by the batch engine around a task
#: (:func:`reporting_frames`). Per thread: a Dask worker with several threads runs several
#: tasks at once (was: one global pair, the last task's, served them all).
_running = threading.local()
#: Frames between two calls of the stop check (tracking, then rendering).
STOP_CHECK_EVERY = 25


class TaskCancelled(Exception):
    """The task was cancelled while it ran (its batch interrupted, its client gone): it stops.

    Dask cannot stop a running thread: a task whose future is cancelled would track to its
    end, keeping its worker busy. The task checks every :data:`STOP_CHECK_EVERY` frames.
    """


@contextlib.contextmanager
def reporting_frames(
    report: Callable[[int], None] | None, stop: Callable[[], None] | None = None
) -> Iterator[None]:
    """While the block runs, :func:`track_sequence` calls ``report(n)`` after frame `n`.

    How a batch shows progress within its sequences: the engine passes a function that moves
    its bar (in this process) or sends the count to the client (on a Dask worker). `stop` is
    called every :data:`STOP_CHECK_EVERY` frames tracked or rendered, and raises
    (:class:`TaskCancelled`) to end the task.
    """
    before = running_task()
    _running.report, _running.stop = report, stop
    try:
        yield
    finally:
        _running.report, _running.stop = before


def running_task() -> tuple[Callable[[int], None] | None, Callable[[], None] | None]:
    """The frame report and the stop check of the task running on this thread, if any.

    What :func:`reporting_frames` set for this thread; ``(None, None)`` outside a task.
    """
    return getattr(_running, "report", None), getattr(_running, "stop", None)


def _checked(frames: Iterable[Any], stop: Callable[[], None] | None) -> Iterator[Any]:
    """`frames`, with ``stop()`` called every :data:`STOP_CHECK_EVERY` of them."""
    for n, frame in enumerate(frames, start=1):
        if stop is not None and n % STOP_CHECK_EVERY == 0:
            stop()
        yield frame


def sequence_length(seq: SequenceInput) -> int | None:
    """The number of frames of `seq` if its header or folder says it; None if unknown.

    0 when `seq` cannot be opened (not a video, no frame, a missing image): its task fails
    with its own message before tracking a frame, and the batch's bar keeps the total of the
    others (was: None, and one unreadable video took the bar's total and time left away).
    """
    from pftrack.io.video import FrameSource

    try:
        n = len(FrameSource(seq.frames))
    except (OSError, ValueError):  # the task then fails with its own message
        return 0
    return n if n > 0 else None


@dataclass(frozen=True)
class TaskResult:
    """What one task sends back to the client.

    Attributes
    ----------
    rows : (M, 10) ndarray of float64
        MOTChallenge rows, written to ``DIR/NAME.txt``.
    files : dict of str to bytes
        Extra outputs by suffix (``{".mp4": ...}`` for ``--render``): ``DIR/NAME<suffix>``.
    info : dict
        JSON-ready figures of the run (frames, tracks, seconds, metrics, ...).
    exact : (M, 10) ndarray of bool or None
        Values of `rows` written with all their digits (given values that ``recover`` and
        ``smooth`` copy, :func:`~pftrack.io.mot.write_mot`'s `exact`); None: 2 decimals.
    error, traceback : str or None
        Set when a step after the work failed (scoring the tracks against a ``gt.txt`` that
        cannot be read), or the video of ``--render`` cannot be written (frames wider or
        higher than its encoder takes, known before the work: no video, and no traceback):
        the other outputs are still written, and the task counts as failed with this one-line
        error and traceback (its sidecar too, so a re-run does it again).

    Raises
    ------
    ValueError
        `rows` that :func:`~pftrack.io.mot.write_mot` refuses (a box value beyond ±1e9 px that
        smoothing or filling moved past the bound, ...): the task fails, not the batch.
    """

    rows: F64
    files: dict[str, bytes] = field(default_factory=dict)
    info: dict[str, Any] = field(default_factory=dict)
    exact: NDArray[np.bool_] | None = None
    error: str | None = None
    traceback: str | None = None

    def __post_init__(self) -> None:
        """Refuse rows that the client's :func:`~pftrack.io.mot.write_mot` would refuse.

        Here, in the task: the task fails and the batch goes on (was: the client's write
        raised, and stopped the batch with every task not yet written cancelled).
        """
        from pftrack.io.mot import check_mot_rows

        check_mot_rows(self.rows, "write_mot")


def one_line(exc: BaseException) -> str:
    """The error as one line; the kind is named unless it is a plain input error.

    As ``pftrack track`` prints it (:func:`pftrack._text.error_line`): ``Is a directory:
    PATH``, not Python's ``[Errno 21] Is a directory: 'PATH'`` (was, in a batch's table).
    """
    text = error_line(exc)
    if isinstance(exc, (ValueError, TypeError, OSError)) and text:
        return text
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__


def _settings(options: object) -> dict[str, Any]:
    """The options as plain JSON values (what a re-run compares to decide "complete")."""
    import json

    text = json.dumps(dataclasses.asdict(options), sort_keys=True, default=str)  # type: ignore[call-overload]
    value: dict[str, Any] = json.loads(text)
    if value.get("det_base", 0) is None:  # not stated: the settings of the runs before it
        del value["det_base"]  # (was not a field): their outputs stay complete
    return value


def _check_int(value: object, what: str, lo: int, hi: int | None = None) -> None:
    """Refuse `value` unless it is an integer in ``lo..hi`` (no upper bound when `hi` is None)."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"{what} must be an integer, got {shown(value)}")
    if value < lo or (hi is not None and value > hi):
        expected = f"an integer >= {lo}" if hi is None else f"an integer in {lo}..{hi}"
        raise ValueError(f"{what} is {brief(value)}, expected {expected}")


def _check_choice(value: object, what: str, choices: tuple[str, ...]) -> None:
    """Refuse `value` unless it is one of `choices` (TypeError: not text)."""
    option(value, what, choices)
    if value not in choices:
        if len(choices) == 2:
            expected = f"{choices[0]!r} or {choices[1]!r}"
        else:
            expected = f"one of {', '.join(choices)}"
        raise ValueError(f"{what} is {brief(value)}, expected {expected}")


def _default_config() -> TrackerConfig:
    from pftrack.tracking.config import TrackerConfig

    return TrackerConfig()


@dataclass(frozen=True)
class TrackOptions:
    """Settings of ``pftrack batch`` shared by every sequence.

    Attributes
    ----------
    config : TrackerConfig
        Tracker settings.
    seed : int
        Random seed (the same for every sequence, as ``pftrack track --seed``).
    detections : {None, "auto"}
        None: the built-in detector; ``"auto"``: each sequence's ``det/det.txt`` (or
        ``det.txt``); a sequence without one fails.
    det_scale : float or None
        Multiplies detection boxes; None: the frame width over ``seqinfo.ini``'s ``imWidth``
        when the sequence has one (0.625 for PETS09-S2L1's video), else 1. The ground truth
        is scaled by ``seqinfo.ini``'s size where it gives one, else, with ``detections``
        "auto", by this (a sequence's detections and ground truth share their pixels).
    det_base : {None, 0, 1}
        The number the detection files' frames count from (``--det-base``): 1 is
        MOTChallenge's; 0 reads a file numbered from 0 (a row on frame 0 is frame 1). None
        reads from 1 and warns of a file that looks numbered from 0
        (:func:`pftrack.io.mot.zero_based_note`); 0 and 1 say nothing of it.
    fill : {"linear", "pf"}
        As ``pftrack track --fill``.
    smooth, link : bool
        As ``pftrack track`` without ``--no-smooth`` and ``--no-link``.
    render : str or None
        Also write an annotated video ``DIR/NAME<render>`` (``".mp4"`` or ``".avi"``).
    iou : float
        IoU threshold of a match for the metrics (where ground truth exists), in (0, 1].

    Raises
    ------
    TypeError, ValueError
        A field of the wrong type or out of its range (``seed`` < 0, ``iou`` outside (0, 1],
        ``fill`` not ``"linear"`` or ``"pf"``, ...): refused here, so a batch stops before any
        task runs rather than failing every sequence.
    """

    config: TrackerConfig = field(default_factory=_default_config)
    seed: int = 0
    detections: str | None = None
    det_scale: float | None = None
    det_base: int | None = None
    fill: FillMode = "linear"
    smooth: bool = True
    link: bool = True
    render: str | None = None
    iou: float = 0.5

    def __post_init__(self) -> None:
        """Check every field, so that a bad value stops the batch before any task runs."""
        from pftrack.tracking.config import TrackerConfig
        from pftrack.tracking.run import DET_SCALE_RANGE

        own = "TrackOptions"  # every message names the class, as the configs' do
        instance(self.config, f"{own}: config", TrackerConfig)
        _check_int(self.seed, f"{own}: seed", 0)
        option(self.detections, f"{own}: detections", (None, "auto"))
        if self.detections not in (None, "auto"):
            raise ValueError(f"{own}: detections is {self.detections!r}, expected None or 'auto'")
        if self.det_scale is not None:
            lo, hi = DET_SCALE_RANGE
            if not lo <= number(self.det_scale, f"{own}: det_scale") <= hi:
                raise ValueError(
                    f"{own}: det_scale is {self.det_scale}, expected a number in "
                    f"[{lo:g}, {hi:g}] (or None: from seqinfo.ini)"
                )
        if self.det_base is not None:
            from pftrack.io.mot import frame_base

            frame_base(self.det_base, f"{own}: det_base")
            if self.detections is None:  # the built-in detector reads no file
                raise ValueError(
                    f"{own}: det_base is {self.det_base}, but detections is None (the built-in "
                    "detector): give detections='auto', or leave det_base None"
                )
        _check_choice(self.fill, f"{own}: fill", ("linear", "pf"))
        flag(self.smooth, f"{own}: smooth")
        flag(self.link, f"{own}: link")
        option(self.render, f"{own}: render", (None, ".mp4", ".avi"))
        if self.render not in (None, ".mp4", ".avi"):
            raise ValueError(f"{own}: render is {self.render!r}, expected None, '.mp4' or '.avi'")
        if not 0 < number(self.iou, f"{own}: iou") <= 1:  # evaluate_mot's range
            raise ValueError(f"{own}: iou is {self.iou}, expected a number in (0, 1]")

    def settings(self) -> dict[str, Any]:
        """JSON-ready settings (stored beside each output)."""
        return _settings(self)


def sequence_metrics(
    gt: F64,
    rows: F64,
    *,
    scale: float = 1.0,
    iou: float = 0.5,
    benchmark: BenchmarkName = "auto",
    num_frames: int | None = None,
) -> dict[str, float | int | str | None]:
    """The figures of one sequence's tracks against its ground truth, for the summary.

    HOTA, DetA, AssA and LocA (TrackEval's, under `benchmark`'s ground-truth rules; ``"auto"``
    guesses them from `gt`'s columns), then MOTA, IDF1 and their counts:
    :func:`pftrack.eval.evaluate_sequence`, what ``pftrack eval`` prints for the same files.
    `num_frames`: the sequence's ``seqLength``, where ``seqinfo.ini`` gives one (a row in a
    later frame is an error, as in ``pftrack eval``).
    """
    from pftrack.eval import evaluate_sequence

    s = evaluate_sequence(
        gt, rows, iou_threshold=iou, scale=scale, benchmark=benchmark, num_frames=num_frames
    )
    m, h = s.mot, s.hota
    out: dict[str, float | int | str | None] = {
        "hota": h.hota,
        "det_a": h.det_a,
        "ass_a": h.ass_a_mean,
        "loc_a": h.loc_a_mean,
        "mota": m.mota,
        "idf1": m.idf1,
        "motp_iou": m.motp_iou,
        "num_switches": m.num_switches,
        "false_positives": m.false_positives,
        "misses": m.misses,
        "benchmark": s.benchmark,
    }
    return {k: None if isinstance(v, float) and not math.isfinite(v) else v for k, v in out.items()}


def missing_detections(seq: SequenceInput, options: TrackOptions) -> str | None:
    """Why `seq` cannot be tracked with `options`' detections, or None.

    ``detections="auto"`` and `seq` has no ``det/det.txt`` (nor ``det.txt``): a video or an
    image folder of its own. :func:`track_sequence` raises it as a ``ValueError``, and
    :func:`~pftrack.batch.track_many` refuses such a sequence on the client, before the
    cluster starts work.
    """
    if options.detections == "auto" and seq.detections is None:
        return f"--detections auto: sequence {seq.name} has no det/det.txt (nor det.txt)"
    return None


def track_sequence(seq: SequenceInput, options: TrackOptions) -> TaskResult:
    """Track one sequence as ``pftrack track`` would; score it where it has ground truth.

    Parameters
    ----------
    seq : SequenceInput
        The sequence (paths as the worker sees them).
    options : TrackOptions
        Settings.

    Returns
    -------
    TaskResult
        The rows (byte-identical to ``pftrack track``'s file once written with
        :func:`~pftrack.io.mot.write_mot`), the annotated video if asked for, and the figures;
        its `error` is set if the ground truth could not be scored (the rows are still there).
    """
    from pftrack.io.mot import MotFile, as_written, read_ground_truth
    from pftrack.io.video import FrameSource, info_scale, read_seqinfo
    from pftrack.recovery.linking import check_scored_ids
    from pftrack.tracking.run import SeqinfoScale, track_path

    instance(seq, "track_sequence: seq", SequenceInput)  # was: an AttributeError, at its use
    instance(options, "track_sequence: options", TrackOptions)
    cpu = time.process_time()
    report, stop = running_task()
    missing = missing_detections(seq, options)  # first: the batch refuses it on the client
    if missing is not None:
        raise ValueError(missing)
    frames = FrameSource(seq.frames)
    # the boxes of det.txt and gt.txt are in seqinfo.ini's pixels
    auto_scale = info_scale(
        (frames.width, frames.height), (seq.image_width, seq.image_height), seq.name
    )
    det: Path | MotFile | None = seq.detections if options.detections == "auto" else None
    if det is not None and options.det_base is not None:  # read as numbered so, said nothing
        det = MotFile(det, options.det_base)
    det_scale = options.det_scale if options.det_scale is not None else SeqinfoScale(auto_scale)
    # the ground truth's pixels: seqinfo.ini's size when it gives one, else those of the given
    # detections' scale (det.txt and gt.txt of one sequence share them; was: 1, and MOTA -100
    # for ground truth of twice the frames' size, a user trial)
    unsized = seq.image_width is None and seq.image_height is None
    gt_scale = det_scale if unsized and det is not None else auto_scale
    render, error = options.render, None
    if render is not None:  # before the work, as track --render: frames its encoder refuses
        from pftrack.io.video_writer import check_frame_size

        try:  # are no reason to lose the tracks (was: refused after tracking, the tracks lost)
            check_frame_size(f"--render {seq.name}{render}", render, frames.width, frames.height)
        except ValueError as exc:
            render = None
            error = f"{exc} (pftrack render can draw {seq.name}.txt, which is written, into one)"
    if det is None and seq.gt is None:  # with detections or a ground truth: refused
        from pftrack.io.video import gap_note

        gap = gap_note(frames)
        if gap is not None:
            warn(gap)  # the sequence's warning, as pftrack track says it
    run = track_path(
        frames,
        detections=det,
        det_scale=det_scale,
        config=options.config,
        seed=options.seed,
        fill=options.fill,
        smooth=options.smooth,
        link=options.link,
        show_progress=False,
        threads=tracking_threads(),
        on_frame=None if report is None and stop is None else _on_frame(report, stop),
    )
    rows = run.rows
    # NAME.txt's values, what pftrack render and eval read: only for a video or a score
    written = as_written(rows) if options.render is not None or seq.gt is not None else rows
    files: dict[str, bytes] = {}
    if render is not None:
        from pftrack.render import write_annotated_video

        with tempfile.TemporaryDirectory(prefix="pftrack-render-") as tmp:
            target = Path(tmp) / f"{seq.name}{render}"
            # the source tracked, read again: what its reading said (a video shorter than its
            # header, a variable frame rate) is not said twice (was: a second FrameSource,
            # whose warnings in other words than the first's were listed twice)
            write_annotated_video(target, _checked(frames, stop), written, frames.fps)
            files[render] = target.read_bytes()
    metrics = trace = None
    if seq.gt is not None:  # last: a ground truth that cannot be scored loses no tracks
        try:
            if frames.gap is not None:  # frame k is the k-th image: the names may be gt's
                raise ValueError(
                    f"{frames.gap}: the ground truth's frame numbers may be the names or the "
                    "images' positions; rename the images 1..N in their order and number the "
                    "ground truth's frames alike"
                )
            # here, not at the top: pftrack.eval imports SciPy's optimize, 0.33 s of CPU in a
            # worker, for nothing where no sequence has ground truth (stop 64)
            from pftrack.eval.sequences import benchmark_of_path

            gt = read_ground_truth(seq.gt)  # one of no row is refused, as by pftrack eval
            check_scored_ids(gt, seq.gt)  # FILE:LINE, as pftrack eval (was: 'row K', 0-based)
            _check_gt_scale(seq, gt, written, gt_scale, frames.width)
            # the benchmark a TrackEval tree's BENCH-SPLIT folder names, as pftrack eval takes it
            named = benchmark_of_path(seq.gt)
            metrics = sequence_metrics(
                gt,
                written,
                scale=gt_scale,
                iou=options.iou,
                benchmark="auto" if named is None else named[0],
                # a frame past seqLength is refused, as pftrack eval refuses it (was: scored)
                num_frames=None if seq.seqinfo is None else read_seqinfo(seq.seqinfo).length,
            )
        except Exception as exc:  # noqa: BLE001 - the tracks are written, the task is failed
            # imported here: the refusal may come before the scorers' import above
            from pftrack.eval.sequences import name_seqinfo

            said = name_seqinfo(one_line(exc), seq.seqinfo)  # a seqLength refusal: which ini
            scoring = f"scoring against {seq.gt} (the tracks are written): {said}"
            error = scoring if error is None else f"{error}; {scoring}"
            trace = traceback.format_exc()
    info: dict[str, Any] = {
        "source": str(seq.frames),
        "frames": run.n_frames,
        "tracks": int(len(np.unique(rows[:, 1]))) if len(rows) else 0,
        "boxes": len(rows),
        "seconds": run.seconds,
        "fps": run.fps,
        "cpu_seconds": time.process_time() - cpu,  # against `seconds`: how loaded the host was
        "detections": None if det is None else str(det),
        "det_scale": det_scale,
        "gt": None if seq.gt is None else str(seq.gt),
        "gt_scale": gt_scale if seq.gt is not None else None,
        "metrics": metrics,
        "host": socket.gethostname(),
    }
    return TaskResult(rows, files, info, error=error, traceback=trace)


def _check_gt_scale(
    seq: SequenceInput, gt: F64, rows: F64, gt_scale: float, frame_width: int
) -> None:
    """Refuse to score tracks that do not match the ground truth as this batch scales it.

    :func:`~pftrack.eval.sequences.check_scale`, the check of ``pftrack eval``, whose figures
    the batch prints (was: not run, a trial: a ``seqinfo.ini`` saying 1280x960 beside 640x480
    images scaled ``gt.txt`` by 0.5 and the built-in detector's tracks scored MOTA -109.6, while
    ``pftrack eval`` of the same file gave 38.4). Its advice is ``pftrack eval``'s options: the
    message says where the batch's scale came from and what to correct.
    """
    from pftrack.eval.sequences import check_scale

    try:
        check_scale(gt, rows, scale=gt_scale, name=f"{seq.name}.txt")
    except ValueError as exc:
        how = (
            f"the frames' width {frame_width} over imWidth={seq.image_width} in {seq.seqinfo}"
            if seq.image_width
            else "the detections' scale, as the sequence's seqinfo.ini gives no size"
        )
        raise ValueError(
            f"{exc} (pftrack eval's check; the batch scaled {seq.gt} by {gt_scale:g}: {how}; "
            "if seqinfo.ini's imWidth and imHeight are not its images' size, correct them)"
        ) from None


def _on_frame(
    report: Callable[[int], None] | None, stop: Callable[[], None] | None
) -> Callable[..., None]:
    """``track_path``'s `on_frame`: report frame `n`; every few frames, the stop check."""

    def on_frame(n: int, *_: Any) -> None:
        if report is not None:
            report(n)
        if stop is not None and n % STOP_CHECK_EVERY == 0:
            stop()

    return on_frame


def read_tracks(path: PathLike) -> F64:
    """Read a tracks file whose (frame, id) pairs are unique (an error names the lines).

    :func:`pftrack.recovery.linking.read_tracks`, which the one-file commands import without
    this package.
    """
    from pftrack.io.mot import say_far_boxes
    from pftrack.recovery.linking import read_tracks as read

    rows = read(path)
    say_far_boxes(rows, path)  # the task's warning, as pftrack recover FILE says it
    return rows


@dataclass(frozen=True)
class RecoverOptions:
    """Settings of ``pftrack recover`` over several files (see its ``--help``).

    Raises
    ------
    TypeError, ValueError
        A field of the wrong type or out of its range (an unknown ``method``, ``max_gap``
        outside 1..100000, ``seed`` < 0, a ``seed`` other than 0 with a ``method`` other than
        "auto", ``max_distance`` not > 0), before any task runs.
    """

    method: RecoveryMethod = "auto"
    max_gap: int = 30
    seed: int = 0
    link: bool = False
    max_distance: float | None = None  # None: 50 px grown to the frame (gate_for_rows)

    def __post_init__(self) -> None:
        """Check every field, so that a bad value stops the batch before any task runs."""
        from pftrack.recovery.fill import MAX_GAP_LIMIT
        from pftrack.recovery.names import METHODS

        own = "RecoverOptions"  # every message names the class, as the configs' do
        _check_choice(self.method, f"{own}: method", METHODS)
        _check_int(self.max_gap, f"{own}: max_gap", 1, MAX_GAP_LIMIT)
        _check_int(self.seed, f"{own}: seed", 0)
        if self.seed != 0 and self.method != "auto":  # fill_gaps' rule, before any task runs
            raise ValueError(f"{own}: seed is used by method 'auto' only, not {self.method!r}")
        flag(self.link, f"{own}: link")
        _check_distance(self.max_distance, f"{own}: max_distance")

    def settings(self) -> dict[str, Any]:
        """JSON-ready settings (stored beside each output)."""
        return _settings(self)


def _check_distance(value: float | None, what: str) -> None:
    """A linking gate: None (grown to the frame) or a finite number > 0 (LinkConfig's rule)."""
    if value is not None and not number(value, what) > 0:
        raise ValueError(
            f"{what} is {value}, expected a finite number > 0 (or None: 50 px grown to the frame)"
        )


def recover_file(path: Path, options: RecoverOptions) -> TaskResult:
    """Fill the gaps of one tracks file as ``pftrack recover FILE`` does (no ``--video``)."""
    from pftrack.recovery import fill_gaps, link_tracklets
    from pftrack.recovery.fill import copied_values
    from pftrack.recovery.linking import link_config_for

    instance(options, "recover_file: options", RecoverOptions)  # was: an AttributeError, later
    rows = read_tracks(path)
    n_links = 0
    if options.link:
        cfg = link_config_for(rows, options.max_gap, options.max_distance)
        rows, mapping = link_tracklets(rows, cfg, None)
        n_links = len(mapping)
    t0 = time.perf_counter()
    filled, rep = fill_gaps(rows, options.method, options.max_gap, seed=options.seed)
    info: dict[str, Any] = {
        "source": str(path),
        "rows_in": len(rows),
        "fragments_linked": n_links,
        "gaps": rep.n_gaps,
        "filled_rows": rep.n_filled_rows,
        "long_holes": rep.n_long_holes,  # longer than max_gap: left unfilled
        "longest_hole": rep.longest_hole,
        "jump_holes": rep.n_jumps,  # two objects under one id: left unfilled (issue 12)
        "largest_jump": rep.largest_jump,
        "rows_out": len(filled),
        "seconds": time.perf_counter() - t0,
        "explain": rep.describe(),
    }
    return TaskResult(filled, {}, info, exact=copied_values(rows, filled))


@dataclass(frozen=True)
class SmoothOptions:
    """Settings of ``pftrack smooth`` over several files (see its ``--help``).

    Raises
    ------
    TypeError, ValueError
        ``max_gap`` not an integer in 1..100000, or ``link`` not a bool, before any task runs.
    """

    max_gap: int = 30
    link: bool = True
    max_distance: float | None = None  # None: 50 px grown to the frame (gate_for_rows)

    def __post_init__(self) -> None:
        """Check every field, so that a bad value stops the batch before any task runs."""
        from pftrack.recovery.fill import MAX_GAP_LIMIT

        own = "SmoothOptions"  # every message names the class, as the configs' do
        _check_int(self.max_gap, f"{own}: max_gap", 1, MAX_GAP_LIMIT)
        flag(self.link, f"{own}: link")
        _check_distance(self.max_distance, f"{own}: max_distance")

    def settings(self) -> dict[str, Any]:
        """JSON-ready settings (stored beside each output)."""
        return _settings(self)


def smooth_file(path: Path, options: SmoothOptions) -> TaskResult:
    """Link, fill and smooth one tracks file as ``pftrack smooth FILE`` does."""
    from pftrack.recovery.fill import long_holes, short_holes
    from pftrack.recovery.linking import link_config_for
    from pftrack.tracking import smooth_tracks
    from pftrack.tracking.offline import smoothed_copies

    instance(options, "smooth_file: options", SmoothOptions)  # was: an AttributeError, later
    t0 = time.perf_counter()
    rows = read_tracks(path)
    link = link_config_for(rows, options.max_gap, options.max_distance) if options.link else None
    result = smooth_tracks(rows, link=link, max_gap=options.max_gap)
    n_long, longest = long_holes(result, options.max_gap)  # every shorter hole was filled
    info: dict[str, Any] = {
        "source": str(path),
        "ids_in": int(len(np.unique(rows[:, 1]))) if len(rows) else 0,
        "rows_in": len(rows),
        "ids_out": int(len(np.unique(result[:, 1]))) if len(result) else 0,
        "rows_out": len(result),
        "long_holes": n_long,  # longer than max_gap: left unfilled
        "longest_hole": longest,
        "jump_holes": short_holes(result, options.max_gap),  # the others were filled: issue 12
        "seconds": time.perf_counter() - t0,
    }
    return TaskResult(result, {}, info, exact=smoothed_copies(result))
