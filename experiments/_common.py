"""What the experiment scripts share: where the data is, where the output goes."""

from __future__ import annotations

import argparse
import contextlib
import io
import os
import sys
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TextIO

from pftrack._typing import F64, PathLike
from pftrack.cli import Parser
from pftrack.cli._options import bounded_int
from pftrack.io.atomic import atomic_write
from pftrack.io.mot import read_mot

REPO = Path(__file__).resolve().parents[1]
"""The repository root (the folder holding ``experiments/``)."""


@dataclass(frozen=True)
class Source:
    """One real sequence of the data folder: its folder, video file, ground-truth scale onto
    the video (PETS09's ground truth is in 768x576 pixels, its video 480x360)."""

    name: str
    video: str
    scale: float


PETS = Source("pets09-s2l1", "video.avi", 0.625)
TUD = Source("tud-campus", "video.mp4", 1.0)

NO_VIDEO = ("ADL-Rundle-6", "ETH-Sunnyday", "KITTI-17")
"""The sequences of ``mot15-gt/``: ground truth, public detections and seqinfo.ini, no video."""


def frame_truth(src: Source, data: Path) -> F64:
    """The ground truth of `src` under `data` in its video's pixels, zero-marked rows left out."""
    gt = read_mot(data / src.name / "gt.txt")
    gt = gt[gt[:, 6] != 0]
    gt[:, 2:6] *= src.scale
    return gt


def scene_size(
    count_name: str, count: int, n_frames: int, size: tuple[int, int]
) -> tuple[int, int]:
    """A synthetic scene's ``size`` (width, height), its object count and length checked."""
    if count < 1 or n_frames < 1:
        raise ValueError(f"{count_name} {count} and n_frames {n_frames} must be >= 1")
    width, height = size
    if width < 160 or height < 120:
        raise ValueError(f"size is {size}, expected at least 160 x 120")
    return width, height


def data_root(arg: PathLike | None = None) -> Path:
    """The folder holding ``pets09-s2l1/`` and ``tud-campus/``.

    `arg` if given, else ``$PFTRACK_DATA``, else ``../shared/data`` beside the repository.
    """
    if arg:
        return Path(arg)
    if os.environ.get("PFTRACK_DATA"):
        return Path(os.environ["PFTRACK_DATA"])
    return REPO / ".." / "shared" / "data"


def data_folder(arg: PathLike | None = None) -> Path | None:
    """:func:`data_root` of `arg` if it is a folder; else None, said on stderr.

    The caller then returns 2: ``if (root := data_folder(args.data)) is None: return 2``.
    """
    root = data_root(arg)
    if root.is_dir():
        return root
    print(f"data folder not found: {root} (set --data or PFTRACK_DATA)", file=sys.stderr)
    return None


def video_folders(
    data: Path, sources: Sequence[Source] = (PETS, TUD)
) -> Iterator[tuple[Source, Path]]:
    """Each of `sources` found under `data`, with its folder, in order.

    One not found is passed over with a note printed in its place:
    ``tud-campus: not found under DATA, skipped``.
    """
    for src in sources:
        folder = data / src.name
        if folder.is_dir():
            yield src, folder
        else:
            print(f"{src.name}: not found under {data}, skipped")


def no_video_folders(data: Path) -> Iterator[tuple[str, Path]]:
    """Each :data:`NO_VIDEO` sequence found under ``data/mot15-gt``, with its folder, in order.

    One not found is passed over with a note printed in its place, as by :func:`video_folders`.
    """
    for name in NO_VIDEO:
        folder = data / "mot15-gt" / name
        if folder.is_dir():
            yield name, folder
        else:
            print(f"{name}: not found under {data / 'mot15-gt'}, skipped")


class _ExperimentParser(Parser):
    """An experiment's parser: ``--help`` shows every option's default.

    An option whose help does not state its default gets ``(default: ...)`` added (flags and
    options without a default excepted). Bad usage is one line and status 2, as ``pftrack``'s
    (:class:`pftrack.cli.Parser`; was: argparse's whole usage first), and so is an ``--out``
    that cannot be a folder (was: the traceback of its ``mkdir``, after the argument checks).
    """

    def parse_known_args(  # type: ignore[override]
        self, args: Sequence[str] | None = None, namespace: argparse.Namespace | None = None
    ) -> tuple[argparse.Namespace, list[str]]:
        parsed, extra = super().parse_known_args(args, namespace)
        out = getattr(parsed, "out", None)
        if isinstance(out, Path):
            problem = _out_problem(out)
            if problem:
                self.error(f"--out {out}: {problem}")
        return parsed, extra

    def format_help(self) -> str:
        for action in self._actions:
            default = action.default
            if not action.option_strings or any(
                default is v for v in (None, False, argparse.SUPPRESS)
            ):  # (0 == False: compared by identity)
                continue
            if action.help is None:
                action.help = "(default: %(default)s)"
            elif "default" not in action.help and action.help != argparse.SUPPRESS:
                action.help += " (default: %(default)s)"
        return super().format_help()


def _out_problem(out: Path) -> str:
    """Why `out` cannot be made a writable folder ("" if it can): its nearest existing path."""
    here = out
    while not here.exists() and here != here.parent:
        here = here.parent
    if not here.is_dir():
        return f"{here} is not a folder"
    if not os.access(here, os.W_OK | os.X_OK):
        return f"{here} is not writable"
    return ""


def experiment_parser(name: str, doc: str | None) -> argparse.ArgumentParser:
    """The parser of ``python -m experiments.<name>``, with ``--data`` and ``--out``.

    Parameters
    ----------
    name : str
        The experiment's module name; the default output folder is ``out/<name>``.
    doc : str or None
        The module docstring; its first line is the description.
    """
    parser = _ExperimentParser(
        prog=f"python -m experiments.{name}", description=(doc or name).split("\n")[0]
    )
    parser.add_argument(
        "--data",
        type=Path,
        default=None,
        help="folder with pets09-s2l1/ and tud-campus/ (default: $PFTRACK_DATA or ../shared/data)",
    )
    parser.add_argument(
        "--out",
        type=Path,
        default=Path("out") / name,
        help=f"output folder for tables and figures (default: out/{name})",
    )
    return parser


def add_detections_and_seeds(parser: argparse.ArgumentParser) -> None:
    """``--detections public builtin`` and ``--seeds N`` (tracker seeds 0..N-1, default 3)."""
    parser.add_argument(
        "--detections", nargs="+", choices=("public", "builtin"), default=["public", "builtin"],
        help="public det.txt and/or the built-in detector (default both)",
    )  # fmt: skip
    parser.add_argument(
        "--seeds", type=bounded_int(1, 1000), default=3,
        help="tracker seeds 0..N-1, N in [1, 1000] (default 3)",
    )  # fmt: skip


def write_text(path: Path, text: str) -> None:
    """Write `text` to `path` atomically, creating its folder."""
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_write(path) as fh:
        fh.write(text)


class _Tee(io.StringIO):
    """A text stream that keeps what is written and passes it on to `stream`."""

    def __init__(self, stream: TextIO) -> None:
        super().__init__()
        self._stream = stream

    def write(self, s: str) -> int:
        self._stream.write(s)
        return super().write(s)

    def flush(self) -> None:
        self._stream.flush()


@contextlib.contextmanager
def tee_stdout(path: Path) -> Iterator[None]:
    """Print as usual inside the block and also save everything printed to `path`.

    The file is written when the block ends without an exception.
    """
    tee = _Tee(sys.stdout)
    with contextlib.redirect_stdout(tee):
        yield
    write_text(path, tee.getvalue())
