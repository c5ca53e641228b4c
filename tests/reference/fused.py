"""Vectorised NumPy implementations a Python user would write: the speed baselines.

``tests.reference.kernels`` holds the obviously-correct references; these are the
fast-as-NumPy-gets ones.
"""

from __future__ import annotations

import cv2
import numpy as np


def hsv_bins(frame, n_h=10, n_s=10, n_v=10, s_min=0.1, v_min=0.2):
    hsv = cv2.cvtColor(frame, cv2.COLOR_BGR2HSV_FULL).astype(np.int32)
    h, s, v = hsv[..., 0], hsv[..., 1], hsv[..., 2]
    colour = (s > s_min * 255) & (v > v_min * 255)
    hb = np.minimum(h * n_h // 256, n_h - 1)
    sb = np.minimum(s * n_s // 256, n_s - 1)
    vb = np.minimum(v * n_v // 256, n_v - 1)
    return np.where(colour, hb * n_s + sb, n_h * n_s + vb).astype(np.int16)


def histograms_and_weights(bins, n_bins, boxes, ref, lam=20.0):
    rows, cols = bins.shape
    hists = np.zeros((len(boxes), n_bins))
    x0 = np.clip(np.floor(boxes[:, 0] - boxes[:, 2] / 2 + 0.5).astype(int), 0, cols)
    x1 = np.clip(np.floor(boxes[:, 0] + boxes[:, 2] / 2 + 0.5).astype(int), 0, cols)
    y0 = np.clip(np.floor(boxes[:, 1] - boxes[:, 3] / 2 + 0.5).astype(int), 0, rows)
    y1 = np.clip(np.floor(boxes[:, 1] + boxes[:, 3] / 2 + 0.5).astype(int), 0, rows)
    for i in range(len(boxes)):
        patch = bins[y0[i] : y1[i], x0[i] : x1[i]].ravel()
        patch = patch[patch >= 0]
        if patch.size:
            hists[i] = np.bincount(patch, minlength=n_bins) / patch.size
    rho = np.sqrt(hists) @ np.sqrt(ref / ref.sum())
    logw = -lam * (1.0 - np.clip(rho, 0, 1))
    w = np.exp(logw - logw.max())
    return w / w.sum()


def systematic_resample(weights, u0):
    n = len(weights)
    cdf = np.cumsum(weights)
    cdf /= cdf[-1]
    return np.minimum(np.searchsorted(cdf, (np.arange(n) + u0) / n, side="right"), n - 1)


def stratified_resample(weights, u):
    n = len(weights)
    cdf = np.cumsum(weights)
    cdf /= cdf[-1]
    return np.minimum(np.searchsorted(cdf, (np.arange(n) + u) / n, side="right"), n - 1)
