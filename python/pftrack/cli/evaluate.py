"""``pftrack eval``: score tracking results against ground truth, one file or a folder."""

from __future__ import annotations

import argparse
import re
import sys
import warnings
from collections.abc import Callable, Collection
from pathlib import Path
from typing import TYPE_CHECKING, Any

from pftrack.cli._options import (
    IOU_HELP,
    YOURS,
    WidthHeight,
    add_command,
    add_force,
    bounded_int,
    iou_threshold,
    report_stream,
)

if TYPE_CHECKING:
    from pftrack._progress import Bar
    from pftrack._typing import F64

#: ``--image-size``'s largest side (px), as ``experiment gaps``' MAX_SIDE.
MAX_IMAGE_SIDE = 100_000

EXAMPLES = """\
examples:
  pftrack eval --gt gt.txt --res tracks.txt
  pftrack eval --gt pets09-s2l1/gt.txt --res tracks.txt --scale 0.625   # gt 768x576, video 480x360
  pftrack eval --gt MOT17/train --res results/ --csv scores.csv         # results/SEQ.txt per SEQ
  pftrack eval --gt data --res results/ --scale pets09-s2l1=0.625 --seqs pets09-s2l1 tud-campus
"""


def scale_spec(text: str) -> tuple[str | None, float]:
    """Argument type of ``--scale``: ``S`` (every sequence) or ``NAME=S`` (one sequence)."""
    name, eq, value = text.rpartition("=")
    if eq and not name.strip():
        raise argparse.ArgumentTypeError(f"expected S or NAME=S, got {text!r}: NAME is empty")
    try:
        v = float(value)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected S or NAME=S with S a number, got {text!r}"
        ) from None
    if not 0 < v < float("inf"):
        raise argparse.ArgumentTypeError(f"expected a finite scale > 0, got {v}")
    return (name or None), v


def add_parser(sub: Any) -> None:
    """Register ``eval`` on `sub` (from ``add_subparsers``)."""
    p = add_command(
        sub,
        "eval",
        help="score tracking results against ground truth (HOTA, MOTA, IDF1, ...)",
        description="Score a MOTChallenge result file against a ground-truth file, or a folder "
        "of results (RES/SEQ.txt, or RES/data/SEQ.txt) against a MOTChallenge folder of "
        "sequences (GT/SEQ/gt/gt.txt or GT/SEQ/gt.txt, with GT/SEQ/seqinfo.ini), or a folder of "
        "them, with one row per sequence and a combined row; TrackEval's tree is read as it is "
        "(--gt gt/mot_challenge/MOT17-train --res trackers/mot_challenge/MOT17-train/NAME). "
        "Reports HOTA, DetA, AssA and LocA, CLEAR-MOT (MOTA, MOTP as mean IoU of matches, FP, "
        "FN, IDSW, Frag, MT/PT/ML) and IDF1/IDP/IDR exactly as TrackEval computes them, on the "
        "rows its MOTChallenge rules score (zero-marked ground-truth rows dropped, the result "
        "boxes on them false positives; for MOT16/17/20 only pedestrians scored and result boxes "
        "on distractors removed), and Smith et al.'s success rate. The combined row sums counts, "
        "as TrackEval does.",
        epilog=EXAMPLES,
    )
    p.add_argument("--gt", required=True, help="ground truth: a MOTChallenge file or folder")
    p.add_argument("--res", required=True, help="results: a MOTChallenge file, or a folder")
    p.add_argument(
        "--scale", type=scale_spec, action="append", default=None, metavar="[NAME=]S",
        help="multiply ground-truth boxes by S, for every sequence or for sequence NAME "
        "(repeat the option for other sequences; twice for the same ones is refused); 0.625 "
        "for PETS09 gt on its 480x360 video (default: 1 everywhere)",
    )  # fmt: skip
    p.add_argument("--iou", type=iou_threshold, default=0.5, help=IOU_HELP)
    p.add_argument(
        "--benchmark", choices=("auto", "MOT15", "MOT16", "MOT17", "MOT20"), default="auto",
        help="ground-truth rules: which rows HOTA, CLEAR-MOT and IDF1 score; auto: the "
        "benchmark a TrackEval folder of the ground truth names (gt/mot_challenge/MOT20-train/"
        "...: MOT20), else MOT17 when column 8 holds classes 1-13 (and column 9 visibilities, or "
        "nothing), else MOT15",
    )  # fmt: skip
    p.add_argument("--seqs", nargs="+", metavar="NAME", default=None,
                   help="score only these sequences of a folder (default: all of "
                   "them)")  # fmt: skip
    p.add_argument("--image-size", action=WidthHeight, number=bounded_int(1, MAX_IMAGE_SIDE),
                   default=None,
                   help=f"image size for the centroid-distance ratio, W H or WxH (px, 1 to "
                   f"{MAX_IMAGE_SIDE}; default: seqinfo.ini's size times the scale, where there "
                   "is one)")  # fmt: skip
    p.add_argument(
        "--no-scale-check", action="store_true",
        help="score even when result boxes look like another pixel scale than the ground "
        "truth, normalised coordinates, or corners x1, y1, x2, y2 where width and height "
        "belong",
    )  # fmt: skip
    p.add_argument("--json", default=None, help="also write all metrics to this JSON file")
    p.add_argument("--csv", default=None, help="also write the table's scores to this CSV file")
    add_force(p)
    p.set_defaults(func=run)


def _check_scales(specs: list[tuple[str | None, float]]) -> None:
    """Refuse a ``--scale`` given twice for every sequence, or twice for one NAME.

    The option is repeated to give sequences their own scales: a second value for the same
    sequences would silently win over the first.
    """
    seen: dict[str | None, float] = {}
    for name, value in specs:
        if name in seen:
            which = "every sequence" if name is None else f"sequence {name}"
            given = f"{seen[name]:g}, then {value:g}"
            raise ValueError(
                f"--scale is given twice for {which} ({given}); give it once (repeat it only "
                "for other sequences: --scale NAME=S)"
            )
        seen[name] = value


def _scales(
    specs: list[tuple[str | None, float]], names: list[str], left_out: Collection[str] = ()
) -> dict[str, float]:
    """Scale per sequence name from the ``--scale`` options.

    A scale for a sequence that ``--seqs`` leaves out (`left_out`) is not used (was: refused
    as "no sequence", of a sequence that is there: a script that gives every sequence's scale
    could not score a few of them; a user trial).
    """
    default = 1.0
    per: dict[str, float] = {}
    for name, value in specs:
        if name is None:
            default = value
        elif name in left_out:
            continue
        elif name not in names:
            raise ValueError(f"--scale {name}={value:g}: no sequence {name!r} (have {names})")
        else:
            per[name] = value
    return {n: per.get(n, default) for n in names}


def _left_out(args: argparse.Namespace, names: list[str]) -> set[str]:
    """The sequences of the ground-truth folder that ``--seqs`` does not score."""
    if not args.seqs or not Path(args.gt).is_dir():
        return set()
    from pftrack.eval import find_sequences

    return {s.name for s in find_sequences(args.gt, args.seqs)} - set(names)


def _jobs(args: argparse.Namespace) -> list[tuple[str, Any, Path]]:
    """(name, SequenceInfo, result file) of every sequence to score, checked before work."""
    from pftrack.eval import find_sequences
    from pftrack.eval.sequences import result_file, sequence_of_file
    from pftrack.io.atomic import refuse_dash, refuse_loop

    gt, res = Path(args.gt), Path(args.res)
    refuse_dash(args.gt, "--gt", name="file or folder")
    refuse_dash(args.res, "--res", name="file or folder")
    for what, given in (("--gt", gt), ("--res", res)):
        refuse_loop(given, what)
    if not gt.exists():
        raise FileNotFoundError(f"ground truth not found: {gt} (a MOTChallenge file or folder)")
    for what, given in (("--gt", gt), ("--res", res)):
        if given.exists() and not (given.is_file() or given.is_dir()):  # /dev/null: read twice
            raise ValueError(f"{what} {given} is not a regular file or a folder (a device or pipe)")
    if gt.is_file():
        if res.is_dir():
            raise ValueError(
                f"--res {res} is a folder but --gt {gt} is one file; give one result file, or "
                "a ground-truth folder of sequences with a folder of SEQ.txt results"
            )
        if not res.is_file():
            raise FileNotFoundError(f"result file not found: {res}")
        if args.seqs:
            raise ValueError("--seqs needs a ground-truth folder, not a file")
        return [(res.stem, sequence_of_file(gt, res.stem), res)]
    seqs = find_sequences(gt, args.seqs or None)  # the others' seqinfo.ini is not read
    if args.seqs:
        known = {s.name for s in seqs}
        unknown = [n for n in args.seqs if n not in known]
        if unknown:
            raise ValueError(f"--seqs: no sequence {unknown[0]!r} in {gt} (have {sorted(known)})")
        seqs = [s for s in seqs if s.name in args.seqs]
    if res.is_file() and len(seqs) == 1:
        return [(seqs[0].name, seqs[0], res)]
    if res.is_file():  # was "results folder not found", of a file that exists
        raise ValueError(
            f"--res {res} is a file, but --gt {gt} holds {len(seqs)} sequences: give a folder "
            "of SEQ.txt results (or pick one sequence with --seqs NAME)"
        )
    if not res.is_dir():
        raise FileNotFoundError(
            f"results folder not found: {res} (a ground-truth folder of {len(seqs)} sequences "
            "needs a folder of SEQ.txt results)"
        )
    found = {s.name: result_file(res, s.name) for s in seqs}
    missing = [name for name, path in found.items() if path is None]
    if missing:
        raise FileNotFoundError(_no_result(res, missing, len(seqs)))
    return [(s.name, s, p) for s in seqs if (p := found[s.name]) is not None]


def _no_result(res: Path, missing: list[str], n_seqs: int) -> str:
    """Why results are missing: the files looked for, and the way out that fits."""
    where = f"{res / missing[0]}.txt (or {res / 'data' / missing[0]}.txt)"
    if len(missing) < n_seqs:  # some found: the others may be left out
        return (
            f"no result for sequence {missing[0]}: {where}; to score only the sequences with "
            f"results, name them with --seqs"
        )
    trackers = [d.name for d in sorted(res.iterdir()) if d.is_dir() and (d / "data").is_dir()]
    if trackers:  # TrackEval's trackers/mot_challenge/BENCH-SPLIT: one folder per tracker
        return (
            f"no result for sequence {missing[0]} in {res}, which holds tracker folders "
            f"({', '.join(trackers[:5])}): give one of them as --res"
        )
    return (
        f"no result for sequence {missing[0]}: {where}; --res must hold SEQ.txt for every "
        "sequence of --gt (or data/SEQ.txt, TrackEval's trackers/mot_challenge/BENCH-SPLIT/"
        "TRACKER)"
    )


def _in_file(message: str, gt: Path, res: Path) -> str:
    """A scorer's message ("ground truth has ...", "result has ...") led by the file it is about.

    Was led by the sequence's name, for one file the result file's stem: ``--gt det.txt --res
    gt.txt`` said "gt: ground truth has id -1 more than once ...", naming the other file.
    """
    if message.startswith("ground truth"):
        return f"{gt}: {message}"
    if message.startswith("result"):
        return f"{res}: {message}"
    return f"{gt} against {res}: {message}"


def _none_matched(path: Path, res: F64, gt_path: Path, gt: F64, iou: float) -> list[str]:
    """The note of a result none of whose boxes matched a ground-truth box, or none.

    Scored as it is (MOTA at or below 0), but almost always a pair of files that do not
    belong together: the tracks of another sequence or video, or frames numbered otherwise
    (was: a table of zeros without a word; a CLI trial scored TUD-Campus's tracks against
    PETS09's ground truth, MOTA -6.9). A scale apart is refused before, by the scale check.
    """
    from pftrack.eval.sequences import none_matched

    if not len(res):  # an empty result says so itself
        return []
    # evaluate_sequence's own warning, with the files named (and "no frame in common" said)
    return [f"{path}: {none_matched(res, gt, iou, whose='its', gt_name=str(gt_path))}"]


def _bar_label(done: int, n: int) -> str:
    """The label of ``eval``'s bar: ``eval`` for one sequence, ``eval 1/3 sequences`` else."""
    return "eval" if n == 1 else f"eval {done}/{n} sequences"


def _mover(bar: Bar, before: int, frames: int) -> Callable[[float], None] | None:
    """`bar`'s ``on_progress`` for a sequence of `frames` frames after `before` frames scored.

    None when the bar is not drawn: the scorers then report nothing.
    """
    if not bar.enabled:
        return None
    return lambda f: bar.set(before + round(f * frames))


def run(args: argparse.Namespace) -> int:
    """Run ``pftrack eval``: optionally write JSON/CSV, then print the table; return the status."""
    import json

    import numpy as np

    from pftrack._progress import Bar, enabled
    from pftrack.cli._signals import hold_interrupts
    from pftrack.eval.rows import (
        frame_ranges_notes,
        gt_conf_note,
        gt_rules_note,
        result_class_note,
    )
    from pftrack.eval.sequences import (
        NONE_MATCHED,
        SequenceScores,
        benchmark_of_path,
        check_scale,
        evaluate_sequence,
        format_scores,
        name_seqinfo,
        scores_csv,
        scores_doc,
    )
    from pftrack.io.atomic import check_output, check_replaceable, staged_outputs
    from pftrack.io.marks import is_marked_csv, is_marked_json, json_marked
    from pftrack.io.mot import no_rows, read_ground_truth, read_mot
    from pftrack.recovery.linking import check_scored_ids

    _check_scales(args.scale or [])
    jobs = _jobs(args)
    # every ground-truth and result file read (a link named s.json may lead to one)
    inputs = (args.gt, args.res, *(p for _, seq, res in jobs for p in (seq.gt_path, res)))
    if args.json is not None:  # "" too: refused as empty (was: nothing written, silently)
        check_output(args.json, what="--json", suffixes=(".json",), inputs=inputs)
    if args.csv is not None:
        check_output(args.csv, what="--csv", suffixes=(".csv",), inputs=inputs)
    if args.json:
        check_replaceable(args.json, "--json", is_marked_json, force=args.force, yours=YOURS)
    if args.csv:
        check_replaceable(args.csv, "--csv", is_marked_csv, force=args.force, yours=YOURS)
    names = [name for name, _, _ in jobs]
    scales = _scales(args.scale or [], names, _left_out(args, names))

    loaded: list[tuple[str, Any, F64, F64, Path]] = []
    frames: list[int] = []  # of each sequence, for the bar: those of its gt or its result
    shown = enabled()
    # a first bar counts the files read and checked (a pair of 100 000 frames took 5 s before
    # the frames' bar appeared: reading 2 s, the scale check 3 s, the frames counted 0.7 s)
    with Bar(2 * len(jobs), desc="eval reading", enable=shown, unit="file") as reading:
        for name, seq, path in jobs:  # read and check everything before scoring anything
            gt = read_ground_truth(seq.gt_path)  # refused if it holds no row
            if shown:  # off a terminal nothing is counted, as the scorers report nothing
                reading.set(2 * len(loaded) + 1)
            res = read_mot(path, what="result file")
            # 1.5 is refused, as recover does (was: scored as 1), and -5 named by its line
            check_scored_ids(gt, seq.gt_path)
            check_scored_ids(res, path)
            if not args.no_scale_check:
                # several sequences: the fix is this one's scale, --scale NAME=S (was --scale S)
                several = name if len(jobs) > 1 else None
                check_scale(gt, res, scale=scales[name], name=f"{path}", sequence=several)
            frames.append(len(np.union1d(gt[:, 0], res[:, 0])) if shown else 0)
            loaded.append((name, seq, gt, res, path))
            if shown:
                reading.set(2 * len(loaded))

    scores: dict[str, SequenceScores] = {}
    notes: list[str] = []
    said: list[str] = []  # gt_rules_note's: below the table's legend
    # the bar counts the frames scored (those of the ground truth or the result), moved as
    # each sequence is scored: it counted sequences, and one long sequence sat at 0/1
    with Bar(sum(frames), desc=_bar_label(0, len(loaded)), enable=shown, unit="frame") as bar:
        for k, (name, seq, gt, res, path) in enumerate(loaded):
            s = scales[name]
            size = tuple(args.image_size) if args.image_size else None
            if size is None and seq.width and seq.height:
                size = (round(seq.width * s), round(seq.height * s))
            # auto: the benchmark of TrackEval's folder (MOT20-train/SEQ), as TrackEval scores
            # it; else guessed from the columns (was: always guessed, MOT20-train as MOT17)
            folder = benchmark_of_path(seq.gt_path) if args.benchmark == "auto" else None
            try:
                with warnings.catch_warnings():
                    # said below as _none_matched's note, naming the files, after the outputs
                    warnings.filterwarnings("ignore", message=re.escape(NONE_MATCHED))
                    scores[name] = evaluate_sequence(
                        gt,
                        res,
                        iou_threshold=args.iou,
                        scale=s,
                        image_size=size,
                        benchmark=folder[0] if folder else args.benchmark,
                        num_frames=seq.length,
                        on_progress=_mover(bar, sum(frames[:k]), frames[k]),
                    )
            except ValueError as exc:
                message = _in_file(name_seqinfo(str(exc), seq.seqinfo), seq.gt_path, path)
                if folder and "MOT15-style" in message:  # say where MOT17 rules came from
                    message += f" (--benchmark auto took {folder[0]} from its folder {folder[1]})"
                raise ValueError(message) from None
            bar.describe(_bar_label(k + 1, len(loaded)))
            if not len(res):  # a tracker that found nothing: scored, and said
                notes.append(
                    f"{path} {no_rows(path)}: scored as tracks of nothing, every ground-truth "
                    "box missed"
                )
            note = result_class_note(res, scores[name].benchmark)
            if note:
                notes.append(f"{path}: {note}")
            note = gt_conf_note(gt)
            if not note:  # which rows the rules scored (was: "MOT17 ground-truth rules" alone)
                rules = gt_rules_note(gt, res, scores[name].benchmark, scale=s)
                said.extend([f"{seq.gt_path}: {rules}"] if rules else [])
            if note:
                notes.append(f"{seq.gt_path}: {note}")
            elif not scores[name].mot.num_matches and scores[name].mot.num_objects:
                notes.extend(_none_matched(path, res, seq.gt_path, gt, args.iou))
            else:  # was said nowhere: a truth of frames 1-40 against tracks of 1-71 scored
                # 133 false positives, MOTA 21.4 for 81.4 on the frames both cover
                notes.extend(
                    frame_ranges_notes(gt, res, gt_name=str(seq.gt_path), res_name=str(path))
                )
    combined = SequenceScores.combine(list(scores.values())) if len(scores) > 1 else None
    # both replaced at the end, or neither (was: one after the other; a Ctrl-C between them,
    # or one code in C dropped, which the second refused, left a new --json beside an old --csv
    # and said "no output was changed")
    with staged_outputs() as stage:
        if args.json:
            if Path(args.gt).is_file():  # one file: its metrics at the top level, as before
                doc = next(iter(scores.values())).as_dict()
            else:
                doc = scores_doc(scores, combined)
            text = json.dumps(json_marked(doc, "eval"), indent=2)
            with stage(args.json, ".json").open("w") as fh:
                fh.write(text + "\n")
        if args.csv:
            with stage(args.csv, ".csv").open("w") as fh:
                fh.write(scores_csv(scores, combined))
        if args.json or args.csv:
            hold_interrupts()  # the work is done: the outputs are put in place whatever comes
    for note in notes:  # once the files are written, as pftrack render says its warnings
        print(f"pftrack eval: warning: {note}", file=sys.stderr)
    # after the files: a closed stdout cannot lose them; not into a file written to stdout
    report = report_stream(args.json, args.csv)
    print(format_scores(scores, combined), file=report)
    for line in said:  # below the legend: which rows its rules scored (a fact, no warning)
        print(line, file=report)
    return 0
