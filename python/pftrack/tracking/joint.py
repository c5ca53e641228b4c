"""The joint tracker: one RJ-MCMC chain over all objects (``sampler="rjmcmc"``).

Where the per-object samplers pair tracks with detections, the joint sampler (Smith et al.
2005, :class:`~pftrack.particle_filter.RJMCMCFilter`) births, kills and moves objects itself;
detections are only its birth candidates. Each estimate is reported with the detection it
overlaps best (IoU >= 0.5), if any.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from pftrack._core import BinnedImage
from pftrack._typing import F64
from pftrack.boxes import _iou_matrix, _to_cxcywh, _to_xywh
from pftrack.particle_filter import RJMCMCConfig, RJMCMCFilter
from pftrack.tracking.config import TrackerConfig
from pftrack.tracking.track import Track

__all__ = ["JointTracker", "joint_config"]


def joint_config(config: TrackerConfig) -> RJMCMCConfig:
    """The joint sampler's settings with the per-object filters' budget and AR(2) dynamics.

    ``config.rjmcmc`` with the sample count of ``config.filter`` and its dynamics, so that only
    the sampler differs between ``sampler="sis" | "mh" | "rjmcmc"``.
    """
    m = config.filter.model
    return replace(
        config.rjmcmc,
        n_samples=config.filter.n_particles,
        a=tuple(m.a),
        b=tuple(m.b),
        sigma=tuple(m.sigma),
        s_min=m.s_min,
        s_max=m.s_max,
    )


class JointTracker:
    """Drive an :class:`~pftrack.particle_filter.RJMCMCFilter` frame by frame.

    Parameters
    ----------
    config : TrackerConfig
        The joint sampler's settings (``rjmcmc``), with the sample count and AR(2) dynamics of
        ``filter``: the same budget and model as the per-object filters, so that only the
        sampler differs between ``sampler="sis" | "mh" | "rjmcmc"``.
    rng : numpy.random.Generator
        Seeds the sampler on its first frame.
    """

    def __init__(self, config: TrackerConfig, rng: np.random.Generator) -> None:
        self.config = config
        self._rng = rng
        self._filter: RJMCMCFilter | None = None
        self._ids: set[int] = set()  # every id the sampler has estimated
        #: The last frame's estimated boxes ``(K, 4)`` (left, top, w, h): what the camera
        #: check leaves out, as the per-object trackers' boxes are.
        self.boxes: F64 = np.zeros((0, 4))

    @property
    def started(self) -> int:
        """Objects the sampler has estimated so far (each with its own id)."""
        return len(self._ids)

    def warp(self, affine: F64) -> None:
        """Move the sampler's identities by the camera's motion (a (2, 3) similarity)."""
        if self._filter is not None:
            self._filter.warp(affine)

    def step(self, frame_index: int, binned: BinnedImage, mask: NDArray[np.uint8], boxes: F64,
             scores: F64, index: NDArray[np.intp]) -> list[Track]:  # fmt: skip
        """One frame: `boxes` (xywh) are the birth candidates, `index` their input positions."""
        if self._filter is None:
            self._filter = RJMCMCFilter(joint_config(self.config), rng=self._rng)
        estimates = self._filter.step(binned, mask, _to_cxcywh(boxes))
        self._ids.update(int(e.id) for e in estimates)
        ebox = np.array([_to_xywh(e.box_cxcywh) for e in estimates]).reshape(-1, 4)
        self.boxes = ebox
        iou = _iou_matrix(ebox, boxes) if len(boxes) else np.zeros((len(estimates), 0))
        out = []
        for k, e in enumerate(estimates):
            j = int(np.argmax(iou[k])) if iou.shape[1] else -1
            matched = j >= 0 and iou[k, j] >= 0.5
            out.append(
                Track(
                    id=int(e.id) + 1,  # MOTChallenge ids count from 1, as sis and mh's do
                    box_xywh=ebox[k].copy(),
                    score=float(scores[j]) if matched else float(e.score),
                    detection_index=int(index[j]) if matched else None,
                    age=frame_index,
                    time_since_update=0 if matched else 1,
                )
            )
        return out
