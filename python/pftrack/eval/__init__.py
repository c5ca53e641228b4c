"""Evaluation of tracking results: HOTA, CLEAR-MOT, IDF1 and Smith et al.'s measures.

:func:`evaluate_hota` reproduces TrackEval's HOTA; :func:`evaluate_mot` its CLEAR-MOT and IDF1
(on the same rows, chosen by its MOTChallenge rules: :func:`prepare_mot`);
:func:`evaluate_sequence` does both, and :func:`find_sequences` reads a MOTChallenge folder of
sequences.
"""

from __future__ import annotations

from pftrack._lazy import lazy_exports
from pftrack.eval.hota import (
    ALPHAS,
    HotaMetrics,
    combine_hota,
    evaluate_hota,
    guess_benchmark,
    mot_iou,
    prepare_mot,
)
from pftrack.eval.metrics import MotMetrics, combine_mot, evaluate_mot, format_metrics, iou_xywh
from pftrack.eval.sequences import (
    SequenceInfo,
    SequenceScores,
    check_scale,
    evaluate_sequence,
    find_sequences,
    format_scores,
)

__all__ = [
    "ALPHAS",
    "HotaMetrics",
    "MotMetrics",
    "SequenceInfo",
    "SequenceScores",
    "check_scale",
    "combine_hota",
    "combine_mot",
    "evaluate_hota",
    "evaluate_mot",
    "evaluate_sequence",
    "find_sequences",
    "format_metrics",
    "format_scores",
    "guess_benchmark",
    "iou_xywh",
    "mot_iou",
    "prepare_mot",
]

# a public submodule loads on first use after a bare ``import pftrack`` (``pftrack.eval.x``)
_, __getattr__, __dir__ = lazy_exports(__name__, {}, globals())
