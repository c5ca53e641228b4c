"""Straightforward NumPy references of the detection kernels (pftrack._core.BackgroundModel)."""

from __future__ import annotations

import numpy as np


def hsv_bin_reference(bgr: np.ndarray, n_h=10, n_s=10, n_v=10, s_min=0.1, v_min=0.2) -> np.ndarray:
    """hsv_bin_of, vectorised in float64: bins (H, W) int16."""
    b, g, r = (bgr[..., i].astype(np.int64) for i in range(3))
    mx = np.maximum(r, np.maximum(g, b))
    mn = np.minimum(r, np.minimum(g, b))
    v = mx / 255.0
    s = np.where(mx > 0, (mx - mn) / np.maximum(mx, 1), 0.0)
    d = np.maximum(mx - mn, 1).astype(np.float64)
    with np.errstate(invalid="ignore"):
        h_r = 60.0 * (g - b) / d
        h_r = np.where(h_r < 0.0, h_r + 360.0, h_r)
        h_g = 60.0 * (b - r) / d + 120.0
        h_b = 60.0 * (r - g) / d + 240.0
    h = np.where(mx == r, h_r, np.where(mx == g, h_g, h_b))
    hb = np.minimum((h * n_h / 360.0).astype(np.int64), n_h - 1)
    sb = np.minimum((s * n_s).astype(np.int64), n_s - 1)
    vb = np.minimum((v * n_v).astype(np.int64), n_v - 1)
    colour = (s > s_min) & (v > v_min)
    return np.where(colour, hb * n_s + sb, n_h * n_s + vb).astype(np.int16)


class BackgroundReference:
    """The algorithm of BackgroundModel, one NumPy step per stage, float32 like the C++."""

    def __init__(
        self,
        alpha=0.05,
        alpha_fg=0.005,
        n_learn=30,
        k_noise=4.0,
        t_min=25.0,
        t_max=60.0,
        low_ratio=0.5,
        shadow_lo=0.5,
        shadow_chroma=0.03,
    ):
        self.alpha, self.alpha_fg, self.k_noise = alpha, alpha_fg, k_noise
        self.n_learn = n_learn
        self.frame_count = 0
        self.t_min, self.t_max, self.low_ratio = t_min, t_max, low_ratio
        self.shadow_lo, self.shadow_chroma = shadow_lo, shadow_chroma
        self.background = None
        self.previous = None
        self.threshold = t_min
        self.threshold_scale = 1.0

    def bounds(self) -> tuple[float, float]:
        """The threshold's bounds: t_min, t_max times threshold_scale, at most 255."""
        s = self.threshold_scale
        return min(s * self.t_min, 255.0), min(s * self.t_max, 255.0)

    def set_threshold_scale(self, s: float) -> None:
        """BackgroundModel.set_threshold_scale: new bounds; T scaled by s / s_old, clamped."""
        t = self.threshold * (s / self.threshold_scale)
        self.threshold_scale = s
        lo, hi = self.bounds()
        self.threshold = min(max(t, lo), hi)

    def apply(
        self, frame: np.ndarray, hold: np.ndarray | None = None
    ) -> tuple[np.ndarray, np.ndarray]:
        bins = hsv_bin_reference(frame)
        f = frame.astype(np.float32)
        if self.background is None:
            self.background = f.copy()
            self.previous = frame.copy()
            self.threshold = self.bounds()[0]
            self.frame_count = 1
            return bins, np.zeros(frame.shape[:2], np.uint8)
        bg = self.background
        t = np.float32(self.threshold)
        t_low = np.float32(self.low_ratio * self.threshold)
        e = f - bg
        d_bg = np.abs(e).max(axis=2)
        d_prev = np.abs(frame.astype(np.int32) - self.previous.astype(np.int32)).max(axis=2)
        cand = (d_bg > t) | ((d_prev.astype(np.float32) > t) & (d_bg > t_low))
        s_i = f[..., 0] + f[..., 1] + f[..., 2]
        s_b = bg[..., 0] + bg[..., 1] + bg[..., 2]
        tol = np.float32(self.shadow_chroma) * s_i * s_b
        chroma_ok = np.ones(d_bg.shape, bool)
        for c in range(3):
            chroma_ok &= np.abs(f[..., c] * s_b - bg[..., c] * s_i) <= tol
        shadow = (
            cand & (s_i < s_b) & (s_i >= np.float32(self.shadow_lo) * s_b) & (s_i > 0) & chroma_ok
        )
        fore = cand & ~shadow
        k = self.frame_count + 1  # this frame's number
        if k <= self.n_learn:
            a_bg = a_fg = max(1.0 / k, self.alpha)
        else:
            a_bg, a_fg = self.alpha, self.alpha_fg
        a_cand = np.float32(a_fg) if hold is None else np.where(hold != 0, 0, a_fg)
        a = np.where(cand, a_cand, np.float32(a_bg)).astype(np.float32)[..., None]
        self.frame_count = k
        self.background = bg + a * e
        self.previous = frame.copy()
        hist = np.bincount(np.minimum(d_bg.astype(np.int32), 255).ravel(), minlength=256)
        self.hist = hist  # BackgroundModel.difference_histogram
        half = 0.5 * d_bg.size
        cum = np.concatenate([[0], np.cumsum(hist)])
        i = int(np.searchsorted(cum[1:], half))  # first bin whose cumulative count >= half
        median = i + (half - cum[i]) / hist[i]
        lo, hi = self.bounds()
        self.threshold = min(max(self.k_noise * median, lo), hi)
        return bins, np.select([fore, shadow], [255, 127], 0).astype(np.uint8)


def _edge_magnitudes_reference(img: np.ndarray, band: np.ndarray) -> np.ndarray:
    """max_c |Sobel(Gaussian 5x5, sigma 1.5)(img_c)| at the `band` pixels (row-major order),
    reflect-101 borders."""
    x = np.arange(-2, 3, dtype=np.float64)
    g = np.exp(-(x * x) / (2 * 1.5**2))
    g /= g.sum()
    a = np.asarray(img, np.float64)
    h, w = a.shape[:2]
    p = np.pad(a, ((0, 0), (2, 2), (0, 0)), mode="reflect")  # NumPy "reflect" is reflect-101
    a = sum(g[k] * p[:, k : k + w] for k in range(5))
    p = np.pad(a, ((2, 2), (0, 0), (0, 0)), mode="reflect")
    a = sum(g[k] * p[k : k + h] for k in range(5))
    p = np.pad(a, ((1, 1), (1, 1), (0, 0)), mode="reflect")
    dx = p[:, 2:] - p[:, :-2]  # (h + 2, w, 3)
    dy = p[2:] - p[:-2]  # (h, w + 2, 3)
    gx = dx[:-2] + 2 * dx[1:-1] + dx[2:]
    gy = dy[:, :-2] + 2 * dy[:, 1:-1] + dy[:, 2:]
    return np.sqrt((gx * gx + gy * gy).max(axis=2))[band]


def edge_support_reference(
    frame: np.ndarray,
    background: np.ndarray,
    mask: np.ndarray,
    boxes: np.ndarray,
    statistic: str = "ratio",
) -> np.ndarray:
    """The ghost test (BackgroundModel.edge_support) in float64 NumPy, no OpenCV.

    ``"ratio"``: summed frame magnitudes over the summed frame-plus-background ones on the
    boundary band; ``"vote"``: the share of band pixels where the frame's magnitude is larger.
    """
    out = np.full(len(boxes), 0.5)
    rows, cols = mask.shape
    for k, (x, y, w, h) in enumerate(np.asarray(boxes, np.float64).reshape(-1, 4)):
        x0, y0 = max(int(x) - 4, 0), max(int(y) - 4, 0)
        x1, y1 = min(int(x + w) + 4, cols), min(int(y + h) + 4, rows)
        if x1 - x0 < 3 or y1 - y0 < 3:
            continue
        m = mask[y0:y1, x0:x1] > 0
        hh, ww = m.shape
        lo = np.pad(m, 1, constant_values=False)  # dilation: outside is background
        hi = np.pad(m, 1, constant_values=True)  # erosion: outside is foreground
        dil = np.zeros_like(m)
        ero = np.ones_like(m)
        for dy in range(3):
            for dx in range(3):
                dil |= lo[dy : dy + hh, dx : dx + ww]
                ero &= hi[dy : dy + hh, dx : dx + ww]
        band = dil & ~ero
        if not band.any():
            continue
        m_f = _edge_magnitudes_reference(frame[y0:y1, x0:x1], band)
        m_b = _edge_magnitudes_reference(background[y0:y1, x0:x1], band)
        if statistic == "vote":
            out[k] = float(np.mean(m_f > m_b))
            continue
        e_f, e_b = float(m_f.sum()), float(m_b.sum())
        if e_f + e_b > 0:
            out[k] = e_f / (e_f + e_b)
    return out


def median_frames_reference(frames: list[np.ndarray]) -> np.ndarray:
    """Per-pixel median (H, W, 3) float32 of uint8 frames: a sort, the middle one(s)."""
    s = np.sort(np.stack(frames).astype(np.float64), axis=0)
    m = len(frames)
    return ((s[(m - 1) // 2] + s[m // 2]) / 2).astype(np.float32)


def morphology_reference(src: np.ndarray, element: np.ndarray, op: str) -> np.ndarray:
    """Grey erosion (``"erode"``) or dilation (``"dilate"``) of `src` by `element`, in NumPy.

    dst(y, x) = min or max over the element's set pixels (dy, dx), taken about its centre
    (kh // 2, kw // 2), of src(y + dy, x + dx); pixels outside the image never win (padded with
    255 for an erosion, 0 for a dilation): cv2.erode / cv2.dilate with their default border.
    """
    kh, kw = element.shape
    ay, ax = kh // 2, kw // 2
    fill = 255 if op == "erode" else 0
    pad = np.full((src.shape[0] + kh, src.shape[1] + kw), fill, np.uint8)
    pad[ay : ay + src.shape[0], ax : ax + src.shape[1]] = src
    reduce = np.minimum if op == "erode" else np.maximum
    out = np.full(src.shape, fill, np.uint8)
    for dy, dx in zip(*np.nonzero(element), strict=True):
        out = reduce(out, pad[dy : dy + src.shape[0], dx : dx + src.shape[1]])
    return out


def close_mask_reference(mask: np.ndarray, element: np.ndarray) -> np.ndarray:
    """The closing of `mask` by `element` (a dilation, then an erosion), in NumPy."""
    return morphology_reference(morphology_reference(mask, element, "dilate"), element, "erode")


def open_mask_reference(mask: np.ndarray, element: np.ndarray) -> np.ndarray:
    """The opening of `mask` by `element` (an erosion, then a dilation), in NumPy."""
    return morphology_reference(morphology_reference(mask, element, "erode"), element, "dilate")


def scale_reference(background: np.ndarray, gain: float) -> np.ndarray:
    """BackgroundModel.scale: background * float32(gain), clipped to 255, in float32."""
    return np.minimum(background.astype(np.float32) * np.float32(gain), np.float32(255))
