"""Input checks shared by the public entry points."""

from __future__ import annotations

import numbers
import os
import sys
from collections.abc import Iterable, Iterator
from typing import Any, TypeVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pftrack._text import counted
from pftrack._typing import F64, RngLike

_T = TypeVar("_T")

__all__ = [
    "BOX_VALUES",
    "MAX_CLASS",
    "MAX_COORD",
    "MAX_FRAME",
    "MAX_ID",
    "MOT_DEFAULTS",
    "bad_id_message",
    "bgr_array",
    "bgr_frame",
    "bool_array",
    "brief",
    "byte_order_hint",
    "colour_hint",
    "depth_hint",
    "first_bad_box",
    "first_at",
    "check_classes",
    "first_bad_class",
    "first_bad_id",
    "flag",
    "generator",
    "instance",
    "integer",
    "listed",
    "materialised",
    "mot_rows",
    "number",
    "option",
    "path_arg",
    "path_refused",
    "real_array",
    "seed",
    "shown",
    "text",
]

#: Box positions and sizes beyond this many pixels are refused: no image is a billion pixels
#: wide, and splines and Kalman filters square and multiply them (1e308 overflows).
MAX_COORD = 1e9
#: Boxes whose right and bottom edges all stay within this many units are taken for
#: normalised coordinates (1 is the frame's width and height; a tracker's boxes may reach a
#: little past it): no file in pixels holds people that fit in 2 x 2 px.
NORMALISED_REACH = 2.0
#: The largest frame number anywhere (a 32-bit int: 2.3 years of video at 30 frames/s).
MAX_FRAME = 2**31 - 1
#: Largest absolute track id accepted (as frames: ids are cast to 32- or 64-bit integers).
MAX_ID = MAX_FRAME
#: Largest class id a tracker takes (a 32-bit signed integer: -2**31 to 2**31 - 1).
MAX_CLASS = 2**31 - 1


def frames_from_1(frame: float, mend: str = "rows[:, 0] += 1") -> str:
    """What a refusal of `frame` as a frame number adds: frames count from 1.

    MOTChallenge frames (and TrackEval's, and pftrack's) are 1-based; a frame 0 is most
    often a file or array numbered from 0 (Python's ``enumerate``, a video decoder's index),
    which the words say how to mend: add 1 to every frame (`mend`, how).
    """
    if frame == 0:
        return f"(MOTChallenge frames count from 1: numbered from 0? add 1 to every frame, {mend})"
    return "(frames count from 1)"


def first_bad_id(ids: ArrayLike) -> int | None:
    """Index of the first id that is not an integer with ``|id| <= MAX_ID``, or None.

    One test for every reader of track ids (``recover``, ``smooth``, ``eval``): an id such as
    1.5 is refused, never truncated to 1.
    """
    a = np.asarray(ids, dtype=np.float64)
    with np.errstate(invalid="ignore"):
        bad = ~(np.abs(a) <= MAX_ID) | (a != np.floor(a))
    return int(np.flatnonzero(bad)[0]) if bad.any() else None


def first_bad_class(classes: F64) -> int | None:
    """Index of the first of `classes` that is not an integer in ``[-2**31, MAX_CLASS]``, or None.

    One test for every tracker's class ids (``Tracker.update``'s column, ``MultiObjectTracker``'s
    `classes`, supervision's ``class_id``): 1.5 is refused, never truncated to 1; NaN too.
    """
    ok = (classes == np.round(classes)) & (classes >= -MAX_CLASS - 1) & (classes <= MAX_CLASS)
    return int(np.flatnonzero(~ok)[0]) if not ok.all() else None


def check_classes(classes: F64, what: str) -> None:
    """Refuse `classes` (1-D) holding a value :func:`first_bad_class` finds, as ``what[k]``.

    Raises
    ------
    ValueError
        ``f"{what}[k] is 1.5, expected an integer in [-2147483648, 2147483647]"``.
    """
    k = first_bad_class(classes)
    if k is not None:
        raise ValueError(
            f"{what}[{k}] is {classes[k]:.17g}, expected an integer in "
            f"[{-MAX_CLASS - 1}, {MAX_CLASS}]"
        )


def exactly(value: float) -> str:
    """`value` as a message shows a refused frame or id: an integer's digits, else ``repr``.

    Not ``:g``, whose 6 digits turned frame 1 + 1e-12 into "frame 1, not an integer" and
    2147483648 into 2.14748e+09.
    """
    v = float(value)
    return str(int(v)) if v.is_integer() and abs(v) < 1e16 else repr(v)


def bad_id_message(value: float) -> str:
    """What is wrong with track id `value` (one :func:`first_bad_id` found), shown exactly."""
    return f"track id {exactly(value)} is not an integer with |id| <= {MAX_ID}"


def rectangular(values: ArrayLike, what: str) -> NDArray[Any]:
    """``np.asarray(values)``; nested sequences of different lengths a ValueError naming `what`.

    NumPy's own words name no argument ("setting an array element with a sequence. The
    requested array has an inhomogeneous shape ..."): the resamplers' weights and
    ``hsv_bins``' mask gave them (an integrator's trial).
    """
    try:
        return np.asarray(values)
    except ValueError:  # NumPy: "setting an array element with a sequence ... inhomogeneous"
        raise ValueError(
            f"{what} must be a rectangular array of numbers, got rows of different lengths"
        ) from None


def real_array(values: ArrayLike, what: str, *, booleans: bool = True) -> F64:
    """`values` as a float64 array, refusing what is not real numbers.

    NumPy would cast complex numbers to their real part with only a warning, and fail on text
    with a message that does not say which argument was wrong.

    Parameters
    ----------
    values : array_like
        Booleans, integers or floats.
    what : str
        How the error names the argument (``"detections"``, ...).
    booleans : bool
        Whether booleans are taken (as 0 and 1); False for values that are never flags (MOT
        rows, track segments).

    Raises
    ------
    TypeError
        Complex numbers, text, or objects that are not numbers; booleans without `booleans`;
        a ``numpy.ma.MaskedArray`` with a masked value (:func:`refuse_masked`).
    ValueError
        Nested sequences of different lengths (ragged rows).
    """
    refuse_masked(values, what)
    raw = rectangular(values, what)
    if raw.dtype.kind not in ("biuf" if booleans else "iuf"):
        raise TypeError(f"{what} must hold real numbers, got dtype {raw.dtype}")
    return raw.astype(np.float64, copy=False)


def refuse_masked(
    values: object,
    what: str,
    mend: str = "an array with the values the masked ones stand for (.filled(value)), or "
    "without them",
) -> None:
    """TypeError when `values` (argument `what`) is a ``numpy.ma.MaskedArray`` with a masked entry.

    ``np.asarray`` drops the mask and keeps the values under it, so a masked entry was used
    as any other: a masked row of a segment recovered from, a masked box or histogram bin
    counted, a masked pixel binned. What a masked entry stands for (a value, or nothing) is
    the caller's to say, as `mend` tells them; a masked array with nothing masked is its
    values. The first check of :func:`real_array`, :func:`bool_array` and :func:`bgr_array`.
    """
    # a MaskedArray exists only once numpy.ma is imported: ``np.ma`` would import it (10-25
    # ms of every command's start-up, for a check that a tracking run makes at import time)
    ma = sys.modules.get("numpy.ma")
    # and while another thread imports it, the module is there without its names yet (no
    # MaskedArray made by a caller can exist then): was an AttributeError on `track
    # --render`'s drawing thread after a Ctrl-C, once runs stopped importing numpy.ma early
    masked_array = getattr(ma, "MaskedArray", None)
    if (
        ma is not None
        and masked_array is not None
        and isinstance(values, masked_array)
        and ma.is_masked(values)
    ):
        n = int(np.count_nonzero(ma.getmaskarray(values)))
        raise TypeError(
            f"{what} is a numpy.ma.MaskedArray with {counted(n, 'masked value')}, whose mask "
            f"NumPy would drop (the masked values used as they are); pass {mend}"
        )


def refuse_masked_weights(weights: object, fn: str) -> None:
    """:func:`refuse_masked` for the `weights` of `fn`, whose mend is weight 0.

    Masked particles were resampled and weighed as any other (filterpy fails with an
    IndexError); ``weights.filled(0)`` gives them weight 0. Shared by the resamplers and
    ``estimate``.
    """
    refuse_masked(weights, f"{fn}: weights", "weights.filled(0) to give masked particles weight 0")


#: Columns 7-10 of a MOTChallenge row (conf, x, y, z) where rows have fewer: the values
#: :func:`pftrack.io.mot.read_mot` gives a line of 6 to 9 fields.
MOT_DEFAULTS = (1.0, -1.0, -1.0, -1.0)


def path_arg(value: object, what: str) -> str | os.PathLike[str]:
    """`value` as a path: a str or an os.PathLike as it is, bytes decoded (``os.fsdecode``).

    pathlib's and open's refusals (``expected str, bytes or os.PathLike object, not
    NoneType``) name neither the function nor the argument, and arguments given in the wrong
    order (``write_mot(rows, path)``, ``VideoWriter(fps, path)``) look like this too.

    Raises
    ------
    TypeError
        Anything else (None, a number, an array, a list): ``{what} must be a str or
        os.PathLike, got NoneType``.
    """
    if isinstance(value, bytes):
        return os.fsdecode(value)
    if isinstance(value, (str, os.PathLike)):
        return value
    raise TypeError(f"{what} must be a str or os.PathLike, got {type(value).__name__}")


def path_refused(value: object, what: str, reader: str) -> None:
    """TypeError when `value` is a path (str, bytes, os.PathLike) where an array was expected.

    NumPy takes a path for a 0-d array of text, refused by its dtype (``got dtype <U36``),
    which does not say that the file must be read first:
    ``{what} is a path ('gt.txt'); read it with {reader}``.
    """
    if isinstance(value, (str, bytes, os.PathLike)):
        raise TypeError(f"{what} is a path ({os.fsdecode(value)!r}); read it with {reader}")


def materialised(rows: ArrayLike) -> ArrayLike:
    """`rows` as a list when it is an iterator (a generator, ``map``), else `rows` itself.

    NumPy takes an iterator for a 0-d object array; its rows (a generator of generators too)
    are read once, into lists. Arrays and sequences are returned as they are.
    """
    if not isinstance(rows, Iterator):
        return rows
    return [list(r) if isinstance(r, Iterator) else r for r in rows]


def mot_rows(rows: ArrayLike, what: str, name: str = "rows") -> F64:
    """MOTChallenge rows (M, 6..10) as an (M, 10) float64 array, the missing columns added.

    The first check of every function that takes rows (``fill_gaps``, ``smooth_tracks``,
    ``link_tracklets``, ``write_mot``, ...), so that they take the same arrays with the same
    messages, and the arrays the commands take as files: 6 to 10 columns ``frame, id, left,
    top, width, height[, conf, x, y, z]``, the missing ones :data:`MOT_DEFAULTS` (conf 1,
    x, y, z -1), as :func:`pftrack.io.mot.read_mot` reads a shorter line. An array without
    values (``[]``, ``np.zeros((0,))``, ``np.zeros((0, 10))``) is no rows. Any iterable of
    rows is taken: an iterator (a generator, ``map(list, rows)``) is read once
    (:func:`materialised`). Only the layout is checked here; the callers check the values.
    `what` names the caller in messages, `name` its argument (``fill_gaps``' ``tracks``).

    Raises
    ------
    TypeError
        Not real numbers (text, complex numbers, booleans); a path (read it with
        :func:`pftrack.io.mot.read_mot` first).
    ValueError
        Ragged rows, or not of shape (M, 6..10):
        ``{what}: rows must have shape (M, 6..10) (6 to 10 columns: frame, id, left, top,
        width, height[, conf, x, y, z]), got (2, 3)``.
    """
    path_refused(rows, f"{what}: {name}", "pftrack.read_mot(path)")
    a = real_array(materialised(rows), f"{what}: {name}", booleans=False)
    if a.size == 0:
        return np.zeros((0, 10))
    if a.ndim != 2 or not 6 <= a.shape[1] <= 10:
        raise ValueError(
            f"{what}: {name} must have shape (M, 6..10) (6 to 10 columns: frame, id, left, top, "
            f"width, height[, conf, x, y, z]), got {a.shape}"
        )
    if a.shape[1] < 10:
        pad = np.tile(np.asarray(MOT_DEFAULTS[a.shape[1] - 6 :]), (len(a), 1))
        a = np.hstack([a, pad])
    return a


#: Names of the values of a box ``left, top, width, height`` (columns 3-6 of a MOTChallenge row).
BOX_VALUES = ("left", "top", "width", "height")


def first_bad_box(boxes: ArrayLike, *, edges: bool = True) -> tuple[int, int, str] | None:
    """The first value of `boxes` that a MOTChallenge file may not hold, or None.

    The rule of :func:`pftrack.io.mot.read_mot`, which every entry point that takes
    MOTChallenge rows applies too: a width or height is never negative (0 is allowed), and no
    value, nor a box's right or bottom edge, lies beyond ±:data:`MAX_COORD` px. Rows are taken
    in order; within a row, a negative size is named before a far value, and that before a far
    edge. NaN breaks neither rule (callers refuse it first).

    Parameters
    ----------
    boxes : (M, 4) array_like of float
        ``left, top, width, height`` per row.
    edges : bool
        Whether the far edges are checked too (False for boxes given by their centres).

    Returns
    -------
    (row, column, problem) or None
        The first bad value's row, its column in `boxes` (0-3, :data:`BOX_VALUES`) and what is
        wrong: ``"negative box width or height"``, ``"a box value is beyond ±1e+09 px"`` or
        ``"a box's right or bottom edge is beyond ±1e+09 px (left + width = 1000000001)"``.
    """
    b = np.asarray(boxes, dtype=np.float64).reshape(-1, 4)
    negative = b[:, 2:] < 0
    far = np.abs(b) > MAX_COORD
    # the far edges too (was: left 1e9, width 20 read, then refused inside the recovery with
    # a kernel's message naming no file or line; a user trial)
    with np.errstate(over="ignore"):  # 1e308 + 1e308: far already, named as such
        edge = np.abs(b[:, :2] + b[:, 2:]) > MAX_COORD if edges else np.zeros((len(b), 2), bool)
    # whole-array tests first: the rows' any(axis=1) took 2.4 of the 4 ms for 62 000 good boxes
    if not (negative.any() or far.any() or edge.any()):
        return None
    bad = negative.any(axis=1) | far.any(axis=1) | edge.any(axis=1)
    r = int(np.argmax(bad))
    if negative[r].any():
        return r, 2 + int(np.argmax(negative[r])), "negative box width or height"
    if far[r].any():
        return r, int(np.argmax(far[r])), f"a box value is beyond ±{MAX_COORD:g} px"
    c = int(np.argmax(edge[r]))  # 0: the right edge, 1: the bottom one
    # the sum named: the size the caller names may be small, its left or top the far one
    total = f"{BOX_VALUES[c]} + {BOX_VALUES[2 + c]} = {b[r, c] + b[r, 2 + c]:.12g}"
    return r, 2 + c, f"a box's right or bottom edge is beyond ±{MAX_COORD:g} px ({total})"


def frames_iterator(frames: Iterable[_T], who: str) -> Iterator[_T]:
    """An iterator over `frames`, given to `who` (``prime``) as an iterable of frames.

    One frame alone (an (H, W) or (H, W, 3) array; ``prime([frame])`` takes it) and what is not
    an iterable (None, a number) are a TypeError naming `who` (were: one frame's rows taken
    for frames, and "'NoneType' object is not iterable").
    """
    if isinstance(frames, np.ndarray) and (
        frames.ndim == 2 or (frames.ndim == 3 and frames.shape[-1] == 3)
    ):
        raise TypeError(
            f"{who} takes an iterable of frames (a list, or a (K, H, W, 3) array), got one "
            f"{frames.shape} frame: prime([frame])"
        )
    try:
        return iter(frames)
    except TypeError:
        raise TypeError(
            f"{who} takes an iterable of frames (a list, a generator or a (K, H, W, 3) array), "
            f"got {type(frames).__name__}"
        ) from None


def bgr_array(frame: ArrayLike, what: str = "frame") -> NDArray[np.uint8]:
    """`frame` itself, checked to be a NumPy (H, W, 3) uint8 array (never converted, nor copied).

    Raises
    ------
    TypeError
        Not an array of uint8 (float frames; ``None``); not a NumPy array at all (a list, a
        PIL image, named by their type, not by the dtype NumPy gives them: a list of ints is
        int64, a PIL image uint8 but RGB); a ``numpy.ma.MaskedArray`` with a masked pixel
        (:func:`refuse_masked`: the core would read the pixels under the mask).
    ValueError
        Not of shape (H, W, 3): a grey (2-D or one-channel) or a BGRA frame's message names
        the ``cv2.cvtColor`` conversion that makes it BGR.
    """
    if not isinstance(frame, np.ndarray):
        # a list (``frame.tolist()``) is int64 to NumPy, and a PIL image uint8 but RGB: both
        # refused alike (a PIL image was taken, its red read as blue); ragged rows too (were
        # NumPy's "setting an array element with a sequence", naming nothing)
        try:
            loose = np.asarray(frame).dtype == object
        except ValueError:
            loose = True
        if loose:
            raise TypeError(
                f"{what} is {type(frame).__name__}, expected a (H, W, 3) uint8 BGR array"
            )
        pil = type(frame).__module__.split(".")[0] == "PIL"
        raise TypeError(
            f"{what} is {type(frame).__name__}, expected a NumPy uint8 array (H, W, 3) (BGR, "
            "as cv2 reads it)"
            + ("; a PIL image is RGB: np.asarray(img)[..., ::-1] gives BGR" if pil else "")
        )
    refuse_masked(frame, what, "a plain array (.filled(0) makes the masked pixels black)")
    f = frame
    if f.dtype != np.uint8:
        raise TypeError(
            f"{what} dtype is {f.dtype}, expected uint8 (BGR, as cv2 reads it){depth_hint(f)}"
        )
    if f.ndim != 3 or f.shape[2] != 3:
        raise ValueError(
            f"{what} must have shape (H, W, 3) (BGR), got {f.shape}{colour_hint(f.shape)}"
        )
    return f


def depth_hint(frame: NDArray[np.generic]) -> str:
    """The end of a message refusing `frame`'s dtype: the conversion to uint8, if one fits.

    A 16-bit frame (``cv2.imread(path, cv2.IMREAD_UNCHANGED)`` of a 16-bit PNG or TIFF) keeps
    its top 8 bits with ``>> 8``; a cast alone (``astype(np.uint8)``) would keep the low ones.
    """
    if frame.dtype == np.uint16:
        return "; a 16-bit frame? (frame >> 8).astype(np.uint8) keeps its top 8 bits"
    return ""


def byte_order_hint(a: NDArray[np.generic], name: str) -> str:
    """The end of a message refusing `a`, updated in place, for its byte order, if swapped.

    A kernel that writes into its argument takes only this machine's byte order (``>f8``, a
    big-endian array from a file or another machine, is not float64 here). The fix is a copy,
    so the caller must keep it: the result is written into that copy, not into `a`.
    """
    if a.dtype.isnative or a.dtype.byteorder == "|":
        return ""
    order = "big" if a.dtype.byteorder == ">" else "little"
    native = a.dtype.newbyteorder("=").name
    return (
        f": {order}-endian, not this machine's byte order; pass a copy in its order, {name} = "
        f"{name}.astype(np.{native}), and read the result from it (a copy made for the call "
        "alone would take the result and be lost)"
    )


def colour_hint(shape: tuple[int, ...]) -> str:
    """The end of a message refusing a frame of `shape`: the conversion to BGR, if one fits."""
    if len(shape) == 2 or (len(shape) == 3 and shape[2] == 1):
        return ": a grey frame? cv2.cvtColor(frame, cv2.COLOR_GRAY2BGR) makes it BGR"
    if len(shape) == 3 and shape[2] == 4:
        return ": a BGRA frame? cv2.cvtColor(frame, cv2.COLOR_BGRA2BGR) makes it BGR"
    return ""


def not_an_image(boxes: object, call: str, what: str, other: str) -> None:
    """TypeError when `boxes` is a uint8 (H, W, 3) array, a frame given for the boxes.

    `call` is the called signature, `what` the name of its boxes argument and `other` the call
    whose order the caller followed (``update(frame, dets)`` for ``update(dets, frame)``): the
    frame's own check would say the user's uint8 frame was the boxes' dtype.
    """
    if isinstance(boxes, np.ndarray) and boxes.ndim == 3 and boxes.dtype == np.uint8:
        raise TypeError(
            f"{call}: {what} is a {boxes.shape} uint8 array, an image; were the arguments "
            f"swapped? ({other})"
        )


def bgr_frame(frame: ArrayLike, what: str = "frame") -> NDArray[np.uint8]:
    """`frame` as a C-contiguous (H, W, 3) uint8 array with at least one pixel.

    A view that is not packed row by row (``frame[..., ::-1]``, a Fortran-ordered array, a
    crop of a larger image) is copied; a packed array is returned as it is (the same object).

    Raises
    ------
    TypeError
        Not an array of uint8 (float frames; ``None``).
    ValueError
        Not of shape (H, W, 3) (grey or BGRA frames: the message names the ``cv2.cvtColor``
        conversion), or a frame with no pixel (height or width 0).
    """
    f = bgr_array(frame, what)
    if f.shape[0] == 0 or f.shape[1] == 0:
        raise ValueError(f"{what} is {f.shape[1]}x{f.shape[0]} pixels, expected at least 1x1")
    return np.ascontiguousarray(f)


def brief(value: object) -> str:
    """`value`'s repr where it takes one line, else its type and shape: a message's one line.

    ``'abc'``, ``None``, ``(640, 480)``; an array or a table (a pandas DataFrame) whose repr
    takes several lines, its type and shape instead: ``ndarray of shape (2, 3)`` (was its
    whole repr, one line of the message per row); anything else of several lines, its type
    and repr joined into one line.
    """
    text = repr(value)
    if "\n" not in text:
        return text
    shape = getattr(value, "shape", None)
    if isinstance(shape, tuple):
        return f"{type(value).__name__} of shape {shape}"
    return f"{type(value).__name__} {' '.join(text.split())}"


def shown(value: object) -> str:
    """`value`'s type and repr on one line, as the refusals below name what they got.

    ``str 'abc'``, ``NoneType None``; an array or a table of several lines as :func:`brief`
    names it: ``ndarray of shape (2, 3)``.
    """
    text = repr(value)
    return f"{type(value).__name__} {text}" if "\n" not in text else brief(value)


def listed(values: Iterable[object]) -> str:
    """`values` as a message lists them: ``'a'``, ``'a' or 'b'``, ``'a', 'b' or 'c'``."""
    names = [repr(v) for v in values]
    return names[0] if len(names) == 1 else f"{', '.join(names[:-1])} or {names[-1]}"


def instance(value: object, what: str, cls: type[_T]) -> _T:
    """`value` itself when it is a `cls` (a sub-config: ``TrackerConfig.filter``), else TypeError.

    Was taken: a DataFrame or an array given for ``TrackerConfig(association=...)`` failed
    later, at a frame, on a missing attribute naming no setting.

    Raises
    ------
    TypeError
        ``{what} must be a FilterConfig, got DataFrame of shape (2, 3)``.
    """
    if not isinstance(value, cls):
        raise TypeError(f"{what} must be a {cls.__name__}, got {shown(value)}")
    return value


def text(value: object, what: str, *, none: bool = True) -> None:
    """TypeError when `value` is not a str (nor None, with `none`: no text), for a label.

    A label (``draw_tracks``' `label`, ``read_mot``'s `what`) goes into a picture or a message
    as it is: an array or a table given for it was written into the message as its whole
    repr, or failed in OpenCV naming no argument.
    """
    if not (isinstance(value, str) or (none and value is None)):
        raise TypeError(f"{what} must be a str, got {shown(value)}")


def option(value: object, what: str, accepted: Iterable[str | None]) -> None:
    """TypeError when `value` is not text (nor None, where None is `accepted`), for an option.

    The membership test that follows (``mode not in ("auto", "on")``) would ask a DataFrame
    or an array given for the option for its truth (pandas' and NumPy's "The truth value ...
    is ambiguous", naming no argument); which text is accepted stays the caller's to check.

    Raises
    ------
    TypeError
        ``{what} must be 'a', 'b' or 'c', got DataFrame of shape (2, 3)``.
    """
    accepted = tuple(accepted)
    if isinstance(value, str) or (value is None and None in accepted):
        return
    raise TypeError(f"{what} must be {listed(accepted)}, got {shown(value)}")


def flag(value: object, what: str) -> bool:
    """`value` as a bool, refusing anything but ``True`` and ``False`` (NumPy's too).

    A truthy string would otherwise turn an option on: ``refine="no"`` is ``True``.

    Raises
    ------
    TypeError
        Not a bool (a string, a number, None).
    """
    if not isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{what} must be True or False, got {shown(value)}")
    return bool(value)


def first_at(mask: NDArray[np.bool_]) -> tuple[tuple[int, ...], str]:
    """The index of `mask`'s first True entry (C order), and how a message names it.

    ``((1, 2), "[1, 2]")`` for a 2-D mask, ``((), "")`` for a 0-D one (a scalar argument).
    """
    k = tuple(int(i) for i in np.unravel_index(int(np.argmax(mask)), mask.shape))
    return k, f"[{', '.join(str(i) for i in k)}]" if k else ""


def bool_array(values: ArrayLike, what: str) -> NDArray[np.bool_]:
    """`values` as a bool array, refusing entries other than True and False (or 1 and 0).

    ``np.asarray(values, dtype=bool)`` would take NaN, 2 and any non-empty string (``"no"``,
    ``"False"``) as True.

    Raises
    ------
    TypeError
        Text, complex numbers or objects; a ``numpy.ma.MaskedArray`` with a masked value
        (:func:`refuse_masked`).
    ValueError
        A number other than 0 and 1 (NaN included); the message names the first.
    """
    refuse_masked(values, what)
    raw = np.asarray(values)
    if raw.dtype == np.bool_:
        return raw
    if raw.dtype.kind not in "iuf":
        raise TypeError(f"{what} must hold True or False (or 1 or 0), got dtype {raw.dtype}")
    bad = (raw != 0) & (raw != 1)
    if bad.any():
        k, at = first_at(bad)
        raise ValueError(f"{what}{at} is {raw[k]}, expected True or False (or 1 or 0)")
    return raw.astype(np.bool_)


def number(value: object, what: str, *, finite: bool = True) -> float:
    """`value` as a float, refusing what is not a real number (text, bools, None).

    ``float("0.5")`` would otherwise take a string, and ``float(True)`` a flag. With `finite`
    False, NaN and infinities pass (for a caller whose range check names them).

    Raises
    ------
    TypeError
        Not an int or float (NumPy's too).
    ValueError
        NaN or infinite (with `finite`); an int beyond a float's range (``10**400``: was
        NumPy's "ufunc 'isfinite' not supported", naming nothing).
    """
    if isinstance(value, (bool, np.bool_)) or not isinstance(
        value, (int, float, np.integer, np.floating)
    ):
        raise TypeError(f"{what} must be a number, got {shown(value)}")
    try:
        v = float(value)
    except OverflowError:
        raise ValueError(f"{what} is an int beyond a float's range (±1.8e+308)") from None
    if finite and not np.isfinite(v):
        raise ValueError(f"{what} is {value}, expected a finite number")
    return v


def real(value: object, what: str, *, finite: bool = True) -> float:
    """:func:`number`, also taking any other real number, as a float (a frame rate, seconds).

    A :class:`fractions.Fraction` is how PyAV gives a stream's rate (``average_rate``,
    ``Fraction(30000, 1001)``): where a frame rate or a time in seconds is taken it works as
    its float does (:func:`number` alone refuses it; a :class:`decimal.Decimal` is not a
    ``numbers.Real`` and stays refused, TypeError).

    Raises
    ------
    TypeError, ValueError
        As :func:`number`; ValueError for a real number beyond a float's range.
    """
    if isinstance(value, numbers.Real) and not isinstance(
        value, (bool, np.bool_, int, float, np.integer, np.floating)
    ):
        try:
            value = float(value)
        except OverflowError:
            raise ValueError(  # its digits unprinted, as number()'s int beyond the range
                f"{what} is a {type(value).__name__} beyond a float's range (±1.8e+308)"
            ) from None
    return number(value, what, finite=finite)


def integer(value: object, what: str, lo: int, hi: int) -> int:
    """`value` as an int in ``[lo, hi]`` (NumPy's too; not a bool, not a float such as 2.0).

    Raises
    ------
    TypeError
        Not an int (a string, a float, None, a bool): ``{what} must be an integer in [lo, hi],
        got str '5'``, as :func:`number` refuses what is not a number.
    ValueError
        An int outside ``[lo, hi]``: ``{what} is {value}, expected an integer in [lo, hi]``.
    """
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"{what} must be an integer in [{lo}, {hi}], got {shown(value)}")
    if not lo <= value <= hi:
        raise ValueError(f"{what} is {value!r}, expected an integer in [{lo}, {hi}]")
    return int(value)


def seed(value: object, what: str) -> int:
    """`value` as a seed: an int >= 0 (NumPy's, not a bool).

    NumPy's own refusals (``"unrecognized seed string"``, ``"expected non-negative integer"``)
    do not name the argument.

    Raises
    ------
    TypeError
        Not an int (a string, a float, None, a bool).
    ValueError
        Negative.
    """
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"{what} must be an int >= 0, got {shown(value)}")
    if value < 0:
        raise ValueError(f"{what} is {value}, expected an int >= 0")
    return int(value)


def generator(rng: RngLike | np.random.RandomState, what: str) -> np.random.Generator:
    """``numpy.random.default_rng(rng)``, whose errors name the argument.

    A Generator is returned as it is; a ``numpy.random.RandomState`` is wrapped (its bit
    generator, whose state the two then share: filterpy's draws). NumPy's refusals
    (``"SeedSequence expects int or sequence of ints for entropy not abc"``, ``"expected
    non-negative integer"``) do not say which argument was wrong.

    Raises
    ------
    TypeError
        Not a Generator, a RandomState, a seed or None (a string, a float, a bool: NumPy would
        take True as the seed 1, as other settings refuse a bool for a number).
    ValueError
        A negative seed.
    """
    if isinstance(rng, (bool, np.bool_)):
        raise TypeError(
            f"{what} must be a numpy.random.Generator (or RandomState), an int >= 0 or None, got "
            f"{shown(rng)}"
        )
    try:
        return np.random.default_rng(rng)
    except (TypeError, ValueError) as e:
        raise type(e)(
            f"{what} must be a numpy.random.Generator (or RandomState), an int >= 0 or None, got "
            f"{shown(rng)}"
        ) from None
