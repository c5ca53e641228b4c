"""What the offline pass gains or loses on each sequence: its steps one at a time, and its holes.

pftrack runs as a user's loop runs it (:class:`pftrack.Tracker`, public detections, seed 0, primed
as ``pftrack track`` primes it) and SORT (``sort-track``, Bewley's defaults) beside it, when
installed. Each tracker's online rows are then passed through
:func:`pftrack.tracking.smooth_tracks` one step at a time, and every result is scored alike
(:func:`pftrack.eval.evaluate_mot`, IoU 0.5):

``online``
    What ``Tracker.update`` returned, frame by frame: BoxMOT's convention, the confirmed tracks
    matched to a detection that frame (no coasted box); SORT's own rows, which are the same kind.
``smoother``, ``smoother+fill``, ``link``, ``offline``
    The ``online`` rows through the box smoother alone; the smoother filling holes of up to 30
    frames inside each id (no linking); linking alone; the whole pass (``smooth_tracks(rows)``).
``finalize``
    pftrack's own offline pass, :meth:`pftrack.Tracker.finalize` (what ``pftrack track`` writes).

The last table sorts the frames the fill adds inside each id of the ``online`` rows by what the
rows on either side of the hole are: both on a true object at IoU 0.5 (``same`` / ``other``
object), one of them, or neither (the track's boxes there match no truth; filling them can only
add false positives).

Usage (from the repository root)::

    python -m experiments.offline_holes [--data ../shared/data]
        [--seq ETH-Sunnyday ADL-Rundle-6 KITTI-17 tud-campus pets09-s2l1] [--out out/offline_holes]
"""

from __future__ import annotations

import contextlib
import importlib.util
import io
import sys
import warnings
from collections import Counter

import numpy as np

from experiments._common import data_folder, experiment_parser, write_text
from experiments.compare_trackers import (
    SEQUENCES,
    PftrackStep,
    load,
    make_sort,
    online_rows,
    public_detections,
)
from pftrack._typing import F64
from pftrack.boxes import iou_xywh
from pftrack.eval import evaluate_mot
from pftrack.io.mot import group_by_frame
from pftrack.tracking import smooth_tracks

STEPS = ("online", "smoother", "smoother+fill", "link", "offline", "finalize")


def steps(online: F64, final: F64 | None) -> dict[str, F64]:
    """The rows after each step of the offline pass (see the module's text)."""
    out = {
        "online": online,
        "smoother": smooth_tracks(online, link=None),
        "smoother+fill": smooth_tracks(online, link=None, max_gap=30),
        "link": smooth_tracks(online, smoother=None),
        "offline": smooth_tracks(online),
    }
    if final is not None:
        out["finalize"] = final
    return out


def hole_ends(rows: F64, gt: F64, scale: float, max_gap: int = 30) -> Counter[str]:
    """Missing frames inside each id (holes of at most `max_gap`), by what the rows on either
    side match in the truth at IoU 0.5: ``same``, ``other`` object, ``one`` side, ``neither``."""
    truth = group_by_frame(gt)

    def match(frame: int, box: F64) -> int | None:
        g = truth.get(frame)
        if g is None or len(g) == 0:
            return None
        iou = iou_xywh(box[None], g[:, 2:6] * scale)[0]
        k = int(iou.argmax())
        return int(g[k, 1]) if iou[k] >= 0.5 else None

    counts: Counter[str] = Counter()
    for tid in np.unique(rows[:, 1]):
        r = rows[rows[:, 1] == tid]
        r = r[np.argsort(r[:, 0])]
        fr = r[:, 0].astype(int)
        for i in np.flatnonzero((np.diff(fr) > 1) & (np.diff(fr) <= max_gap + 1)):
            a, b = match(fr[i], r[i, 2:6]), match(fr[i + 1], r[i + 1, 2:6])
            kind = (
                "neither"
                if a is None and b is None
                else "one"
                if a is None or b is None
                else "same"
                if a == b
                else "other"
            )
            counts[kind] += int(fr[i + 1] - fr[i] - 1)
    return counts


def main(argv: list[str] | None = None) -> int:
    ap = experiment_parser("offline_holes", __doc__)
    default = ["ETH-Sunnyday", "ADL-Rundle-6", "KITTI-17", "tud-campus", "pets09-s2l1"]
    ap.add_argument(
        "--seq",
        nargs="+",
        default=default,
        choices=list(SEQUENCES),
        metavar="SEQ",
        help=f"sequences, of {', '.join(SEQUENCES)} (default: all five)",
    )
    args = ap.parse_args(argv)
    root = data_folder(args.data)
    if root is None:
        return 2
    # SORT beside pftrack when sort-track is installed (pip install --no-deps sort-track)
    trackers = ("pftrack", "sort") if importlib.util.find_spec("sort") else ("pftrack",)
    lines = ["| sequence | tracker | " + " | ".join(STEPS) + " |", "|---" * (len(STEPS) + 2) + "|"]
    holes = ["| sequence | tracker | same | other | one | neither |", "|---" * 6 + "|"]
    for name in args.seq:
        seq, folder, frames, gt, size = load(root, name)
        dets = public_detections(folder, seq, len(frames))
        for tracker in trackers:
            with warnings.catch_warnings(), contextlib.redirect_stdout(io.StringIO()):
                warnings.simplefilter("ignore")
                if tracker == "pftrack":
                    pf = PftrackStep()
                    pf.prime(frames, own=False)
                    runs = steps(online_rows(pf, frames, dets)[0], pf.result())
                else:
                    runs = steps(online_rows(make_sort(seq), frames, dets)[0], None)
            cells = []
            for step in STEPS:
                if step not in runs:
                    cells.append("")
                    continue
                m = evaluate_mot(gt, runs[step], scale=seq.scale, image_size=size)
                cells.append(f"{100 * m.mota:.1f} / {100 * m.idf1:.1f} ({m.false_positives} FP)")
            lines.append(f"| {name} | {tracker} | " + " | ".join(cells) + " |")
            c = hole_ends(runs["online"], gt, seq.scale)
            holes.append(
                f"| {name} | {tracker} | {c['same']} | {c['other']} | {c['one']} | {c['neither']} |"
            )
            print(lines[-1], flush=True)
    text = "\n".join(lines) + "\n\nFrames filled inside ids, by their holes' ends:\n\n"
    text += "\n".join(holes) + "\n"
    print()
    print(text)
    write_text(args.out / "offline_holes.md", text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
