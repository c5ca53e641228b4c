"""Merged people split by their head tops and the learnt person size (`PaperConfig.crowd_split`).

People who touch or overlap make one blob. The blob pass cuts a blob only into people side by
side, at a valley of its column profile (`BlobConfig.split_valley`); people one behind the
other, or side by side with no valley between them, stay one box. This pass reads such a blob
from the top down with the scene's own person size (`PersonSizeModel`, fitted to isolated
blobs): the highest foreground row of the blob is a head top; the person whose head is there
has the height ``head_height(lines, top)`` and the width the model expects at its foot row; its
box is placed about the columns of the head and its pixels are taken out of the blob; the next
head top is read from what is left, until what is left is less than a part of a person. A blob
that yields two people or more is replaced by their boxes (whole people, the hidden parts
included, as a tracker's box is); one that yields a single person keeps its own box.

Nothing here is fitted to a sequence: the three shares below are read off a person's shape
(a head is about a third of the body's width; a person seen at all fills a quarter of its box
or more; a box a third taller or wider than the person at its foot row is more than one).
"""

from __future__ import annotations

import cv2
import numpy as np
from numpy.typing import NDArray

from pftrack._typing import F64
from pftrack.detection.size_model import PersonSizeModel, expected_size, head_height

MORE_THAN_ONE = 1.3
"""A box is read only when it is this much taller or wider than the person at its foot row."""

SHOULDER_DROP = 0.06
"""A head top's outline falls by this share of the person's height to its shoulders, each side."""

MAX_SLOPE = 0.5
"""Read heads only where the height line's slope ``b`` is at most this: the person whose head
is at row ``t`` is ``(a + b t) / (1 - b)`` tall, so a head top read one row off moves the height
by ``b / (1 - b)`` rows, at most one here (PETS09's fit: 0.25; a camera at head height, such as
TUD-Campus's with 1.33, makes a bump of a few rows a person of another size)."""

MIN_SHARE = 0.25
"""A placed person holds at least this share of its box in foreground pixels of the blob."""


def _check(mask: object, boxes: object, scores: object) -> tuple[NDArray[np.uint8], F64, F64]:
    if not isinstance(mask, np.ndarray) or mask.ndim != 2 or mask.dtype != np.uint8:
        raise TypeError(f"split_crowds: mask is {_brief(mask)}, expected an (H, W) uint8 array")
    b = np.asarray(boxes, dtype=np.float64) if isinstance(boxes, np.ndarray) else None
    if b is None or b.ndim != 2 or b.shape[1] != 4 or not np.isfinite(b).all():
        raise ValueError(
            f"split_crowds: boxes is {_brief(boxes)}, expected a finite (K, 4) float array"
        )
    s = np.asarray(scores, dtype=np.float64) if isinstance(scores, np.ndarray) else None
    if s is None or s.shape != (len(b),):
        raise ValueError(f"split_crowds: scores is {_brief(scores)}, expected ({len(b)},) floats")
    return mask, b, s


def _brief(v: object) -> str:
    if isinstance(v, np.ndarray):
        return f"an array of shape {v.shape} and dtype {v.dtype}"
    return f"a {type(v).__name__}"


def split_crowds(
    mask: NDArray[np.uint8], boxes: F64, scores: F64, size: PersonSizeModel
) -> tuple[F64, F64]:
    """Replace each box that holds several people by one box per person.

    Parameters
    ----------
    mask : (H, W) ndarray of uint8
        The cleaned foreground (non-zero: foreground).
    boxes : (K, 4) ndarray of float64
        ``left, top, w, h`` of the blobs.
    scores : (K,) ndarray of float64
        Their scores (foreground share of the box).
    size : PersonSizeModel
        The scene's person size; nothing changes before it is fitted.

    Returns
    -------
    boxes, scores
        The boxes (unchanged ones first in their order, then each split blob's people in place
        of it), and their scores (a new box's: its share of foreground pixels in `mask`).

    Raises
    ------
    TypeError, ValueError
        `mask` not a 2-D uint8 array; `boxes` not finite (K, 4); `scores` not (K,).
    """
    mask, boxes, scores = _check(mask, boxes, scores)
    lines = size.coefficients
    if lines is None or not len(boxes) or lines[0, 0] > MAX_SLOPE:
        return boxes, scores
    rows, cols = mask.shape
    foot = boxes[:, 1] + boxes[:, 3]
    exp = expected_size(lines, foot)
    tall = boxes[:, 3] > MORE_THAN_ONE * exp[:, 0]
    wide = boxes[:, 2] > MORE_THAN_ONE * exp[:, 1]
    out_b: list[F64] = []
    out_s: list[F64] = []
    for k in range(len(boxes)):
        people = _people(mask, boxes[k], lines, rows, cols) if tall[k] or wide[k] else None
        if people is None:
            out_b.append(boxes[k : k + 1])
            out_s.append(scores[k : k + 1])
            continue
        out_b.append(people)
        out_s.append(_fill(mask, people))
    return np.ascontiguousarray(np.vstack(out_b)), np.concatenate(out_s)


def _people(mask: NDArray[np.uint8], box: F64, lines: F64, rows: int, cols: int) -> F64 | None:
    """The people of one blob's box read from its head tops, or None for fewer than two.

    A head top is a column where the blob's upper outline (its first foreground row) is
    highest within half that person's width either side, and the outline lies at least
    `SHOULDER_DROP` of the person's height lower somewhere in the outer half of each side
    (the shoulders; the box's edge or an empty column counts as lower). One wide person has
    one such peak however wide; two people side by side, or one whose head shows above or
    beside a nearer one, have two. The person of each head top has the height of the person
    whose head is at that row and the expected width at its foot; heads within half a width
    of a higher head's column are that person's. A nearer person whose head lies inside the
    blob (under a farther one's body) is not read: one tall person, whose size the scene's
    model may not know, has the same silhouette.
    """
    x0, y0 = int(box[0]), int(box[1])
    x1, y1 = x0 + int(box[2]), y0 + int(box[3])
    m = _own_pixels(mask[y0:y1, x0:x1])
    bh, bw = m.shape
    if bh < 2 or bw < 2:
        return None
    has = m.any(axis=0)
    top = np.where(has, np.argmax(m, axis=0), bh).astype(np.int64)
    h_top = head_height(lines, (y0 + top).astype(np.float64))
    w_top = expected_size(lines, y0 + top + np.maximum(h_top, 1.0))[:, 1]
    # columns whose outline is a local top (plateaus: their middle column)
    lo = np.minimum(np.r_[top[1:], bh], np.r_[bh, top[:-1]])
    cand = np.flatnonzero(has & (top <= lo) & (h_top > 0))
    found: list[tuple[float, float, float, float]] = []
    for x in cand[np.argsort(top[cand], kind="stable")]:
        h, w = float(h_top[x]), float(w_top[x])
        if any(abs(x + 0.5 - (f[0] - x0 + f[2] / 2.0)) < f[2] / 2.0 for f in found):
            continue  # a column of a higher head's person
        r = max(int(round(w / 2.0)), 2)
        a, b = max(x - r, 0), min(x + r + 1, bw)
        if top[a:b].min() < top[x]:
            continue
        drop = top[x] + SHOULDER_DROP * h
        left = top[max(x - r, 0) : max(x - r // 2, 0) + 1] if x - r // 2 > 0 else None
        right = top[min(x + r // 2, bw - 1) : x + r + 1] if x + r // 2 < bw else None
        if not (_lower(left, x - r < 0, drop) and _lower(right, x + r >= bw, drop)):
            continue
        found.append((x0 + x + 0.5 - w / 2.0, float(y0 + top[x]), w, h))
    if len(found) < 2:
        return None
    out = np.asarray(found, np.float64)
    held = np.array([np.count_nonzero(_window(mask, f)) for f in out])
    if np.any(held < MIN_SHARE * out[:, 2] * out[:, 3]):
        return None  # a person placed over too little of the blob: not a reading to trust
    # whole people, clipped to the frame (a truth box is the person's extent in the image)
    lo2 = np.maximum(out[:, :2], 0.0)
    hi2 = np.minimum(out[:, :2] + out[:, 2:], np.array([cols, rows], np.float64))
    return np.column_stack([lo2, np.maximum(hi2 - lo2, 1.0)])


def _own_pixels(crop: NDArray[np.uint8]) -> NDArray[np.bool_]:
    """The largest 8-connected region of a box's crop: the blob, without a neighbour's corner."""
    n, labels, stats, _ = cv2.connectedComponentsWithStats(
        (crop != 0).view(np.uint8), connectivity=8
    )
    fg: NDArray[np.bool_] = crop != 0
    if n <= 2:
        return fg
    own = 1 + int(np.argmax(stats[1:, cv2.CC_STAT_AREA]))
    out: NDArray[np.bool_] = labels == own
    return out


def _lower(side: NDArray[np.int64] | None, edge: bool, drop: float) -> bool:
    """Whether the outline on one side of a head falls to `drop` (or the box ends there)."""
    return edge or side is None or not len(side) or float(side.max()) >= drop


def _window(mask: NDArray[np.uint8], box: F64) -> NDArray[np.uint8]:
    x, y, w, h = box
    a, b = max(int(x), 0), max(int(y), 0)
    return mask[b : b + max(int(h), 1), a : a + max(int(w), 1)]


def _fill(mask: NDArray[np.uint8], boxes: F64) -> F64:
    """Foreground share of each box (K, 4) in `mask`."""
    out = np.empty(len(boxes))
    for k, box in enumerate(boxes):
        win = _window(mask, box)
        out[k] = np.count_nonzero(win) / max(win.size, 1)
    return out
