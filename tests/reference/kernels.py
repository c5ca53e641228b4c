"""Straightforward NumPy references for the C++ kernels: slow, obvious, and the ground truth
the tests hold the core to. Each follows the documented semantics, not the C++ code."""

from __future__ import annotations

import numpy as np


def hsv_bins(frame, mask=None, n_h=10, n_s=10, n_v=10, s_min=0.1, v_min=0.2):
    f = frame.astype(np.int64)
    b, g, r = f[..., 0], f[..., 1], f[..., 2]
    mx = np.maximum(r, np.maximum(g, b))
    mn = np.minimum(r, np.minimum(g, b))
    v = mx / 255.0
    s = np.where(mx > 0, (mx - mn) / np.maximum(mx, 1), 0.0)
    d = np.maximum(mx - mn, 1).astype(np.float64)
    h = np.where(
        mx == r,
        60.0 * (g - b) / d,
        np.where(mx == g, 60.0 * (b - r) / d + 120.0, 60.0 * (r - g) / d + 240.0),
    )
    h = np.where((mx == r) & (h < 0), h + 360.0, h)
    colour = (s > s_min) & (v > v_min)
    hb = np.minimum((h * n_h / 360.0).astype(np.int64), n_h - 1)
    sb = np.minimum((s * n_s).astype(np.int64), n_s - 1)
    vb = np.minimum((v * n_v).astype(np.int64), n_v - 1)
    out = np.where(colour, hb * n_s + sb, n_h * n_s + vb)
    if mask is not None:
        out = np.where(np.asarray(mask) == 0, -1, out)
    return out.astype(np.int16)


def box_range(cx, cy, w, h, rows, cols):
    x0 = max(0, int(np.floor(cx - w / 2 + 0.5)))
    x1 = min(cols, int(np.floor(cx + w / 2 + 0.5)))
    y0 = max(0, int(np.floor(cy - h / 2 + 0.5)))
    y1 = min(rows, int(np.floor(cy + h / 2 + 0.5)))
    return x0, x1, y0, y1


def lattice_step(w, h, min_samples):
    """floor(sqrt(w h / min_samples)) from 4 min_samples pixels on, else 1; at most 64, and at
    most half the shorter side (at least 1)."""
    area = w * h
    if min_samples <= 0 or not area >= 4 * min_samples or not np.isfinite(area):
        return 1
    k = min(np.floor(np.sqrt(area / min_samples)), max(1.0, np.floor(0.5 * min(w, h))))
    return min(64, int(k))


def box_histograms(bins, n_bins, boxes, kernel="uniform", step=1):
    """Histograms of the boxes' pixels; with `step` > 1 of the pixels whose column and row are
    multiples of `step` only."""
    rows, cols = bins.shape
    out = np.zeros((len(boxes), n_bins))
    for i, (cx, cy, w, h) in enumerate(boxes):
        x0, x1, y0, y1 = box_range(cx, cy, w, h, rows, cols)
        if x0 >= x1 or y0 >= y1:
            continue
        x0, y0 = -(-x0 // step) * step, -(-y0 // step) * step  # the first lattice column, row
        patch = bins[y0:y1:step, x0:x1:step].astype(np.int64)
        if patch.size == 0:
            continue
        if kernel == "uniform":
            wts = np.ones(patch.shape)
        else:
            ys, xs = np.mgrid[y0:y1:step, x0:x1:step].astype(np.float64)
            dx = (xs - cx) * (2.0 / w if w > 0 else 0.0)
            dy = (ys - cy) * (2.0 / h if h > 0 else 0.0)
            wts = np.maximum(0.0, 1.0 - dy * dy - dx * dx)
        keep = patch >= 0
        hist = np.bincount(patch[keep], weights=wts[keep], minlength=n_bins)
        total = hist.sum()
        if total > 0:
            out[i] = hist / total
    return out


def bhattacharyya_coefficient(hists, ref):
    ref = np.asarray(ref, dtype=np.float64)
    return np.sqrt(np.asarray(hists)) @ np.sqrt(ref / ref.sum())


def bhattacharyya_distance(hists, ref):
    rho = np.clip(bhattacharyya_coefficient(hists, ref), 0.0, 1.0)
    return np.sqrt(1.0 - rho)


def bhattacharyya_weights(hists, ref, lam=20.0):
    d = bhattacharyya_distance(hists, ref)
    logw = -lam * d**2
    w = np.exp(logw - logw.max())
    return w / w.sum()


def _cdf(weights):
    c = np.cumsum(np.asarray(weights, dtype=np.float64))
    c = c / c[-1]  # the sequential total, as the core sums
    c[-1] = 1.0
    return c


def systematic_resample(weights, u0):
    n = len(weights)
    positions = (np.arange(n) + u0) / n
    return np.minimum(np.searchsorted(_cdf(weights), positions, side="right"), n - 1)


def stratified_resample(weights, u):
    n = len(weights)
    positions = (np.arange(n) + np.asarray(u)[:n]) / n
    return np.minimum(np.searchsorted(_cdf(weights), positions, side="right"), n - 1)


def _search(cdf, u):
    """np.searchsorted(cdf, u) (filterpy's search), but a draw of exactly 0 takes the first cdf
    value > 0: never a leading particle of weight 0."""
    u = np.asarray(u)
    return np.where(u > 0, np.searchsorted(cdf, u), np.searchsorted(cdf, 0.0, side="right"))


def multinomial_resample(weights, u):
    n = len(weights)
    return np.minimum(_search(_cdf(weights), np.asarray(u)[:n]), n - 1)


def residual_resample(weights, u):
    w = np.asarray(weights, dtype=np.float64)
    n = len(w)
    nw = n * w / np.cumsum(w)[-1]
    # N w_i within the sum's round-off (about N ulps) of an integer counts as that integer
    copies = np.floor(nw * (1.0 + (n + 2) * np.finfo(np.float64).eps)).astype(np.int64)
    idx = np.repeat(np.arange(n), copies)
    rest = n - len(idx)
    if rest > 0:
        residual = nw - copies
        idx = np.concatenate([idx, np.minimum(_search(_cdf(residual), u[:rest]), n - 1)])
    return idx


def propagate(particles, noise, a, b, sigma, s_min, s_max, use_means=False, m1=None, m2=None):
    p = particles.copy()
    x1 = np.broadcast_to(m1, p[:, :3].shape) if use_means else p[:, :3]
    x2 = np.broadcast_to(m2, p[:, :3].shape) if use_means else p[:, 3:]
    new = np.asarray(a) * x1 + np.asarray(b) * x2 + np.asarray(sigma) * noise
    new[:, 2] = np.clip(new[:, 2], s_min, s_max)
    p[:, 3:] = p[:, :3]
    p[:, :3] = new
    return p


def reseed(box, velocity, w0, h0, noise, pos_sd, s_sd, s_min, s_max):
    """Particles (N, 6), weights (N,) and means (2, 3) re-seeded around `box` (cx, cy, w, h)."""
    cx, cy, w, h = box
    vx, vy = velocity
    s0 = np.clip(np.sqrt((w / w0) * (h / h0)), s_min, s_max)
    p = np.empty((len(noise), 6))
    p[:, 0] = cx + pos_sd * noise[:, 0]
    p[:, 1] = cy + pos_sd * noise[:, 1]
    p[:, 2] = np.clip(s0 + s_sd * noise[:, 2], s_min, s_max)
    p[:, 3] = p[:, 0] - vx
    p[:, 4] = p[:, 1] - vy
    p[:, 5] = p[:, 2]
    means = np.array([[cx, cy, s0], [cx - vx, cy - vy, s0]])
    return p, np.full(len(noise), 1.0 / len(noise)), means


def association_cost(
    track_boxes, heights, coasted, rho, boxes, match_distance, colour_weight, match_iou, forbidden
):
    """The gated pairing cost of tracks and detections, as pftrack's associate computed it."""
    a, b = track_boxes[:, None, :], boxes[None, :, :]
    ax1, ay1 = a[..., 0] + a[..., 2], a[..., 1] + a[..., 3]
    bx1, by1 = b[..., 0] + b[..., 2], b[..., 1] + b[..., 3]
    iw = np.maximum(np.minimum(ax1, bx1) - np.maximum(a[..., 0], b[..., 0]), 0.0)
    ih = np.maximum(np.minimum(ay1, by1) - np.maximum(a[..., 1], b[..., 1]), 0.0)
    inter = iw * ih
    union = a[..., 2] * a[..., 3] + b[..., 2] * b[..., 3] - inter
    iou = np.divide(inter, union, out=np.zeros(inter.shape), where=union > 0)
    tc = track_boxes[:, :2] + track_boxes[:, 2:] / 2
    dc = boxes[:, :2] + boxes[:, 2:] / 2
    dx, dy = tc[:, 0:1] - dc[:, 0], tc[:, 1:2] - dc[:, 1]
    dist = np.sqrt(dx * dx + dy * dy)
    radius = match_distance * heights * (1.0 + 0.25 * np.minimum(coasted, 8))
    cost = (1.0 - iou) + colour_weight * (1.0 - rho) + np.minimum(dist / radius[:, None], 2.0)
    gate = (iou >= match_iou) | (dist <= radius[:, None])
    return np.where(gate, cost, forbidden)


def sis_step(
    particles,
    weights,
    means,
    bins,
    n_bins,
    ref,
    w0,
    h0,
    a,
    b,
    sigma,
    s_min,
    s_max,
    use_means,
    lam,
    kernel,
    u0,
    normals,
    min_samples=0,
):
    """One SIS step given the draws (u0 for resampling, (N, 3) normals)."""
    idx = systematic_resample(weights, u0)
    p = particles[idx]
    n = len(p)
    step = lattice_step(means[0][2] * w0, means[0][2] * h0, min_samples)
    p = propagate(p, normals, a, b, sigma, s_min, s_max, use_means, means[0], means[1])
    boxes = np.column_stack([p[:, 0], p[:, 1], p[:, 2] * w0, p[:, 2] * h0])
    hists = box_histograms(bins, n_bins, boxes, kernel, step)
    rho = bhattacharyya_coefficient(hists, ref)
    logw = np.log(np.full(n, 1.0 / n)) - lam * (1.0 - np.clip(rho, 0, 1))
    w = np.exp(logw - logw.max())
    w /= w.sum()
    mean = w @ p[:, :3] / w.sum()
    return p, w, mean, p[np.argmax(w), :3]
