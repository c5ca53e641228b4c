"""What a batch runs on: sequences found in videos, image folders and MOTChallenge folders.

A *sequence* is one video file, one folder of images, or one MOTChallenge sequence folder
(``SEQ/img1/`` or a single video in ``SEQ/``, with ``seqinfo.ini``, ``det/det.txt`` and
``gt/gt.txt``; ``SEQ/det.txt`` and ``SEQ/gt.txt`` are accepted too). A folder that is none of
these is a folder of sequences: each entry in it that is a sequence is one (one level deep).
Sequences deeper than that (``DIR/train/SEQ`` when ``DIR`` is given) are not tracked, but never
passed over silently: with none found the error names the folders that hold them, with some a
warning does.
"""

from __future__ import annotations

import json
import os
import stat
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from pftrack._check import shown
from pftrack._text import counted
from pftrack._typing import PathLike
from pftrack._warn import warn
from pftrack.io.atomic import refuse_dash, refuse_loop
from pftrack.io.mot import is_mot_text
from pftrack.io.video import (
    VIDEO_SUFFIXES,
    image_files,
    natural_key,
    read_seqinfo,
    video_files,
)

__all__ = ["VIDEO_SUFFIXES", "SequenceInput", "find_sequences", "find_track_files"]

#: File extensions taken as videos when a folder is scanned.

#: What a batch is given: one path or several.
Inputs = PathLike | list[PathLike] | tuple[PathLike, ...]

#: How the refusal of a stream URL among a batch's sequences ends.
_LIVE = " (pftrack track reads a stream live, alone)"

#: Names a sequence may not have: its outputs would overwrite the batch's own files.
RESERVED_NAMES = ("summary",)


@dataclass(frozen=True)
class SequenceInput:
    """One sequence of a batch.

    Attributes
    ----------
    name : str
        Output name: the video's stem or the sequence folder's name (``DIR/NAME.txt``).
    frames : Path
        What :class:`~pftrack.io.video.FrameSource` reads: a video file or an image folder.
    detections : Path or None
        The sequence's detection file (``det/det.txt`` or ``det.txt``), if any.
    gt : Path or None
        Its ground truth (``gt/gt.txt`` or ``gt.txt``), if any.
    image_width, image_height : int or None
        ``imWidth`` and ``imHeight`` of its ``seqinfo.ini``: the size the detection and
        ground-truth boxes are given in (PETS09's are 768x576 for a 480x360 video).
    """

    name: str
    frames: Path
    detections: Path | None = None
    gt: Path | None = None
    image_width: int | None = None
    image_height: int | None = None
    seqinfo: Path | None = None

    @property
    def files(self) -> tuple[Path, ...]:
        """Every file or folder the sequence reads.

        ``seqinfo.ini`` too: its sizes scale the boxes, so a resumed batch redoes a sequence
        whose ``seqinfo.ini`` changed.
        """
        paths = (self.frames, self.detections, self.gt, self.seqinfo)
        return tuple(p for p in paths if p is not None)


def _absolute(inputs: Inputs, hint: str = "") -> list[Path]:
    """The inputs as absolute paths: workers may run in another folder than this process.

    Raises
    ------
    TypeError
        `inputs` is neither a path nor an iterable of paths, or one of them is no path
        (was: Python's words, "'NoneType' object is not iterable", naming no parameter).
    ValueError
        No input, an empty path or ``-``, or a URL (``rtsp://cam/stream``; `hint` ends that
        message; was: "input not found: /cwd/rtsp:/cam/stream").
    """
    if isinstance(inputs, bytes):
        inputs = os.fsdecode(inputs)
    if isinstance(inputs, (str, os.PathLike)):
        paths: list[object] = [inputs]
    else:
        try:  # a list, a tuple, or any iterable of paths (Path.glob's)
            paths = list(inputs)
        except TypeError:
            raise TypeError(
                f"inputs must be a path or a list of paths, got {shown(inputs)}"
            ) from None
    given: list[str | os.PathLike[str]] = []
    for i, p in enumerate(paths):
        if isinstance(p, bytes):
            p = os.fsdecode(p)
        if not isinstance(p, (str, os.PathLike)):
            raise TypeError(f"inputs[{i}] must be a path (str or os.PathLike), got {shown(p)}")
        given.append(p)
    if not given:
        raise ValueError("no input given")
    for p in given:  # was: "input not found: /cwd/-"
        refuse_dash(p, "input", name="file or folder")
        if os.fspath(p) == "":  # was: the current folder, tracked as an image folder
            raise ValueError("an input is an empty path; give a file or folder")
        if "://" in os.fspath(p) and not os.path.lexists(p):
            raise ValueError(
                f"input {os.fspath(p)} is a URL, not a file or a folder: a batch reads files{hint}"
            )
    return [Path(os.path.abspath(p)) for p in given]


def _first_file(folder: Path, *candidates: str) -> Path | None:
    for rel in candidates:
        if (folder / rel).is_file():
            return folder / rel
    return None


def _batch_output(path: Path) -> bool:
    """Whether the video `path` was written by a batch: the sidecar beside it lists it.

    ``pftrack batch --render`` writes ``DIR/NAME.mp4`` with its sidecar ``DIR/NAME.json``
    (:mod:`pftrack.batch.engine`), whose ``outputs`` name it (or, after a later run without
    ``--render``, its ``earlier_outputs``). Such a video is not an input
    when its folder is looked into: a batch whose ``--out`` is its input folder can be re-run.
    """
    sidecar = path.with_name(f"{path.stem}.json")
    try:
        if not sidecar.is_file():  # ENAMETOOLONG for a 251-byte stem: no sidecar either
            return False
        entry = json.loads(sidecar.read_text(encoding="utf-8"))
    except (OSError, ValueError):  # not a sidecar of ours: the video is an input
        return False
    if not isinstance(entry, dict) or entry.get("kind") != "track":
        return False
    listed = [entry.get("outputs"), entry.get("earlier_outputs")]  # earlier: a run since
    return any(isinstance(v, list) and path.name in v for v in listed)


def _videos(folder: Path) -> list[Path]:
    """The videos of a sequence folder, less those a batch rendered into it."""
    return [p for p in video_files(folder) if not _batch_output(p)]


def _sequences_beside(folder: Path) -> list[Path]:
    """The videos and sequence-like folders in `folder` (sequences of their own)."""
    out = []
    for p in sorted(folder.iterdir(), key=_listing_key):
        if p.name[0] == ".":
            continue
        if p.is_file() and p.suffix.lower() in VIDEO_SUFFIXES and not _batch_output(p):
            out.append(p)
        elif p.is_dir() and _sequence_like(p):
            out.append(p)
    return out


def _sequence_like(folder: Path) -> bool:
    """Whether `folder` looks like a sequence; False for one that cannot be listed.

    (``lost+found`` at the top of a disk: its refusal must not refuse the folder around it.)
    """
    try:
        return (
            (folder / "seqinfo.ini").is_file()
            or (folder / "img1").is_dir()
            or bool(image_files(folder))
            or bool(_videos(folder))
        )
    except OSError:
        return False


def _image_folder(path: Path) -> SequenceInput | None:
    """A folder of images as one sequence; None without images.

    Refused when it also holds videos or sequence folders: a stray ``thumbnail.jpg`` in a
    folder of videos made the whole folder one sequence of one frame, the videos passed over
    with exit status 0 (a user trial). Which was meant is not known.
    """
    images = image_files(path)
    if not images:
        return None
    others = _sequences_beside(path)
    if others:
        listed = ", ".join(p.name for p in others[:3]) + (", ..." if len(others) > 3 else "")
        pictures = ", ".join(p.name for p in sorted(images)[:3]) + (
            ", ..." if len(images) > 3 else ""
        )
        raise ValueError(
            f"folder {path} holds {len(images)} image{'s' * (len(images) > 1)} ({pictures}) "
            f"and {len(others)} video{'s' * (len(others) > 1)} or sequence folder"
            f"{'s' * (len(others) > 1)} ({listed}): whether it is one sequence of images or a "
            "folder of sequences is not known; move the images into a folder of their own, or "
            "the others out"
        )
    return SequenceInput(path.name, path, *_annotations(path))


def _as_sequence(path: Path) -> SequenceInput | None:
    """`path` as one sequence, or None when it is a folder of sequences."""
    beside = path.parent / "seqinfo.ini"
    if path.is_file():
        # SEQ/video.avi (../shared/data's layout): SEQ's detections, truth and sizes, as
        # pftrack track reads it (was: none, --detections auto failed, no metrics)
        return (
            _within(path.stem, path, beside) if beside.is_file() else SequenceInput(path.stem, path)
        )
    if (
        beside.is_file()
        and not (path / "seqinfo.ini").is_file()
        and (path.name == "img1" or image_files(path))
    ):  # SEQ/img1 or SEQ/IMDIR given: the sequence SEQ, these frames, as pftrack track reads
        # them (was: SEQ's imDir read instead of img1; IMDIR a sequence without det.txt)
        return _within(path.parent.name, path, beside)
    if path.name == "img1":  # SEQ/img1 given, no seqinfo.ini: the sequence is SEQ, as
        path = path.parent  # pftrack track takes it (was: 'img1', no det.txt)
    ini = path / "seqinfo.ini"
    if not ini.is_file():
        if (path / "img1").is_dir():
            return SequenceInput(path.name, path / "img1", *_annotations(path))
        return _image_folder(path)
    # a sequence folder, read as pftrack track reads it: its imDir, else its one video
    try:
        info = read_seqinfo(ini)
    except ValueError:  # its task reads it again and fails, naming the fault; the others run
        return SequenceInput(path.name, path, seqinfo=ini)
    frames = path / info.image_dir
    if not frames.is_dir():
        videos = _videos(path)  # the shared data's layout: SEQ/video.avi
        # none or several: the task fails, as pftrack track SEQ does, and the others run
        frames = videos[0] if len(videos) == 1 else path
    return SequenceInput(
        path.name, frames, *_annotations(path), info.width, info.height, seqinfo=ini
    )


def _within(name: str, frames: Path, ini: Path) -> SequenceInput:
    """`frames` (a video or an image folder) of the sequence folder of `ini`, given itself.

    With that folder's detections, ground truth and ``seqinfo.ini`` sizes, as
    ``pftrack track FRAMES`` reads them.
    """
    try:
        info = read_seqinfo(ini)
    except ValueError:  # its task reads it again and fails, naming the fault; the others run
        return SequenceInput(name, frames, seqinfo=ini)
    annotations = _annotations(ini.parent)
    return SequenceInput(name, frames, *annotations, info.width, info.height, seqinfo=ini)


def _refuse_tracks_file(path: Path) -> None:
    """Refuse a file of MOTChallenge rows given as a sequence, before any work.

    ``pftrack batch gt.txt`` (a tracks file meant for ``recover`` or ``smooth``) was a task
    that failed as "not a video", exit 1, after the batch had started and made ``--out``.
    """
    if (
        path.is_file()
        and path.suffix.lower() not in VIDEO_SUFFIXES
        and path.stat().st_size > 0
        and is_mot_text(path)
    ):
        raise ValueError(
            f"{path} holds MOTChallenge rows (tracks or detections), not frames: pftrack batch "
            "tracks videos, image folders and sequence folders; pftrack recover or pftrack "
            "smooth take tracks files"
        )


def _readable_as_sequence(path: Path) -> SequenceInput | None:
    """:func:`_as_sequence`, or a sequence whose task fails for a folder it cannot look into.

    As an unreadable video is (the others run; :func:`cannot_read` names it in the failed
    entry). Was: the whole batch stopped, exit 2, with ``Permission denied: DIR/seqinfo.ini``.
    """
    try:
        return _as_sequence(path)
    except PermissionError:
        if cannot_read(path) is None:  # deeper (its det/ unreadable): said as it is
            raise
        return SequenceInput(path.name, path)


def _annotations(folder: Path) -> tuple[Path | None, Path | None]:
    """A sequence folder's detection and ground-truth files, if any."""
    return (
        _first_file(folder, "det/det.txt", "det.txt"),
        _first_file(folder, "gt/gt.txt", "gt.txt"),
    )


#: How far below a folder of sequences :func:`_below` looks for the sequences it passed over
#: (``DIR/a/b/c/SEQ`` for ``DIR``), and how many folders it lists at most: a hint, not a scan.
DEEPER_LEVELS = 3
DEEPER_FOLDERS = 256


def _has_frames(folder: Path) -> bool:
    """Whether `folder` is a sequence with frames to track (False if it cannot be listed).

    Stricter than :func:`_sequence_like`: a folder of annotations alone (``seqinfo.ini`` and
    ``gt.txt``, no images or video, as ``../shared/data/mot15-gt/*``) is no sequence to point
    a user at.
    """
    try:
        ini = folder / "seqinfo.ini"
        if ini.is_file():
            try:
                if (folder / read_seqinfo(ini).image_dir).is_dir():
                    return True
            except ValueError:  # refused when tracked; its img1/ or video still shows it
                pass
        return (folder / "img1").is_dir() or bool(image_files(folder)) or bool(_videos(folder))
    except OSError:
        return False


def _below(
    folders: list[Path], names_in: Callable[[list[Path]], tuple[list[str], list[Path]]]
) -> list[tuple[Path, list[str]]]:
    """The folders below `folders` (themselves included) that hold what `names_in` names.

    Breadth first, :data:`DEEPER_LEVELS` levels down at most and :data:`DEEPER_FOLDERS`
    folders in all (a hint, not a scan), each branch stopping at the first folder that holds
    something. ``names_in(entries)`` gets a folder's visible entries (hidden ones and broken
    links passed over, in listing order) and returns the names it holds and the folders to
    look into when it holds none. A folder that cannot be listed is passed over.
    """
    found: list[tuple[Path, list[str]]] = []
    queue = deque((f, 1) for f in folders)
    listed = 0
    while queue and listed < DEEPER_FOLDERS:
        folder, level = queue.popleft()
        listed += 1
        try:
            entries = sorted(folder.iterdir(), key=_listing_key)
            names, below = names_in(
                [e for e in entries if not e.name.startswith(".") and not _broken_link(e)]
            )
        except OSError:
            continue
        if names:
            found.append((folder, names))
        elif level < DEEPER_LEVELS:
            queue.extend((f, level + 1) for f in below)
    return found


def _sequences_in(entries: list[Path]) -> tuple[list[str], list[Path]]:
    """The sequences among a folder's `entries` (videos, folders with frames), and the others.

    The other folders, for :func:`_below` to look into: symbolic links to folders are not
    followed (a loop).
    """
    names: list[str] = []
    below: list[Path] = []
    for entry in entries:
        if entry.is_file():
            if entry.suffix.lower() in VIDEO_SUFFIXES and not _batch_output(entry):
                names.append(entry.name)
        elif entry.is_dir():
            if _has_frames(entry):
                names.append(entry.name)
            elif not entry.is_symlink():
                below.append(entry)
    return names, below


def _frameless_in(entries: list[Path]) -> tuple[list[str], list[Path]]:
    """The sequence folders without frames among a folder's `entries`, and its other folders.

    Without frames: a ``seqinfo.ini``, detections or ground truth, and no image folder or video
    (``../shared/data/mot15-gt/*``): annotations alone, which no batch can track.
    """
    names: list[str] = []
    below: list[Path] = []
    for entry in entries:
        if not entry.is_dir() or entry.is_symlink():
            continue
        if _has_frames(entry):
            continue  # a sequence (or a folder of them): named by the other hint, if deeper
        if (entry / "seqinfo.ini").is_file() or any(_annotations(entry)):
            names.append(entry.name)
        else:
            below.append(entry)
    return names, below


def _frameless(found: list[tuple[Path, list[str]]]) -> str:
    """``DIR/mot15-gt, which holds 3 sequence folders without frames (A, B, C)``, joined."""

    def one(folder: Path, names: list[str]) -> str:
        shown = ", ".join(names[:3]) + (", ..." if len(names) > 3 else "")
        held = counted(len(names), "sequence folder")
        return f"{folder}, which holds {held} without frames ({shown})"

    return "; ".join(one(f, n) for f, n in found[:3]) + ("; ..." if len(found) > 3 else "")


#: Why the folders of :func:`_frameless` are passed over.
_NO_FRAMES = (
    "annotations alone (seqinfo.ini, det.txt, gt.txt; no image folder, no video), nothing a "
    "batch can track"
)


def _tracks_in(entries: list[Path]) -> tuple[list[str], list[Path]]:
    """The ``.txt`` files among a folder's `entries`, and its folders (not links to them)."""
    names = [e.name for e in entries if e.suffix.lower() == ".txt" and e.is_file()]
    return names, [e for e in entries if e.is_dir() and not e.is_symlink()]


def _held(deeper: list[tuple[Path, list[str]]]) -> str:
    """``DIR/train holds 2 sequences (SEQ1, SEQ2)`` for each of `deeper`, joined."""

    def one(folder: Path, names: list[str]) -> str:
        shown = ", ".join(names[:3]) + (", ..." if len(names) > 3 else "")
        return f"{folder} holds {len(names)} sequence{'s' * (len(names) > 1)} ({shown})"

    return "; ".join(one(f, n) for f, n in deeper[:3]) + ("; ..." if len(deeper) > 3 else "")


def _pass(deeper: list[tuple[Path, list[str]]]) -> str:
    """``pass DIR/train`` (or several) for the folders of `deeper`."""
    return "pass " + " ".join(str(f) for f, _ in deeper[:3]) + (" ..." if len(deeper) > 3 else "")


def find_sequences(inputs: Inputs) -> list[SequenceInput]:
    """The sequences named by `inputs`, in order (a folder of sequences in natural order).

    A video that a batch rendered (``NAME.mp4`` listed by the sidecar ``NAME.json`` beside it)
    is passed over when a folder is looked into, so that ``--out`` may be the input folder;
    given by its own path, it is an input.

    Parameters
    ----------
    inputs : path or sequence of paths
        Video files, image folders, MOTChallenge sequence folders, or folders of any of these.

    Raises
    ------
    FileNotFoundError
        An input does not exist (a broken symbolic link is named as one). A broken link met in
        a scanned folder is not refused: it is a sequence whose task fails, named so; so is a
        link loop met there.
    ValueError
        No sequence is found (the error names deeper folders that hold some), or two have the
        same name (their outputs would collide), or one input is given twice (the same path
        once links are resolved, or hard links of one file), or an input is a symbolic link
        loop (``a`` -> ``b`` -> ``a``).

    Warns
    -----
    UserWarning
        A folder of sequences has sequences deeper than one level (``DIR/train/SEQ`` for
        ``DIR``): they are not tracked; the warning names the folders that hold them.
    """
    paths = _absolute(inputs, _LIVE)
    _refuse_given_twice(paths)
    found: list[SequenceInput] = []
    for path in paths:
        _check_exists(path)
        _refuse_special(path, " (pftrack track reads a pipe live, alone)")
        _refuse_tracks_file(path)
        seq = _readable_as_sequence(path)
        if seq is not None:
            found.append(seq)
            continue
        entries = sorted(path.iterdir(), key=_listing_key)
        before = len(found)
        passed: list[Path] = []  # folders of sequences in `path`: not looked into
        for entry in entries:
            if entry.name.startswith("."):
                continue
            if _broken_link(entry):  # its task fails, named so; the others run
                if entry.suffix.lower() in VIDEO_SUFFIXES or not entry.suffix:
                    name = entry.stem if entry.suffix else entry.name
                    found.append(SequenceInput(name, entry))
                continue  # notes.txt -> nowhere: passed over, as a file of that kind would be
            if entry.is_file() and (
                entry.suffix.lower() not in VIDEO_SUFFIXES or _batch_output(entry)
            ):
                continue
            kind = _special(entry)
            if kind is not None:  # was: "Not a directory: PATH", the whole batch stopped
                if entry.suffix.lower() in VIDEO_SUFFIXES:
                    warn(
                        f"{entry} is {kind}, not a video file: passed over (pftrack track "
                        "reads a pipe live, alone)",
                        UserWarning,
                        stacklevel=2,
                    )
                continue
            child = _readable_as_sequence(entry)
            if child is not None:
                found.append(child)
            elif entry.is_dir():  # a link to one too (train -> /mnt/train); not deeper ones
                passed.append(entry)
        given = {os.path.realpath(p) for p in paths}  # DIR and DIR/train both given: said of none
        deeper = [d for d in _below(passed, _sequences_in) if os.path.realpath(d[0]) not in given]
        # annotations without frames below (../shared/data/mot15-gt/*): was passed over silently
        frameless = [
            d for d in _below(passed, _frameless_in) if os.path.realpath(d[0]) not in given
        ]
        if len(found) == before:  # was: the same words with deeper sequences, not naming them
            where = (
                f"; deeper, {_held(deeper)}: {_pass(deeper)} instead (a folder is looked into "
                "one level deep)"
                if deeper
                else ""
            )
            if frameless:
                where += f"; {_frameless(frameless)}: {_NO_FRAMES}"
            raise ValueError(
                f"no sequence in folder {path}: expected videos ({', '.join(VIDEO_SUFFIXES)}), "
                f"image folders or MOTChallenge sequence folders in it{where}"
            )
        if frameless:
            warn(
                f"folder {path}: passed over {_frameless(frameless)}: {_NO_FRAMES}",
                UserWarning,
                stacklevel=2,
            )
        if deeper:  # was: passed over silently
            n = len(found) - before
            warn(
                f"folder {path}: {n} sequence{'s' * (n > 1)} tracked from it, not those deeper "
                f"(a folder is looked into one level deep): {_held(deeper)}; {_pass(deeper)} "
                "too to track them",
                UserWarning,
                stacklevel=2,
            )
    _check_names([s.name for s in found], [s.frames for s in found])
    return found


def find_track_files(inputs: Inputs) -> list[Path]:
    """MOTChallenge text files named by `inputs`: files, or the ``*.txt`` files of folders.

    Raises
    ------
    FileNotFoundError
        An input does not exist (a broken symbolic link is named as one; one met in a folder is
        listed: its task fails, named so).
    ValueError
        A folder holds no ``.txt`` file, or two files have the same name, or one is given
        twice (under any names: hard links too), or an input is a symbolic link loop.
    """
    paths = _absolute(inputs)
    _refuse_given_twice(paths)
    found: list[Path] = []
    for path in paths:
        _check_exists(path)
        _refuse_special(path)
        if path.is_file():
            found.append(path)
            continue
        files = sorted(
            (
                p
                for p in path.iterdir()
                # broken: its task fails; .TXT too (was: passed over without a word, a user trial)
                if (p.is_file() or _broken_link(p)) and p.suffix.lower() == ".txt"
            ),
            key=_listing_key,
        )
        files = [p for p in files if not p.name.startswith(".")]
        scores = [p for p in files if _trackeval_summary(p)]
        for p in scores:  # beside the tracker's data/: was read as tracks, its task failed
            warn(f"{p} is TrackEval's summary of scores, not tracks: passed over", stacklevel=2)
        files = [p for p in files if p not in scores]
        if not files:
            what = f"no .txt file in folder {path}" if not scores else (
                f"no tracks file in folder {path} (only TrackEval's summaries of scores)"
            )  # fmt: skip
            raise ValueError(f"{what}{_txt_below(path)}")
        found.extend(files)
    _check_names([p.stem for p in found], found)
    return found


#: The first field of the header line of a summary TrackEval writes, ``CLS_summary.txt``: its
#: fields come in a set order, HOTA's, CLEAR's, Identity's and Count's first (its
#: ``write_summary_results``), so the first is one of these when any of them was evaluated.
_TRACKEVAL_FIELDS = ("HOTA", "MOTA", "IDF1", "Dets")


def _trackeval_summary(path: Path) -> bool:
    """Whether `path` is a summary of scores that TrackEval wrote, not tracks.

    ``CLS_summary.txt`` (``pedestrian_summary.txt``, beside ``data/`` in ``trackers/NAME/``)
    whose first line is TrackEval's header of metric names, ``HOTA DetA AssA ...``.
    """
    if not path.name.endswith("_summary.txt"):
        return False
    try:
        with path.open(encoding="utf-8", errors="replace") as fh:
            first = fh.readline(4096).split()
    except OSError:  # its task names it
        return False
    return bool(first) and first[0] in _TRACKEVAL_FIELDS


def _txt_below(folder: Path) -> str:
    """``; DIR/data holds 3 (a.txt, b.txt, c.txt): pass it instead`` for tracks files deeper.

    A tracker's results often sit a level or two down (TrackEval's
    ``trackers/NAME/data/SEQ.txt``): was "no .txt file in folder DIR" alone. The folders below
    `folder` (:func:`_below`) that hold ``.txt`` files; empty when there is none.
    """
    try:
        subfolders = [e for e in sorted(folder.iterdir(), key=_listing_key) if e.is_dir()]
    except OSError:
        return ""
    found = _below([e for e in subfolders if not e.name.startswith(".") and not e.is_symlink()],
                   _tracks_in)  # fmt: skip
    if not found:
        return ""
    held = "; ".join(
        f"{f} holds {len(n)} ({', '.join(n[:3])}{', ...' if len(n) > 3 else ''})"
        for f, n in found[:3]
    )
    more = f" and {len(found) - 3} more folders" if len(found) > 3 else ""
    return f"; {held}{more}: pass {'it' if len(found) == 1 else 'them'} instead"


def cannot_read(path: Path) -> str | None:
    """Why `path` cannot be looked into, if it is a folder that cannot be, else None.

    ``cannot read the folder PATH (Permission denied)``: such a folder (mode 700 of another
    user, ``lost+found``) can be seen but not listed, and what was looked for in it
    (``seqinfo.ini``, ``img1/``) raised ``PermissionError``, naming a file that need not exist.
    """
    try:
        if path.is_dir():
            os.scandir(path).close()
    except OSError as exc:
        return f"cannot read the folder {path} ({exc.strerror})"
    return None


def _special(path: Path) -> str | None:
    """``a named pipe``, ``a character device``, ... if `path` is neither a file nor a folder."""
    try:
        mode = path.stat().st_mode
    except OSError:  # missing or unreadable: said elsewhere
        return None
    kinds = (
        (stat.S_ISFIFO, "a named pipe"),
        (stat.S_ISCHR, "a character device"),
        (stat.S_ISBLK, "a block device"),
        (stat.S_ISSOCK, "a socket"),
    )
    return next((kind for test, kind in kinds if test(mode)), None)


def _refuse_special(path: Path, hint: str = "") -> None:
    """Refuse an input that is a pipe, a device or a socket, naming it as one.

    A batch reads each input from a file or folder, as many times as it takes (the client's
    fingerprint and frame count, then the task). Was: ``Not a directory: PATH``.
    """
    kind = _special(path)
    if kind is not None:
        raise ValueError(
            f"input {path} is {kind}, not a file or a folder: a batch reads files{hint}"
        )


def _broken_link(path: Path) -> bool:
    """Whether `path` is a symbolic link to nothing (a target moved or deleted)."""
    return path.is_symlink() and not path.exists()


def _check_exists(path: Path) -> None:
    """Refuse an input that does not exist, naming a broken symbolic link or a loop as one."""
    refuse_loop(path, "input")  # was: "is a broken symbolic link (to b)", b there, a link too
    if _broken_link(path):
        raise FileNotFoundError(
            f"input not found: {path} is a broken symbolic link (to {os.readlink(path)})"
        )
    if not path.exists():
        raise FileNotFoundError(f"input not found: {path}")


def _listing_key(path: Path) -> tuple[object, ...]:
    """The order of a folder's entries: natural order of the name before its extension.

    So ``tud.mp4``, ``tud2.mp4``, ``tud10.mp4``, as ``ls -v`` lists them (was: ``tud2.mp4``
    first, the natural key of the whole name putting the text ``tud`` before ``tud.mp4``);
    digit runs compare as numbers (:func:`~pftrack.io.video.natural_key`, as for an image
    folder's frames: ``9.jpg`` before ``10.jpg``).
    """
    stem, dot, suffix = path.name.rpartition(".")
    if not dot or not stem:  # no extension (a folder), or a name like ".x"
        stem, suffix = path.name, ""
    return natural_key(stem), suffix.lower(), path.name


def _check_names(names: list[str], sources: list[Path]) -> None:
    seen: dict[str, Path] = {}
    for name, source in zip(names, sources, strict=True):
        if name in RESERVED_NAMES:
            raise ValueError(f"{source}: the name {name!r} is reserved for the batch's own file")
        if name in seen and _same_file(seen[name], source):  # was: "both named" A and A
            raise _given_twice(seen[name], source)
        if name in seen:
            named = _named_by(name, source)
            link = f"{named} NEWNAME{named.suffix if named.is_file() else ''}"
            raise ValueError(
                f"two inputs are both named {name!r} ({seen[name]} and {source}): their outputs "
                "would collide; run them in separate batches, or give them distinct names "
                f"(symbolic links: ln -s {link})"
            )
        seen[name] = source


def _refuse_given_twice(paths: list[Path]) -> None:
    """Refuse a file or folder given twice under any names: hard links too (one inode).

    Was: ``recover a.txt b.txt`` with ``b.txt`` a hard link of ``a.txt`` (or a symbolic link
    of another name) ran it twice. Only the inputs as given: two sequences found in a folder
    may share their frames (MOT17's three detectors' copies of one ``img1/``, linked).
    """
    seen: dict[tuple[int, int], Path] = {}
    for path in paths:
        try:
            st = path.stat()
        except OSError:  # missing, or a link loop: refused as such when it is looked at
            continue
        key = (st.st_dev, st.st_ino)
        if key in seen:
            raise _given_twice(seen[key], path)
        seen[key] = path


def _given_twice(first: Path, second: Path) -> ValueError:
    """The error of one input given twice, as `first` and then as `second`."""
    given = f"{second} is" if first == second else f"{first} and {second} are"
    same = os.path.realpath(first) == os.path.realpath(second)
    how = "the same path once links are resolved" if same else "one file, hard linked"
    return ValueError(f"{given} the same input, given twice ({how}): give each input once")


def _named_by(name: str, source: Path) -> Path:
    """The file or folder that gives a sequence read from `source` its `name`.

    A video's own path; for a sequence folder's ``img1/`` or its one video, the sequence
    folder (a link to its ``img1/`` alone would leave its detections, ground truth and
    ``seqinfo.ini`` behind; a user trial).
    """
    for path in (source, *source.parents):
        if (path.stem if path.is_file() else path.name) == name:
            return path
    return source


def _same_file(a: Path, b: Path) -> bool:
    """Whether `a` and `b` name the same file or folder (links and ``..`` resolved)."""
    try:
        return a == b or os.path.realpath(a) == os.path.realpath(b) or os.path.samefile(a, b)
    except OSError:
        return False
