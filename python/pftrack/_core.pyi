# Hand-written stubs for the compiled module pftrack._core (cpp/bindings/*.cpp).
# Checked by tests/test_stubs.py with `python -m mypy.stubtest pftrack._core`: keep in step.
# Shapes and dtypes are in the comments; every array argument is converted to the dtype shown
# (one copy when it differs) unless marked "in place", which must already be C-contiguous
# float64 and is written without a copy.
from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any, Literal, NoReturn, overload

import numpy as np
from numpy.typing import ArrayLike, NDArray

_F64 = NDArray[np.float64]
_I32 = NDArray[np.int32]

class BinnedImage:
    """A frame's colour-bin index per pixel (-1: never counted)."""

    # bins (H, W) int16, every value in [-1, n_bins)
    def __init__(self, bins: ArrayLike, n_bins: int) -> None: ...
    def __copy__(self) -> BinnedImage: ...  # every bin computed
    def __deepcopy__(self, memo: dict[int, object]) -> BinnedImage: ...
    def __reduce__(self) -> tuple[type[BinnedImage], tuple[NDArray[np.int16], int]]: ...
    @property
    def n_bins(self) -> int: ...
    @property
    def shape(self) -> tuple[int, int]: ...  # (H, W)
    @property
    def bins(self) -> NDArray[np.int16]: ...  # (H, W) int16, read-only view
    @property
    def tiles_pending(self) -> int: ...  # tiles of 16 x 32 pixels a lazy image has not binned

class BackgroundModel:
    """Adaptive background + frame difference + threshold, fused with HSV binning."""

    def __init__(
        self,
        alpha: float = 0.05,
        alpha_fg: float = 0.005,
        n_learn: int = 30,
        k_noise: float = 4.0,
        t_min: float = 25.0,
        t_max: float = 60.0,
        low_ratio: float = 0.5,
        shadow_lo: float = 0.5,
        shadow_chroma: float = 0.03,
        n_h: int = 10,
        n_s: int = 10,
        n_v: int = 10,
        s_min: float = 0.1,
        v_min: float = 0.2,
    ) -> None: ...
    def __copy__(self) -> BackgroundModel: ...  # an independent copy
    def __deepcopy__(self, memo: dict[int, object]) -> BackgroundModel: ...
    # pickled: settings, then what it has learnt (size, counts, threshold, background, ...);
    # __reduce__ gives copyreg.__newobj__ and that state, at every protocol (0 to 5)
    def __getstate__(self, /) -> tuple[object, ...]: ...
    def __setstate__(self, arg0: tuple[object, ...], /) -> None: ...
    def __reduce__(
        self,
    ) -> tuple[
        Callable[..., BackgroundModel], tuple[type[BackgroundModel]], tuple[object, ...]
    ]: ...
    # frame (H, W, 3) uint8 BGR -> (BinnedImage of all pixels, raw mask (H, W) uint8:
    # 255 foreground, 127 shadow, 0 background)
    # bins=False: no bins (None), for a caller that bins only the pixels it keeps (hsv_bins);
    # hold (H, W) uint8/bool: candidates where it is not 0 are not learnt (rate 0)
    @overload
    def apply(
        self, frame: NDArray[np.uint8], bins: Literal[True] = True, hold: ArrayLike | None = None
    ) -> tuple[BinnedImage, NDArray[np.uint8]]: ...
    @overload
    def apply(
        self, frame: NDArray[np.uint8], bins: Literal[False], hold: ArrayLike | None = None
    ) -> tuple[None, NDArray[np.uint8]]: ...
    @overload
    def apply(
        self, frame: NDArray[np.uint8], bins: bool, hold: ArrayLike | None = None
    ) -> tuple[BinnedImage | None, NDArray[np.uint8]]: ...
    # background += rate (frame - background) where mask != 0
    def blend(self, frame: NDArray[np.uint8], mask: ArrayLike, rate: float) -> None: ...
    # median of sum(frame) / sum(background) over every step-th row and column (pixels whose
    # background sum is >= min_sum): the frame's global gain; 1 when no pixel qualifies
    def global_gain(
        self, frame: NDArray[np.uint8], step: int = 4, min_sum: float = 30.0
    ) -> float: ...
    # (sampled_mean(frame, step), global_gain(frame, step, min_sum)): the same two floats, the
    # sampled pixels read once
    def mean_and_gain(
        self, frame: NDArray[np.uint8], step: int = 4, min_sum: float = 30.0
    ) -> tuple[float, float]: ...
    # background *= gain (float32, clipped to 255)
    def scale(self, gain: float) -> None: ...
    # threshold bounds [s t_min, s t_max] (at most 255); threshold *= s / old s, clamped
    def set_threshold_scale(self, s: float) -> None: ...
    @property
    def threshold_scale(self) -> float: ...
    # ghost test: (K,) share of each box's (K, 4) mask-boundary edges held by the frame
    # (statistic 'ratio': of the summed magnitudes, 'vote': of the band pixels)
    def edge_support(
        self,
        frame: NDArray[np.uint8],
        mask: ArrayLike,
        boxes: ArrayLike,
        statistic: str = "ratio",
    ) -> NDArray[np.float64]: ...
    def set_background(self, background: ArrayLike) -> None: ...  # (H, W, 3) BGR, float32
    def reset(self) -> None: ...
    @property
    def initialized(self) -> bool: ...
    @property
    def frame_count(self) -> int: ...
    @property
    def threshold(self) -> float: ...
    @property
    def n_bins(self) -> int: ...
    @property
    def shape(self) -> tuple[int, int] | None: ...  # (H, W), or None before the first frame
    @property
    def background(self) -> NDArray[np.float32] | None: ...  # (H, W, 3) BGR copy, or None before
    @property
    def difference_histogram(self) -> NDArray[np.int64]: ...  # (256,) int64
    @property
    def alpha(self) -> float: ...
    @property
    def alpha_fg(self) -> float: ...
    @property
    def n_learn(self) -> int: ...
    @property
    def k_noise(self) -> float: ...
    @property
    def t_min(self) -> float: ...
    @property
    def t_max(self) -> float: ...
    @property
    def low_ratio(self) -> float: ...
    @property
    def shadow_lo(self) -> float: ...
    @property
    def shadow_chroma(self) -> float: ...

class RJMCMCTracker:
    """Reversible-jump MCMC joint tracker (birth, death, update, swap)."""

    def __init__(
        self,
        burn_in: int = 50,
        n_samples: int = 200,
        p_birth: float = 0.1,
        p_death: float = 0.1,
        p_update: float = 0.7,
        p_swap: float = 0.1,
        a: ArrayLike = ...,  # (3,) AR2 coefficients
        b: ArrayLike = ...,  # (3,)
        sigma: ArrayLike = ...,  # (3,) noise std of cx, cy, s
        s_min: float = 0.2,
        s_max: float = 5.0,
        lam: float = 10.0,
        kernel: str = "uniform",
        interaction: float = 10.0,
        coverage: float = 20.0,
        background_penalty: float = 0.25,
        birth_prior: float = 2.0,
        survival: float = 0.95,
        birth_sigma_xy: float = 3.0,
        birth_sigma_s: float = 0.05,
        birth_eps: float = 0.02,
        birth_gate: float = 0.1,  # no newborn on a candidate overlapping a kept identity this much
        detection: float = 20.0,  # weight of an object's best IoU with a candidate in log π
        min_samples: float = 0.0,  # large boxes counted on a lattice (lattice_step); 0: every pixel
    ) -> None: ...
    def __reduce__(self) -> NoReturn: ...  # TypeError: the chain cannot be pickled
    # mask (H, W) uint8/bool; candidates (K, 4) cx, cy, w, h; candidate_hists (K, B) or None
    # (the default: computed from the image). seed and step have no default: after a default,
    # a stub takes them by keyword only (the binding takes them by position too).
    def step(
        self,
        image: BinnedImage,
        mask: NDArray[Any],
        candidates: _F64,
        candidate_hists: ArrayLike | None = None,
        *,
        seed: int,
        step: int,
    ) -> dict[str, Any]: ...
    @property
    def tracks(self) -> list[Any]: ...
    def warp(self, affine: _F64) -> None: ...  # (2, 3) similarity, previous frame to this one
    @property
    def next_id(self) -> int: ...
    # tracks: dicts as .tracks gives them (id, w0, h0, ref (B,), parents (N_i, 6), existence)
    def restore(self, tracks: list[Any], next_id: int) -> None: ...
    def prepare(
        self,
        image: BinnedImage,
        mask: NDArray[Any],
        candidates: _F64,  # (K, 4)
        candidate_hists: ArrayLike | None = None,  # (K, B)
    ) -> None: ...
    def slots(self) -> list[Any]: ...
    # slots (M,) int32, states (M, 6) float64
    def log_target(self, slots: _I32, states: _F64) -> float: ...
    def log_acceptance(
        self,
        move: str,
        slots: _I32,
        states: _F64,
        to_slots: _I32,
        to_states: _F64,
        slot: int = -1,
    ) -> float: ...
    def propose(
        self, move: str, slots: _I32, states: _F64, seed: int, step: int, k: int
    ) -> tuple[_I32, _F64, int] | None: ...

# --- colour: binning, histograms, likelihood ---------------------------------------------
# frame (H, W, 3) uint8 BGR; mask (H, W) uint8/bool, 0 = background (bin -1)
def hsv_bins(
    frame: NDArray[np.uint8],
    mask: NDArray[Any] | None = None,
    n_h: int = 10,
    n_s: int = 10,
    n_v: int = 10,
    s_min: float = 0.1,
    v_min: float = 0.2,
    lazy: bool = False,  # tiles binned when first read (same bins); .bins bins the rest
) -> BinnedImage: ...

# per-pixel median (H, W, 3) float32 of (H, W, 3) uint8 frames (numpy.median's values), in bands
# of rows on up to `threads` threads (the same values with any number)
def median_frames(frames: Sequence[NDArray[np.uint8]], threads: int = 1) -> NDArray[np.float32]: ...
def mask_bins(binned: BinnedImage, mask: NDArray[Any]) -> BinnedImage: ...  # mask (H, W)

# mean level of every step-th pixel of every step-th row of a (H, W, 3) uint8 frame, any
# strides: numpy's frame[::step, ::step].mean(), the same double
def sampled_mean(frame: NDArray[np.uint8], step: int) -> float: ...

# testing hook: whether background.hpp's hand-written AVX2 passes may run (BackgroundModel.apply's
# row pass, hsv_bins' rows, clean_mask / open_mask / close_mask's bit planes; the portable loops
# otherwise, the same results); returns the previous setting, process-wide
def _set_avx2(allowed: bool) -> bool: ...

# closing of a (H, W) uint8/bool mask by a (kh, kw) element whose rows are single runs,
# as cv2.morphologyEx(MORPH_CLOSE) -> new (H, W) uint8
def close_mask(mask: NDArray[Any], element: NDArray[Any]) -> NDArray[np.uint8]: ...

# opening (an erosion, then a dilation), likewise, as cv2.morphologyEx(MORPH_OPEN)
def open_mask(mask: NDArray[Any], element: NDArray[Any]) -> NDArray[np.uint8]: ...

# opening by open_element, then closing by close_element, in one call -> new (H, W) uint8;
# a mask of 0 and one or two levels (255 the upper) as bit planes, others byte by byte; the
# planes cover only the blocks of rows near a non-zero byte (the others are 0)
def clean_mask(
    mask: NDArray[Any], open_element: NDArray[Any], close_element: NDArray[Any]
) -> NDArray[np.uint8]: ...

# boxes (K, 4) float64 cx, cy, w, h -> (K, B) float64, rows sum to 1 (0 for an empty box)
# method "auto" | "direct" | "integral", as box_weights (the same histograms on every path)
def box_histograms(
    image: BinnedImage, boxes: _F64, kernel: str = "uniform", method: str = "auto"
) -> _F64: ...

# boxes (K, 4), ref (B,) -> (K,) weights ~ exp(-lam D^2), summing to 1 (fused histograms);
# method "auto" | "direct" | "integral" (uniform-kernel counts from integral histograms of
# groups of overlapping boxes; the same weights on every path); step > 1: only the pixels whose
# column and row are multiples of step are counted
def box_weights(
    image: BinnedImage,
    boxes: _F64,
    ref: _F64,
    lam: float = 20.0,
    kernel: str = "uniform",
    method: str = "auto",
    step: int = 1,
) -> _F64: ...

# hists (K, B) float64, ref (B,) -> (K,)
def bhattacharyya_coefficient(hists: _F64, ref: _F64) -> _F64: ...
def bhattacharyya_distance(hists: _F64, ref: _F64) -> _F64: ...
def bhattacharyya_weights(hists: _F64, ref: _F64, lam: float = 20.0) -> _F64: ...

# --- assignment: cost (R, C) float64, +inf forbids a pair -> (rows, cols) int32 ----------
# gated pairing cost (T, D) of track boxes (T, 4) and detection boxes (D, 4), xywh
def association_cost(
    track_boxes: ArrayLike,
    heights: ArrayLike,
    coasted: ArrayLike,
    rho: ArrayLike,
    boxes: ArrayLike,
    match_distance: float,
    colour_weight: float,
    match_iou: float,
    forbidden: float,
) -> _F64: ...
def linear_sum_assignment(cost: _F64) -> tuple[_I32, _I32]: ...  # rows ascending
def sparse_assignment(
    r: ArrayLike, c: ArrayLike, cost: ArrayLike, n_ends: int, n_starts: int, unjoined: float
) -> tuple[NDArray[np.int64], NDArray[np.int64]]: ...  # ends ascending
def overlap_pairs(
    a: ArrayLike, b: ArrayLike
) -> tuple[NDArray[np.int64], NDArray[np.int64]]: ...  # (i, j) increasing
def padded_assignment(cost: ArrayLike, tau: float, forbidden: float) -> tuple[_I32, _I32]: ...

# --- box refinement: boxes (K, 4) left, top, w, h; mask (H, W) uint8 or bool -> (K, 4) -----
def refine_boxes(
    boxes: _F64,
    mask: NDArray[Any],
    fraction: float,
    min_cover: float,
    leg_fill: float | None = ...,
    min_height: float = ...,
) -> _F64: ...

# --- blob pass: mask (H, W) uint8 0/255 -> boxes (K, 4) left, top, w, h and fills (K,) -------
# size_lines (2, 2) [[h_slope, h_intercept], [w_slope, w_intercept]] in the foot row, or None
def blob_boxes(
    mask: NDArray[np.uint8] | NDArray[np.bool_],
    min_area: float,
    max_area: float,
    min_aspect: float,
    max_aspect: float,
    min_fill: float,
    person_aspect: float,
    size_lines: _F64 | None,
    split_ratio: float,
    split_max_height: float,
    merge_slack: float,
    split_valley: float = ...,
) -> tuple[_F64, _F64]: ...  # unsorted (outer contours' order)
def split_count(
    boxes: _F64, size_lines: _F64, split_ratio: float, split_max_height: float
) -> NDArray[np.int64]: ...  # (K,)
def merge_fragments(boxes: _F64, size_lines: _F64, merge_slack: float) -> list[list[int]]: ...
def size_fit(samples: _F64) -> _F64: ...  # (n, 3) foot y, h, w -> (2, 2) size lines

# short boxes (K, 4) extended down through rows of mask != 0, to the expected foot row
def extend_legs(
    mask: NDArray[np.uint8] | NDArray[np.bool_],
    boxes: _F64,
    size_lines: _F64,
    min_height: float,
    row_fill: float,
) -> _F64: ...  # (K, 4)
def theil_sen(x: _F64, y: _F64) -> tuple[float, float]: ...  # x, y (n,) -> slope, intercept

# --- resampling: weights (N,) float64 >= 0 -> indices (N,) int32 --------------------------
def systematic_resample(weights: _F64, u0: float) -> _I32: ...  # u0 in [0, 1)
def stratified_resample(weights: _F64, u: _F64) -> _I32: ...  # u (N,) in [0, 1)
def multinomial_resample(weights: _F64, u: _F64) -> _I32: ...  # draw order
def residual_resample(weights: _F64, u: _F64) -> _I32: ...  # first R of u used

# --- dynamics and filter steps --------------------------------------------------------------
# particles (N, 6) in place; noise (N, 3) N(0, 1); a, b, sigma, mean_prev, mean_prev2 (3,)
def propagate(
    particles: _F64,
    noise: _F64,
    a: ArrayLike,
    b: ArrayLike,
    sigma: ArrayLike,
    s_min: float,
    s_max: float,
    use_means: bool,
    mean_prev: ArrayLike,
    mean_prev2: ArrayLike,
) -> None: ...

# particles (N, 6), weights (N,) -> (mean (3,), map (3,), map_index)
def estimate(particles: _F64, weights: _F64) -> tuple[_F64, _F64, int]: ...

# particles (N, 6), weights (N,), means (2, 3): in place; ref (B,); returns a dict of estimates
def sis_step(
    particles: _F64,
    weights: _F64,
    means: _F64,
    image: BinnedImage,
    ref: _F64,
    w0: float,
    h0: float,
    a: ArrayLike,
    b: ArrayLike,
    sigma: ArrayLike,
    s_min: float,
    s_max: float,
    use_means: bool,
    lam: float,
    kernel: str,
    resample: bool,
    seed: int,
    step: int,
    min_samples: float = 0.0,
) -> dict[str, Any]: ...

# sis_step for K objects on one image, one call (GIL released): lists of K particles (N_k, 6),
# weights (N_k,), means (2, 3) updated in place; returns (K, 11): mean (3), map (3), map_index,
# ess, rho_max, rho_mean, fg_mean
def sis_step_batch(
    particles: list[_F64],
    weights: list[_F64],
    means: list[_F64],
    image: BinnedImage,
    refs: list[_F64],
    w0: ArrayLike,
    h0: ArrayLike,
    a: ArrayLike,
    b: ArrayLike,
    sigma: ArrayLike,
    s_min: float,
    s_max: float,
    use_means: bool,
    lam: float,
    kernel: str,
    resample: bool,
    seeds: list[int],
    steps: list[int],
    min_samples: float = 0.0,
) -> _F64: ...

# lists of K particles (N_k, 6), weights (N_k,), means (2, 3) re-seeded in place around boxes
# (K, 4) cx, cy, w, h with velocities (K, 2); noise (sum N_k, 3), object after object
def reseed_batch(
    particles: list[_F64],
    weights: list[_F64],
    means: list[_F64],
    boxes: ArrayLike,
    velocities: ArrayLike,
    w0: ArrayLike,
    h0: ArrayLike,
    noise: ArrayLike,
    pos_sd: float,
    s_sd: float,
    s_min: float,
    s_max: float,
) -> None: ...
def centre_predict_tracks(
    tracks: list[Any],
    summary: ArrayLike,
    gains: list[float] | tuple[float, ...],
    colour_noise: float,
    flat_rho: float,
) -> _F64: ...
def centre_follow_tracks(
    tracks: list[Any], boxes: ArrayLike, detection_noise: float, smooth: bool
) -> _F64: ...
def mh_step(
    particles: _F64,
    weights: _F64,
    means: _F64,
    image: BinnedImage,
    ref: _F64,
    w0: float,
    h0: float,
    a: ArrayLike,
    b: ArrayLike,
    sigma: ArrayLike,
    s_min: float,
    s_max: float,
    use_means: bool,
    lam: float,
    kernel: str,
    resample: bool,
    seed: int,
    step: int,
    n_iter: int = 1,
    burn_in: int = 0,
    proposal: str = "dynamics",
    rw_sigma: ArrayLike = ...,  # (3,)
    min_samples: float = 0.0,
) -> dict[str, Any]: ...

# counter-based random streams (CounterRng), for tests and references: (n,) float64
def counter_normals(seed: int, stream: int, n: int) -> _F64: ...
def counter_uniforms(seed: int, stream: int, start: int, n: int) -> _F64: ...

# --- trajectory recovery ----------------------------------------------------------------------
# A (n, n), Q (n, n), H (m, n), Pi_T (m, m), m0 (n,), Pi_0 (n, n), y (m,) goal, T steps
def gdt_solve(
    A: ArrayLike,
    Q: ArrayLike,
    H: ArrayLike,
    Pi_T: ArrayLike,
    m0: ArrayLike,
    Pi_0: ArrayLike,
    y: ArrayLike,
    T: int,
    form: str = "general",
    start_conditioned: bool = True,
) -> dict[str, Any]: ...  # path (T+1, n), eps (T, n, n), cov (T+1, n, n), x0_mean, x0_cov
def gdt_solve_batch(
    problems: list[Any],
    form: str = "general",
    start_conditioned: bool = True,
    paths_only: bool = False,
) -> list[Any]: ...
def gdt_sample(
    A: ArrayLike,
    Q: ArrayLike,
    H: ArrayLike,
    Pi_T: ArrayLike,
    m0: ArrayLike,
    Pi_0: ArrayLike,
    y: ArrayLike,
    T: int,
    n_samples: int,
    seed: int,
    form: str = "general",
    start_conditioned: bool = True,
) -> NDArray[np.float64]: ...  # (n_samples, T+1, n)

# seg_a, seg_b stacked (frame, pos...) rows; a_len, b_len (G,) int32 -> (sum(T_g - 1), m)
def gdt_recover_batch(
    seg_a: _F64,
    a_len: _I32,
    seg_b: _F64,
    b_len: _I32,
    A: ArrayLike,
    Q: ArrayLike,
    H: ArrayLike,
    R: ArrayLike,
    p_init_velocity: float,
    goal: str,
    history: int,
    start_conditioned: bool,
) -> _F64: ...

# z (K, m) -> (m (n,), P (n, n)) after the last observation
def kalman_filter(
    z: ArrayLike,
    A: ArrayLike,
    Q: ArrayLike,
    H: ArrayLike,
    R: ArrayLike,
    m_init: ArrayLike,
    P_init: ArrayLike,
) -> tuple[_F64, _F64]: ...

# z stacked runs (sum lengths,), lengths (R,) int32, q, r (G,) -> (G,) log-likelihoods
def noise_loglik_grid(z: _F64, lengths: _I32, q: _F64, r: _F64) -> _F64: ...

# one coordinate's window z (n,) with NaN where unobserved; gap from index fa to fb; F, Q (d, d),
# d = 2 or 3; p0 (d,) prior variances; stand hypotheses t1, t2 (H,) int32 ((-1, -1) = none)
# -> smoothed gap positions (H, fb - fa - 1), window log-likelihoods (H,)
def gap_mixture(
    z: _F64,
    fa: int,
    fb: int,
    F: _F64,
    Q: _F64,
    r: float,
    p0: _F64,
    t1: _I32,
    t2: _I32,
    v2: float,
) -> tuple[_F64, _F64]: ...

# jobs: (z, fa, fb, model, t1, t2) as gap_mixture's arguments, model an index into F, Q, r, p0,
# v2 (one entry per model); on up to `threads` threads -> [(paths, loglik)] as gap_mixture gives
def gap_mixture_many(
    jobs: Sequence[tuple[_F64, int, int, int, _I32, _I32]],
    F: Sequence[_F64],
    Q: Sequence[_F64],
    r: Sequence[float],
    p0: Sequence[_F64],
    v2: Sequence[float],
    threads: int,
) -> list[tuple[_F64, _F64]]: ...

# z stacked runs (sum lengths,), lengths (R,) int32; F, Q (K * d, d) stacked models, r (K,)
# -> (K,) log-likelihoods (the same on any number of threads)
def state_loglik_batch(
    z: _F64, lengths: _I32, F: _F64, Q: _F64, r: _F64, big: float, threads: int = 1
) -> _F64: ...

# rts_gaps.hpp (register_smoothing.cpp)
# points (P, 3) float64 rows (frame, x, y); offsets (G + 1,) int32 window bounds; n_before (G,)
# int32 points of segment A per window -> (M, 2) smoothed (x, y) of every frame inside every gap
def rts_gaps_batch(
    points: _F64, offsets: _I32, n_before: _I32, q: float, r: float, v0: float
) -> _F64: ...

# z (T, n) float64; has (T,) or (T, n) bool/uint8 (rows without a measurement never read); q, r2
# (n,) -> (T, n) RTS-smoothed positions of independent constant-velocity axes
def rts_smooth(
    z: ArrayLike,
    has: ArrayLike,
    q: ArrayLike,
    r2: ArrayLike,
    velocity_sd: float,
    update_first: bool,
) -> _F64: ...

# --- MOTChallenge text ------------------------------------------------------------------------
# ids (M, 2) float64 integral frame, id; values (M, 8) float64 finite; decimals (M, 8) int64,
# 0..22 ("%.{d}f") or 31 (repr) -> "frame,id,v1,...,v8\n" lines, as Python's % writes them.
# Dtypes are not converted (TypeError); strided arrays are copied once.
def mot_lines(
    ids: NDArray[np.float64], values: NDArray[np.float64], decimals: NDArray[np.int64]
) -> str: ...

# values (n,) float64 -> (n,) int64: the fewest decimals d <= most (0..22) with
# rint(v 10^d) / 10^d == v and |rint(v 10^d)| < limit (<= 2**53), else -1
def fewest_decimals(values: NDArray[np.float64], limit: float, most: int) -> NDArray[np.int64]: ...

# a MOT file's bytes -> its rows (M, 6..10) float64, bit for bit as np.loadtxt reads them, when
# they are of the common layout (numbers only, one separator, the same columns on every line;
# no row: (0, 10)), else None (mot.py's _read_fast then calls np.loadtxt)
def parse_mot_text(text: bytes) -> NDArray[np.float64] | None: ...

# --- square regions (recovery.calibrate._region_blocks) -------------------------------------
# xy (n, 2) float64 finite, points of runs of sizes (runs,) int64 (sum n); centres (squares, 2)
# float64 finite; side finite > 0; work >= 0; decimals 0..22 -> (run, start, length) int64 of
# the stretches inside each square (distances rounded to decimals as np.round rounds them) with
# a point of the run before and after, square by square while the points in their bands of x
# stay within work (the first square always)
def region_blocks(
    xy: NDArray[np.float64],
    sizes: NDArray[np.int64],
    centres: NDArray[np.float64],
    side: float,
    work: int,
    decimals: int,
) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.int64]]: ...

# --- the still camera's measurement (camera.hpp): grey (H, W) uint8; points (N, 2) or (N, 1, 2) --
def still_flow(
    prev: NDArray[np.uint8],
    next: NDArray[np.uint8],
    pts: ArrayLike,
    win_size: int = 11,
    max_count: int = 30,
    epsilon: float = 0.01,
    min_eig: float = 1e-4,
) -> tuple[NDArray[np.float32], NDArray[np.bool_]]: ...  # places (N, 2), followed (N,)
def similarity_fit(src: ArrayLike, dst: ArrayLike) -> _F64 | None: ...  # (2, 3)
def grey_halved(frame: NDArray[np.uint8]) -> NDArray[np.uint8]: ...  # (H, W, 3) -> (H // 2, W // 2)
