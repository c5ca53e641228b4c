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
from pftrack.particle_filter import RJMCMCConfig, RJMCMCFilter, box_histograms
from pftrack.tracking.association import first_of_twins
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
             scores: F64, index: NDArray[np.intp], labels: NDArray[np.int64],
             given: bool) -> list[Track]:  # fmt: skip
        """One frame: `boxes` (xywh) are the birth candidates, `index` their input positions.

        `boxes` are in :func:`~pftrack.tracking.tracker.canonical_order`. A given detection
        (`given`) that is a second box on an object, by the rule the per-object samplers' births
        follow (:func:`~pftrack.tracking.association.first_of_twins`), opens no newborn slot
        (its histogram is passed as all zeros); it still supports the identities it overlaps
        (the chain's detection term). Until 6 December each box of a duplicated pair opened
        its own slot, and both were born: 15-20 identities for 5 walkers.
        """
        if self._filter is None:
            self._filter = RJMCMCFilter(joint_config(self.config), rng=self._rng)
        cxcywh = _to_cxcywh(boxes)
        hists = self._birth_histograms(binned, boxes, cxcywh, labels, given)
        estimates = self._filter.step(binned, mask, cxcywh, hists)
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

    def _birth_histograms(self, binned: BinnedImage, boxes: F64, cxcywh: F64,
                          labels: NDArray[np.int64], given: bool) -> F64 | None:  # fmt: skip
        """The candidates' histograms, all zeros for a duplicate's; None: no duplicate.

        None leaves them to the chain, which computes the same ones: a frame without a
        duplicate runs exactly as before the rule.
        """
        overlap = self.config.lifecycle.birth_overlap if given else None
        everyone = list(range(len(boxes)))
        explained = np.zeros(len(boxes), np.bool_)  # the chain has no matched detections
        if len(first_of_twins(boxes, labels, everyone, explained, overlap)) == len(everyone):
            return None  # no two candidates on one object
        hists = box_histograms(binned, cxcywh, self.config.rjmcmc.kernel)  # the chain's
        coloured = [k for k in everyone if hists[k].sum() > 0]  # the others cannot be born
        born = first_of_twins(boxes, labels, coloured, explained, overlap)
        hists[np.setdiff1d(everyone, born).astype(np.intp)] = 0.0
        return hists
