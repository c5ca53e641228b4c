"""Argument types and option groups shared by several sub-commands."""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

from pftrack._limits import (
    DEFAULT_BURN_IN,
    DEFAULT_MH_ITER,
    DEFAULT_MH_PROPOSAL,
    DEFAULT_MH_RW_SIGMA,
    DEFAULT_MOVES,
    MAX_BURN_IN,
    MAX_JOINT_SAMPLES,
    MAX_MH_ITER,
    MAX_MH_RW_SIGMA,
    MAX_PARTICLES,
    MH_PROPOSALS,
    MOVES,
    MOVES_RULE,
    joint_samples_error,
    moves_error,
    proposal_error,
    unread_error,
)
from pftrack._text import counted as counted  # the commands' counts, re-exported

if TYPE_CHECKING:
    from pftrack.tracking import TrackerConfig

#: ``--max-side``'s default: :attr:`pftrack.tracking.TrackerConfig.max_side` (0: None). Stated
#: here, not imported, so that ``--help`` does not import the tracker; a test checks they agree.
DEFAULT_MAX_SIDE = 0
#: ``--max-side``'s range besides 0: :data:`pftrack.tracking.config.MIN_SIDE` and ``MAX_SIDE``,
#: stated here for the same reason (a test checks they agree).
MAX_SIDE_RANGE = (64, 100_000)
#: ``--crossings``' default: :attr:`pftrack.tracking.CrossingConfig.enabled` ("on" for True),
#: stated here for the same reason (a test checks they agree).
DEFAULT_CROSSINGS = "off"
#: ``--birth-score``'s default: :attr:`pftrack.tracking.LifecycleConfig.birth_score`, stated
#: here for the same reason (a test checks they agree).
DEFAULT_BIRTH_SCORE = 0.9
#: ``LifecycleConfig.max_coast``, ``--max-coast``'s default, stated here for the same reason.
DEFAULT_MAX_COAST = 10
#: ``--size-ratio``'s default: :attr:`pftrack.tracking.LifecycleConfig.size_ratio`, stated here
#: for the same reason (a test checks they agree).
DEFAULT_SIZE_RATIO = 0.8
#: ``--det-scale``'s range (``track`` and ``batch``): the one
#: :func:`pftrack.tracking.load_detections` accepts, stated here for the same reason (a test
#: checks they agree).
DET_SCALE_RANGE = (1e-3, 1e3)
#: ``--fps``'s range (``track``): :data:`pftrack.io.video.FRAME_RATE_RANGE`, the one
#: ``seqinfo.ini``'s ``frameRate`` may give, stated here for the same reason (a test checks they
#: agree).
FPS_RANGE = (0.01, 1000.0)


class HelpFormatter(argparse.RawDescriptionHelpFormatter):
    """Show every option's default and keep the description's and examples' line breaks.

    An option's help ends in ``(default: X)``, unless it says its default itself (the word
    "default" in it); a missing value reads ``(default: none)``. Flags (on when given) and
    required options show none.
    """

    def _get_help_string(self, action: argparse.Action) -> str | None:
        text = action.help or ""
        if (
            "default" in text
            or action.default is argparse.SUPPRESS
            or action.required
            or action.nargs == 0  # a flag: off unless given
            or not action.option_strings  # a positional argument
        ):
            return text
        return f"{text} (default: {'none' if action.default is None else '%(default)s'})"

    def _format_args(self, action: argparse.Action, default_metavar: str) -> str:
        if isinstance(action, WidthHeight):  # was "W [H ...]": nargs="+" takes W H or WxH
            return "W H"
        return super()._format_args(action, default_metavar)


class WidthHeight(argparse.Action):
    """``--image-size``: ``W H`` (two words) or ``WxH`` (one); shown as ``W H`` in the usage.

    With `number` (an argument type such as :func:`bounded_int`'s), the value is stored as a
    ``(W, H)`` tuple of its results, a bad one refused as argparse refuses a bad type
    (``argument --image-size: expected an integer in [1, 100000], got 0``); without, the
    words as given, for the command to check.
    """

    def __init__(
        self,
        option_strings: Sequence[str],
        dest: str,
        number: Callable[[str], Any] | None = None,
        **kwargs: Any,
    ) -> None:
        kwargs.setdefault("metavar", ("W", "H"))
        super().__init__(option_strings, dest, nargs="+", **kwargs)
        self.number = number

    def __call__(
        self,
        parser: argparse.ArgumentParser,
        namespace: argparse.Namespace,
        values: str | Sequence[Any] | None,
        option_string: str | None = None,
    ) -> None:
        words = [str(v) for v in (values or ())]
        if self.number is None:
            setattr(namespace, self.dest, words)
            return
        parts = words[0].lower().split("x") if len(words) == 1 else words
        if len(parts) != 2:
            raise argparse.ArgumentError(self, f"expected W H or WxH, got {' '.join(words)!r}")
        size = []
        for part in parts:
            try:
                size.append(self.number(part))
            except argparse.ArgumentTypeError as exc:
                raise argparse.ArgumentError(self, str(exc)) from None
            except (TypeError, ValueError):  # was "invalid int value: ''" for "10x"
                kind = {"int": "integers", "float": "numbers"}.get(
                    getattr(self.number, "__name__", ""), "numbers"
                )
                raise argparse.ArgumentError(
                    self, f"expected W H or WxH with W and H {kind}, got {' '.join(words)!r}"
                ) from None
        setattr(namespace, self.dest, tuple(size))


def add_command(sub: Any, name: str, **kwargs: Any) -> argparse.ArgumentParser:
    """Add sub-command `name` to `sub` with the package's help formatter."""
    parser: argparse.ArgumentParser = sub.add_parser(name, formatter_class=HelpFormatter, **kwargs)
    parser.add_argument(  # also accepted after the command; SUPPRESS keeps the global value
        "-q", "--quiet", action="store_true", default=argparse.SUPPRESS,
        help="no progress bars (as pftrack --quiet)",
    )  # fmt: skip
    return parser


def int_at_least(lo: int) -> Any:
    """Argument type: an integer >= `lo`."""

    def parse(text: str) -> int:
        v = int(text)
        if v < lo:
            raise argparse.ArgumentTypeError(f"expected an integer >= {lo}, got {v}")
        return v

    parse.__name__ = "int"  # argparse names the type in its messages
    return parse


#: An integer >= 1.
positive_int = int_at_least(1)
#: An integer >= 0 (``--seed``, ``--workers``).
non_negative_int = int_at_least(0)


def finite_float(text: str) -> float:
    """Argument type: a finite number (not nan, not inf)."""
    v = float(text)
    if not math.isfinite(v):
        raise argparse.ArgumentTypeError(f"expected a finite number, got {v}")
    return v


finite_float.__name__ = "float"


def iou_threshold(text: str) -> float:
    """Argument type of ``--iou`` (``eval``, ``batch``): a number in (0, 1].

    The range :func:`pftrack.eval.evaluate_mot` accepts (a test checks they agree); stated in
    :data:`IOU_HELP`.
    """
    v = float(text)
    if not 0 < v <= 1:  # also refuses nan
        raise argparse.ArgumentTypeError(f"expected a number in (0, 1], got {v:g}")
    return v


iou_threshold.__name__ = "float"

#: ``--iou``'s help (``eval``, ``batch``): one wording of :func:`iou_threshold`'s range.
IOU_HELP = "IoU threshold of a CLEAR-MOT match, in (0, 1]"


def bounded_int(lo: int, hi: int) -> Any:
    """Argument type: an integer in [lo, hi] (absurd sizes are refused, not tried)."""

    def parse(text: str) -> int:
        v = int(text)
        if not lo <= v <= hi:
            raise argparse.ArgumentTypeError(f"expected an integer in [{lo}, {hi}], got {v}")
        return v

    parse.__name__ = "int"  # argparse names the type in its messages
    return parse


def bounded_float(lo: float, hi: float) -> Any:
    """Argument type: a number in [lo, hi]."""

    def parse(text: str) -> float:
        v = float(text)
        if not lo <= v <= hi:
            raise argparse.ArgumentTypeError(f"expected a number in [{lo:g}, {hi:g}], got {v:g}")
        return v

    parse.__name__ = "float"
    return parse


def size_ratio(text: str) -> float | str:
    """Argument type of ``--size-ratio``: a number in (0, 1), or ``off``."""
    if text == "off":
        return text
    v = float(text)
    if not 0.0 < v < 1.0:
        raise argparse.ArgumentTypeError(f"expected a number in (0, 1) or off, got {v:g}")
    return v


def add_max_distance(p: argparse.ArgumentParser) -> None:
    """``--max-distance``, the linking gate of ``recover --link`` and ``smooth``."""
    p.add_argument("--max-distance", type=bounded_float(1e-3, 1e6), default=None, metavar="PX",
                   help="linking gate on the motion-prediction distance (pixels, 0.001 to 1e6; "
                   "default: 50 px, times the diagonal of the boxes' extent over 800 when it is "
                   "larger than 640x480)")  # fmt: skip


def max_side(text: str) -> int:
    """Argument type of ``--max-side``: 0 (the frame's own size) or pixels in [64, 100000]."""
    from pftrack.tracking.config import MAX_SIDE, MIN_SIDE

    v = int(text)
    if v != 0 and not MIN_SIDE <= v <= MAX_SIDE:
        raise argparse.ArgumentTypeError(
            f"expected 0 (full size) or an integer in [{MIN_SIDE}, {MAX_SIDE}], got {v}"
        )
    return v


max_side.__name__ = "int"


#: The numbers a detection file's frames may count from (``--det-base``):
#: :data:`pftrack.io.mot.FRAME_BASES`, stated here so that ``--help`` imports no reader (a
#: test checks they agree).
DET_BASES = (0, 1)
#: ``--det-base``'s help, the same for ``pftrack track`` and ``pftrack batch``.
DET_BASE_HELP = (
    "the number the detection file's frames count from (default: 1, MOTChallenge's, with a "
    "warning for a file that looks numbered from 0 and is not refused); 0: numbered from 0 (a "
    "decoder's index, KITTI's, Python's enumerate), read with 1 added to every frame; 1 "
    "stated: read from 1 without that warning"
)


def det_scale(text: str) -> float | None:
    """Argument type of ``--det-scale``: ``auto`` (None) or a number in :data:`DET_SCALE_RANGE`."""
    return None if text == "auto" else float(bounded_float(*DET_SCALE_RANGE)(text))


det_scale.__name__ = "float"


def check_input_file(path: str, *, what: str) -> None:
    """Check, before any work, that the input file `path` of option `what` can be read.

    Raises
    ------
    FileNotFoundError
        It does not exist.
    ValueError
        It is a folder, or not a regular file (``/dev/null``, a named pipe: read twice to name
        a bad line).
    PermissionError
        It cannot be read.
    """
    import os
    from pathlib import Path

    p = Path(path)
    if p.is_dir():
        raise ValueError(f"{what} {path} is a folder, not a file")
    if not p.exists():
        from pftrack.io.atomic import refuse_dash, refuse_loop

        refuse_dash(path, what)
        refuse_loop(path, what)
        raise FileNotFoundError(f"{what} not found: {path}")
    if not p.is_file():
        raise ValueError(f"{what} {path} is not a regular file (a device, pipe or socket)")
    if not os.access(p, os.R_OK):
        raise PermissionError(f"{what} {path} is not readable")


def non_negative_float(text: str) -> float:
    """Argument type: a finite number >= 0 (a probability of ``--moves``, normalised later)."""
    v = float(text)
    if not (math.isfinite(v) and v >= 0):
        raise argparse.ArgumentTypeError(f"expected a finite number >= 0, got {v:g}")
    return v


non_negative_float.__name__ = "float"


def add_chain_options(p: argparse.ArgumentParser) -> None:
    """The samplers' chain settings: ``track``'s, and ``experiments.sampler_experiment``'s.

    ``--mh-iter``, ``--mh-proposal``, ``--mh-rw-sigma`` (MH), ``--burn-in``, ``--moves``
    (RJ-MCMC); :func:`chain_error` checks them together and :func:`chain_config` puts them in a
    :class:`~pftrack.tracking.TrackerConfig`.
    """
    p.add_argument(
        "--mh-iter", type=bounded_int(1, MAX_MH_ITER), default=DEFAULT_MH_ITER, metavar="N",
        help=f"with --sampler mh: Metropolis-Hastings iterations per particle and frame (1 to "
        f"{MAX_MH_ITER}; the likelihood is evaluated particles x (N + 1) times per object)",
    )  # fmt: skip
    p.add_argument(
        "--mh-proposal", choices=MH_PROPOSALS, default=DEFAULT_MH_PROPOSAL,
        help="with --sampler mh: the chain's proposal, a fresh draw of the AR(2) dynamics from "
        "a random parent (the paper's) or a Gaussian random walk from the chain's state",
    )  # fmt: skip
    p.add_argument(
        "--mh-rw-sigma", type=bounded_float(0.0, MAX_MH_RW_SIGMA), nargs=3,
        default=list(DEFAULT_MH_RW_SIGMA), metavar=("CX", "CY", "S"),
        help=f"with --mh-proposal random_walk: standard deviations of its step, cx and cy in "
        f"pixels (scaled with the frame's size as the filter's noise is) and the scale, each 0 "
        f"to {MAX_MH_RW_SIGMA:g} (default: "
        f"{' '.join(f'{v:g}' for v in DEFAULT_MH_RW_SIGMA)})",
    )  # fmt: skip
    p.add_argument(
        "--burn-in", type=bounded_int(0, MAX_BURN_IN), default=DEFAULT_BURN_IN, metavar="B",
        help=f"with --sampler rjmcmc: burn-in iterations of the joint chain per frame (0 to "
        f"{MAX_BURN_IN}; a frame costs about (B + particles) x particles)",
    )  # fmt: skip
    p.add_argument(
        "--moves", type=non_negative_float, nargs=4, default=list(DEFAULT_MOVES),
        metavar=tuple(m.upper() for m in MOVES),
        help="with --sampler rjmcmc: probabilities of the joint chain's birth, death, update "
        f"and swap moves, normalised by the chain: finite and >= 0, not all 0, {MOVES_RULE} "
        f"(default: {' '.join(f'{v:g}' for v in DEFAULT_MOVES)})",
    )  # fmt: skip


def chain_error(args: argparse.Namespace) -> str | None:
    """The message refusing :func:`add_chain_options`' values together, or None.

    The ranges argparse checks alone; here what depends on several values: the moves' rule
    and the random-walk step without ``--mh-proposal random_walk``.
    """
    return moves_error(tuple(args.moves), "--moves") or proposal_error(
        args.mh_proposal, tuple(args.mh_rw_sigma), ("--mh-proposal", "--mh-rw-sigma"), cli=True
    )


def chain_config(args: argparse.Namespace, base: TrackerConfig) -> TrackerConfig:
    """`base` with :func:`add_chain_options`' values (checked: :func:`chain_error`)."""
    from dataclasses import replace

    b, d, u, w = args.moves
    return replace(
        base,
        mh_iter=args.mh_iter,
        mh_proposal=args.mh_proposal,
        mh_rw_sigma=tuple(args.mh_rw_sigma),
        rjmcmc=replace(
            base.rjmcmc, burn_in=args.burn_in, p_birth=b, p_death=d, p_update=u, p_swap=w
        ),
    )


def add_tracker_options(p: argparse.ArgumentParser) -> None:
    """The tracker's options, shared by ``track`` (and any command that tracks).

    The samplers' limits and defaults are :mod:`pftrack._limits`' constants, which
    :class:`pftrack.Tracker` checks against too.
    """
    p.add_argument(
        "--particles", type=bounded_int(0, MAX_PARTICLES), default=0, metavar="N",
        help=f"particles per object (1 to {MAX_PARTICLES}; with --sampler rjmcmc, the joint "
        f"chain's kept samples, 1 to {MAX_JOINT_SAMPLES}: its cost per frame grows as N "
        "squared, about 8 ms at 2000 and 0.15 s at 10000 with 5 objects); 0: 200 with "
        "--detections for sis and mh, else 100",
    )  # fmt: skip
    p.add_argument("--seed", type=non_negative_int, default=0,
                   help="random seed, an integer >= 0: same seed, same tracks")  # fmt: skip
    p.add_argument(
        "--detector", choices=("paper", "mog2", "knn"), default="paper",
        help="built-in detector: the paper's adaptive background (C++), or OpenCV's MOG2/KNN",
    )  # fmt: skip
    p.add_argument(
        "--bootstrap", choices=("auto", "spread", "first", "none"), default="auto",
        help="starting background: the median of 30 frames spread over the whole video (a "
        "first pass; people present from frame 1 leave no ghost), of the first 30 frames "
        "(streaming), or the first frame alone; auto: spread for the built-in detector, first "
        "with --detections (only box refinement uses it)",
    )  # fmt: skip
    p.add_argument(
        "--sampler", choices=("sis", "mh", "rjmcmc"), default="sis",
        help="sis: one sequential-importance-sampling filter per object (the paper's method); "
        "mh: Metropolis-Hastings per object; rjmcmc: one joint RJ-MCMC chain over all objects "
        "(Smith et al. 2005)",
    )  # fmt: skip
    add_chain_options(p)
    p.add_argument(
        "--dynamics", choices=("ar2", "ar2-mean"), default="ar2",
        help="AR(2) model per particle (eq. 7) or from the particle-set means (eq. 8)",
    )  # fmt: skip
    p.add_argument(
        "--camera-motion", choices=("auto", "on", "off"), default="auto",
        help="camera-motion compensation: auto measures the camera's motion each frame and, "
        "once it moves, moves the tracks with it and stops using the background model (a still "
        "camera tracks exactly as with off); on: treat the camera as always moving",
    )  # fmt: skip
    p.add_argument(
        "--max-side", type=max_side, default=DEFAULT_MAX_SIDE, metavar="PX",
        help=f"working resolution: frames whose longer side is larger are scaled down to PX "
        f"pixels for detection and tracking, boxes written in the frame's pixels; PX from "
        f"{MAX_SIDE_RANGE[0]} to {MAX_SIDE_RANGE[1]}, or 0 to track at the frame's own size",
    )  # fmt: skip
    p.add_argument(
        "--open-size", type=bounded_int(0, 255), default=0, metavar="PX",
        help="built-in detector: side of the opening that cleans its mask, in pixels (0 to "
        "255); 0 takes "
        "it from the frame's rows (3 at 360 rows, 5 at 480): raise it when touching people "
        "stay joined, lower it when thin people break apart",
    )  # fmt: skip
    p.add_argument("--max-coast", type=bounded_int(0, 100_000), default=DEFAULT_MAX_COAST,
                   metavar="FRAMES", help="frames a track survives on its particle filter alone "
                   "(0.4 s at 25 frames/s: pftrack.Tracker's max_coast is in seconds); refused "
                   "with --sampler rjmcmc, whose chain keeps tracks by their existence "
                   "probability")  # fmt: skip
    p.add_argument(
        "--min-conf", type=finite_float, default=0.0, metavar="C",
        help="ignore detections whose score is below C; the built-in detector's score is the "
        "share of foreground pixels in a blob's box, in [0, 1], so C must lie in [0, 1] "
        "without --detections",
    )  # fmt: skip
    p.add_argument(
        "--birth-score", type=bounded_float(0.0, 1.0), default=None, metavar="S",
        help="with --detections: a detection starts a track with a score of at least min(S, "
        "the lower quartile of the scores of 50 frames from the first with detections), S in "
        "[0, 1] (applied while "
        "every score lies in [0, 1]; other scores never gate births); refused without "
        f"--detections: the built-in detector starts a track from any blob (default: "
        f"{DEFAULT_BIRTH_SCORE:g})",
    )  # fmt: skip
    p.add_argument(
        "--size-ratio", type=size_ratio, default=None, metavar="R",
        help="with --detections and the smoother: leave out every track whose median height is "
        "below R or above 1/R times the height a line of the detections' heights against "
        "their foot row gives at its row (tracks on a detector's false boxes), R in (0, 1), or "
        "off; judged only on a still camera, within the detections' rows, and where the line "
        "explains the detections' heights (not when people's sizes do not follow their row, "
        "nor under a zoom); refused without --detections: the built-in detector has its own "
        f"size model (default: {DEFAULT_SIZE_RATIO:g})",
    )  # fmt: skip
    p.add_argument(
        "--fill", choices=("linear", "pf"), default="linear",
        help="boxes of a gap the filter bridged: interpolated between the detections at its "
        "ends, or the filter's own; written as they are with --no-smooth; with smoothing the "
        "smoother's boxes replace them, and they only guide the offline linking (and "
        "--crossings)",
    )  # fmt: skip
    p.add_argument(
        "--no-smooth", action="store_true",
        help="write each frame's box as the tracker reported it online, instead of smoothing "
        "every track over the whole run (RTS smoother; bridged gaps are the smoother's "
        "interpolation)",
    )  # fmt: skip
    p.add_argument(
        "--crossings", choices=("on", "off"), default=DEFAULT_CROSSINGS,
        help="offline pass: where two tracks' boxes overlapped, exchange their tails when "
        "each one's motion and size before the crossing predict the other's after it better "
        "(tracks the tracker swapped; motion and size only, no colour); part of the smoothing "
        "pass: refused with --no-smooth",
    )  # fmt: skip
    p.add_argument(
        "--no-refine", action="store_true",
        help="with --detections, take the boxes as given instead of shrinking each to the "
        "foreground of a background model (for a detector with tight boxes; no background "
        "model runs, no frames are read ahead for it); refused without --detections. Use it "
        "too for sideways or overhead-rotated footage: refinement, like the built-in "
        "detector, assumes upright people",
    )  # fmt: skip
    p.add_argument(
        "--no-link", action="store_true",
        help="keep fragments of one object under separate ids, instead of joining them by "
        "motion and size across gaps of up to 30 frames",
    )  # fmt: skip


def tracker_config(args: argparse.Namespace) -> TrackerConfig:
    """The :class:`~pftrack.tracking.TrackerConfig` that :func:`add_tracker_options` describes.

    Raises
    ------
    ValueError
        Options that contradict each other (``--crossings on`` or ``--size-ratio R`` with
        ``--no-smooth``), or an option of given detections without them (``--det-scale S``,
        ``--birth-score``, ``--size-ratio``, ``--no-refine``, and a ``--min-conf`` outside the
        built-in detector's scores, [0, 1]); more than
        :data:`pftrack._limits.MAX_JOINT_SAMPLES` ``--particles`` with ``--sampler rjmcmc``;
        ``--moves`` the joint chain cannot use; ``--mh-iter``, ``--mh-proposal`` or
        ``--mh-rw-sigma`` without ``--sampler mh``, ``--mh-rw-sigma`` without ``--mh-proposal
        random_walk``, ``--burn-in`` or ``--moves`` without ``--sampler rjmcmc``. The sampler
        checks are :class:`pftrack.Tracker`'s (:mod:`pftrack._limits`), with the options' names.
    """
    from dataclasses import replace

    if args.crossings == "on" and args.no_smooth:  # the repair is part of the offline pass
        raise ValueError(
            "--crossings on needs the smoother, which --no-smooth turns off; drop one of them"
        )
    if isinstance(getattr(args, "size_ratio", None), float) and args.no_smooth:
        raise ValueError(
            f"--size-ratio {args.size_ratio:g} judges the smoothed tracks, and --no-smooth "
            "turns the smoother off; drop one of them"
        )
    if not getattr(args, "detections", None):  # the built-in detector: options it never uses
        if getattr(args, "det_scale", None) is not None:
            raise ValueError(
                f"--det-scale {args.det_scale:g} scales the boxes of --detections; the built-in "
                "detector's are in the frame's pixels: drop it, or give --detections"
            )
        if getattr(args, "det_base", None) is not None:
            raise ValueError(
                f"--det-base {args.det_base} says how --detections numbers its frames; the "
                "built-in detector reads no file: drop it, or give --detections"
            )
        if args.birth_score is not None:
            raise ValueError(
                f"--birth-score {args.birth_score:g} gates the births of --detections; the "
                "built-in detector starts a track from any blob: drop it, or give --detections"
            )
        if getattr(args, "size_ratio", None) is not None:
            raise ValueError(
                f"--size-ratio {args.size_ratio} judges the tracks of --detections; the "
                "built-in detector has its own size model: drop it, or give --detections"
            )
        if args.no_refine:
            raise ValueError(
                "--no-refine takes the boxes of --detections as given; the built-in "
                "detector's boxes are not refined: drop it, or give --detections"
            )
        if not 0.0 <= args.min_conf <= 1.0:
            raise ValueError(
                f"--min-conf {args.min_conf:g}: the built-in detector's scores are the share of "
                "foreground pixels in a blob's box, in [0, 1]; give a value in [0, 1], or "
                "--detections"
            )

    elif args.no_refine:  # no background model runs: the options of one do nothing
        unused = [
            f"{flag} {value}"
            for flag, value, default, used in (
                ("--bootstrap", getattr(args, "bootstrap", "auto"), "auto", False),
                ("--detector", args.detector, "paper", args.sampler == "rjmcmc"),
                ("--open-size", args.open_size, 0, args.sampler == "rjmcmc"),
            )
            if value != default and not used  # RJ-MCMC reads the detector's foreground
        ]
        if unused:
            raise ValueError(
                f"{', '.join(unused)}: with --no-refine no background model runs, so "
                f"{'it does' if len(unused) == 1 else 'they do'} nothing: drop "
                f"{'it' if len(unused) == 1 else 'them'}, or --no-refine"
            )

    moves = tuple(args.moves)
    rw_sigma = tuple(args.mh_rw_sigma)
    refused = (
        (joint_samples_error(args.particles, "--particles", "--sampler rjmcmc")
         if args.sampler == "rjmcmc" else None)
        or chain_error(args)
        or unread_error(args.sampler, {"mh_iter": args.mh_iter, "mh_proposal": args.mh_proposal,
                                       "mh_rw_sigma": rw_sigma, "burn_in": args.burn_in,
                                       "moves": moves}, cli=True)
    )  # fmt: skip
    if refused:
        raise ValueError(refused)
    if args.sampler == "rjmcmc":  # the joint chain's own existence and births decide
        unused = [
            f"{flag} {value:g}"
            for flag, value, default in (
                ("--max-coast", args.max_coast, DEFAULT_MAX_COAST),
                ("--birth-score", args.birth_score, None),
            )
            if value is not None and value != default
        ]
        if unused:
            raise ValueError(
                f"{', '.join(unused)}: the joint sampler (--sampler rjmcmc) keeps and starts "
                "tracks by its own existence probabilities, so "
                f"{'it does' if len(unused) == 1 else 'they do'} nothing: drop "
                f"{'it' if len(unused) == 1 else 'them'}, or use --sampler sis or mh"
            )

    from pftrack.tracking import TrackerConfig

    base = chain_config(args, TrackerConfig())
    model = replace(base.filter.model, use_means=args.dynamics == "ar2-mean")
    filt = replace(base.filter, n_particles=args.particles or base.filter.n_particles, model=model)
    return replace(
        base,
        filter=filt,
        given_particles=None if args.particles else base.given_particles,
        detector=args.detector,
        sampler=args.sampler,
        camera_motion=args.camera_motion,
        max_side=args.max_side or None,
        open_size=args.open_size or None,
        refine=replace(base.refine, enabled=not args.no_refine),
        crossings=replace(base.crossings, enabled=args.crossings == "on"),
        lifecycle=replace(
            base.lifecycle,
            max_coast=args.max_coast,
            min_score=args.min_conf,
            birth_score=DEFAULT_BIRTH_SCORE if args.birth_score is None else args.birth_score,
            size_ratio=_size_ratio(getattr(args, "size_ratio", None)),
        ),
    )


def _size_ratio(value: float | str | None) -> float | None:
    """``LifecycleConfig.size_ratio`` from ``--size-ratio`` (None: not given; ``off``)."""
    if value is None:
        return DEFAULT_SIZE_RATIO
    return None if value == "off" else float(value)


def opencv_single_threaded() -> None:
    """Give OpenCV one thread in this process (the commands that decode and track).

    On these frame sizes OpenCV's thread pool does not shorten a run and costs CPU spinning
    in the kernel: ``pftrack track`` on PETS09-S2L1 takes the same 4.1-4.4 s wall either way,
    with 6.5 s of CPU (1.1 s system) against 5.3 s (0.2 s) with one thread. The decoding thread
    and the GIL-free C++ kernels still use a second core. Library calls leave OpenCV's setting
    alone: only the command's own process is changed.
    """
    import cv2

    cv2.setNumThreads(1)


def is_stdout(*paths: str | None) -> bool:
    """Whether one of `paths` is where this process's standard output goes.

    ``--out /dev/stdout`` (or ``/dev/fd/1``, or the very file stdout is redirected to): the
    rows go there, so a command's own report (summary lines, tables) must not. Compared by
    device and inode, so a pipe or a redirected file is recognised under any name.
    """
    import os
    import sys

    try:
        fd = sys.stdout.fileno()
        target = os.fstat(fd)
    except (AttributeError, OSError, ValueError):  # no real stdout (a test's capture)
        return False
    for path in paths:
        if not path:
            continue
        try:
            st = os.stat(path)
            if os.path.samefile(path, os.devnull):  # discarded: nothing there to keep apart
                continue
        except OSError:
            continue
        if (st.st_dev, st.st_ino) == (target.st_dev, target.st_ino):
            return True
    return False


def report_stream(*outputs: str | None) -> Any:
    """Where a command prints its report: stderr when an output is stdout, else stdout."""
    import sys

    return sys.stderr if is_stdout(*outputs) else sys.stdout


#: What a file an output option would replace may be, for the message of
#: :func:`~pftrack.io.atomic.check_replaceable` (a picture, a JSON or CSV file: the user's).
YOURS = "pftrack did not write (a file of yours?)"
#: The same for a tracks ``--out``: a file that holds no MOTChallenge rows.
TRACKS_YOURS = "holds no MOTChallenge rows (a file of yours?)"


def add_force(parser: argparse.ArgumentParser) -> None:
    """``--force``: replace output files pftrack did not write (docs/io.md's one rule)."""
    parser.add_argument(
        "--force", action="store_true",
        help="replace an existing output file that pftrack did not write (default: refused, "
        "exit 2; absent, empty and pftrack's own files are always replaced)",
    )  # fmt: skip
