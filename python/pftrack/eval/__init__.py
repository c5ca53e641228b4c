"""Evaluation of tracking results: CLEAR-MOT, IDF1 and Smith et al.'s per-object measures."""

from __future__ import annotations

from pftrack.eval.metrics import MotMetrics, evaluate_mot, format_metrics, iou_xywh

__all__ = ["MotMetrics", "evaluate_mot", "format_metrics", "iou_xywh"]
