"""Colour observation model: HSV bins per pixel, box histograms, Bhattacharyya likelihood.

The histogram has ``Nh*Ns`` colour bins for pixels whose saturation and value exceed
thresholds and ``Nv`` grey bins (by value) for the rest, after Pérez et al. [1]_. Pixels a
foreground mask marks as background are never counted, so an object's histogram is not diluted
by the floor behind it. The likelihood of a candidate box is ``p(z|x) ∝ exp(-λ D²)`` with the
Bhattacharyya distance ``D = sqrt(1 - Σ sqrt(q*(n) q(n)))`` (the first paper's eq. 9-10).

References
----------
.. [1] Pérez, P., Hue, C., Vermaak, J. & Gangnet, M. (2002). Color-based probabilistic tracking.
   ECCV 2002, LNCS 2350, 661-675.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pftrack import _core
from pftrack._check import bgr_array, brief, integer, number, real_array, rectangular, shown

BinnedImage = _core.BinnedImage

__all__ = [
    "BinnedImage",
    "HsvBinning",
    "bhattacharyya_coefficient",
    "bhattacharyya_distance",
    "bhattacharyya_weights",
    "box_histograms",
    "box_weights",
    "hsv_bins",
]


@dataclass(frozen=True)
class HsvBinning:
    """How pixels are binned: ``n_h*n_s`` colour bins plus ``n_v`` grey bins.

    Attributes
    ----------
    n_h, n_s, n_v : int
        Hue, saturation and value (grey) bin counts (default 10 each: 110 bins).
    s_min, v_min : float
        A pixel goes to a colour bin only if its saturation > `s_min` and value > `v_min`
        (both on [0, 1]); otherwise to a grey bin.

    Raises
    ------
    TypeError
        A bin count that is not an int (a bool, a float, a string).
    ValueError
        A bin count outside [1, 64], `s_min` or `v_min` outside [0, 1].
    """

    n_h: int = 10
    n_s: int = 10
    n_v: int = 10
    s_min: float = 0.1
    v_min: float = 0.2

    def __post_init__(self) -> None:
        for name in ("n_h", "n_s", "n_v"):
            integer(getattr(self, name), f"HsvBinning: {name}", 1, 64)
        for name in ("s_min", "v_min"):
            v = number(getattr(self, name), f"HsvBinning: {name}", finite=False)
            if not (0.0 <= v <= 1.0):
                raise ValueError(f"HsvBinning: {name} is {brief(v)}, expected a value in [0, 1]")

    @property
    def n_bins(self) -> int:
        """Total number of bins."""
        return self.n_h * self.n_s + self.n_v


def _frame(frame: ArrayLike, name: str = "frame") -> NDArray[np.uint8]:
    f = bgr_array(frame, name)
    # the core reads packed pixels in rows at a positive stride (a crop of a larger image is
    # fine): anything else, a flipped (``frame[::-1]``) or broadcast frame too, is copied once
    if f.strides[2] != 1 or f.strides[1] != 3 or f.strides[0] <= 0:
        f = np.ascontiguousarray(f)
    return f


def hsv_bins(
    frame: ArrayLike,
    mask: ArrayLike | None = None,
    binning: HsvBinning = HsvBinning(),
    lazy: bool = False,
) -> BinnedImage:
    """Bin every pixel of a BGR uint8 frame once, for all the histograms of that frame.

    Parameters
    ----------
    frame : (H, W, 3) array_like of uint8
        BGR image as OpenCV reads it.
    mask : (H, W) array_like of uint8 or bool, optional
        Foreground mask; zero pixels get bin -1 and are never counted.
    binning : HsvBinning
        Bin counts and thresholds.
    lazy : bool
        Bin on demand: the image keeps a copy of the frame (and mask) and bins each tile of
        16x32 pixels the first time a histogram, weight or filter step reads it, so pixels
        that no box covers are never binned. The bins are the same; ``.bins`` and any copy
        bin every pixel still missing first.

    Returns
    -------
    BinnedImage
        ``.bins`` is the (H, W) int16 bin index per pixel, ``.n_bins`` the bin count.

    Raises
    ------
    TypeError
        A frame that is not uint8 (a uint16 frame's message names the conversion), a mask
        that is not uint8 or bool, a `binning` that is not an :class:`HsvBinning`.
    ValueError
        A frame not of shape (H, W, 3) (a grey or BGRA frame's message names the
        ``cv2.cvtColor`` conversion), an empty frame, or a mask of another size.

    Examples
    --------
    >>> import numpy as np
    >>> from pftrack import hsv_bins
    >>> frame = np.zeros((4, 6, 3), np.uint8)  # black: value 0, grey bin 100 (bins 100-109)
    >>> frame[:, 3:] = (0, 0, 255)  # BGR red: hue 0, saturation 1, colour bin 9
    >>> image = hsv_bins(frame)
    >>> image.n_bins, image.shape, image.bins.dtype
    (110, (4, 6), dtype('int16'))
    >>> image.bins[0]
    array([100, 100, 100,   9,   9,   9], dtype=int16)
    """
    if not isinstance(binning, HsvBinning):
        raise TypeError(f"hsv_bins: binning must be an HsvBinning, got {shown(binning)}")
    fn = "hsv_bins"
    f = _frame(frame, f"{fn}: frame")
    m = None
    if mask is not None:
        m = rectangular(mask, f"{fn}: mask")
        if m.dtype not in (np.uint8, np.bool_):
            raise TypeError(f"{fn}: mask dtype is {m.dtype}, expected uint8 or bool")
        if m.shape != f.shape[:2]:
            raise ValueError(f"{fn}: mask shape is {m.shape}, expected the frame's {f.shape[:2]}")
        m = np.ascontiguousarray(m)
    if not isinstance(lazy, (bool, np.bool_)):
        raise TypeError(f"{fn}: lazy must be a bool, got {type(lazy).__name__}")
    return _core.hsv_bins(
        f, m, binning.n_h, binning.n_s, binning.n_v, binning.s_min, binning.v_min, bool(lazy)
    )


def box_histograms(
    image: BinnedImage, boxes_cxcywh: ArrayLike, kernel: str = "uniform"
) -> NDArray[np.float64]:
    """Normalised colour histograms of boxes.

    Parameters
    ----------
    image : BinnedImage
        From :func:`hsv_bins`.
    boxes_cxcywh : (K, 4) array_like of float
        Boxes as centre x, centre y, width, height in pixels. A box covers the pixels with
        centres in ``[cx - w/2, cx + w/2)`` (rounded half up) and is clipped to the image.
    kernel : {"uniform", "epanechnikov"}
        Pixel weights: all 1, or ``max(0, 1 - r²)`` with r the box-normalised distance to the
        centre (down-weights the background-prone border).

    Returns
    -------
    (K, B) ndarray of float64
        Rows sum to 1; a box with nothing to count (outside the image, or only background)
        gets an all-zero row, whose Bhattacharyya coefficient with any reference is 0.

    Raises
    ------
    TypeError
        `image` is not a :class:`BinnedImage` (the frame itself: bin it with
        :func:`hsv_bins`), the boxes are not real numbers, `kernel` is not a string.
    ValueError
        Boxes not of shape (K, 4) (an empty list is 0 boxes), a value not finite or beyond
        ±1e9 px, a negative width or height, an unknown kernel.

    Notes
    -----
    With the uniform kernel, the counts of many overlapping boxes (one object's particles) may
    come from one integral histogram of their union [1]_ instead of visiting every pixel of
    every box; the counts, hence the histograms, are exactly the same.

    References
    ----------
    .. [1] Porikli, F. (2005). Integral histogram: a fast way to extract histograms in
       Cartesian spaces. CVPR 2005, 829-836.

    Examples
    --------
    >>> import numpy as np
    >>> from pftrack import box_histograms, hsv_bins
    >>> frame = np.zeros((4, 6, 3), np.uint8)
    >>> frame[:, 3:] = (0, 0, 255)  # left half black (bin 100), right half red (bin 9)
    >>> boxes = [[3, 2, 6, 4], [4.5, 2, 3, 4], [100, 100, 4, 4]]  # whole, red half, outside
    >>> h = box_histograms(hsv_bins(frame), boxes)
    >>> h.shape, h.dtype
    ((3, 110), dtype('float64'))
    >>> h[:, [9, 100]]
    array([[0.5, 0.5],
           [1. , 0. ],
           [0. , 0. ]])
    """
    fn = "box_histograms"
    error = not_binned(image, f"{fn}: image")
    if error is not None:
        raise error
    if not isinstance(kernel, str):  # pybind11 would list its signatures
        raise TypeError(f"{fn}: kernel must be 'uniform' or 'epanechnikov', got {shown(kernel)}")
    return _core.box_histograms(image, _boxes(boxes_cxcywh, fn), kernel)


def not_binned(image: object, what: str) -> TypeError | None:
    """The error to raise when `image` is not a :class:`BinnedImage`, or None when it is.

    A frame given as it is read is the likely mistake: the message says to bin it.
    """
    if isinstance(image, BinnedImage):
        return None
    hint = ""
    if isinstance(image, np.ndarray) and image.ndim == 3:
        hint = " (a frame? bin it first)"
    return TypeError(
        f"{what} must be a BinnedImage from hsv_bins(frame), got {type(image).__name__}{hint}"
    )


def _boxes(boxes_cxcywh: ArrayLike, fn: str) -> NDArray[np.float64]:
    """Boxes as a row-major (K, 4) float64 array the core takes (one box (4,) is K = 1).

    The core checks the values (finite, within ±1e9 px, w, h >= 0) and names the first bad box.
    """
    b = real_array(boxes_cxcywh, f"{fn}: boxes")
    if b.ndim == 1 and b.size == 0:
        return np.zeros((0, 4))  # [] is no box, as np.zeros((0, 4))
    b = np.atleast_2d(b)
    if b.ndim != 2:
        raise ValueError(f"{fn}: boxes must have shape (K, 4) (cx, cy, w, h), got {b.shape}")
    if b.shape[1] != 4:
        raise ValueError(f"{fn}: boxes cols is {b.shape[1]}, expected 4 (cx, cy, w, h)")
    return np.ascontiguousarray(b)


def _histograms(hists: ArrayLike, fn: str) -> NDArray[np.float64]:
    """`hists` as a row-major (K, B) float64 array (the core normalises each row and checks it)."""
    h = np.atleast_2d(real_array(hists, f"{fn}: hists"))
    if h.ndim != 2:
        raise ValueError(
            f"{fn}: hists must have shape (K, B), one histogram per row, got {h.shape}"
        )
    return np.ascontiguousarray(h)


def _reference(ref: ArrayLike, fn: str) -> NDArray[np.float64]:
    """`ref` as a (B,) float64 array (the core checks its values)."""
    r = real_array(ref, f"{fn}: ref")
    if r.ndim != 1:
        raise ValueError(f"{fn}: ref must have shape (B,), one histogram, got {r.shape}")
    return np.ascontiguousarray(r)


def _pair(hists: ArrayLike, ref: ArrayLike, fn: str) -> tuple[NDArray[np.float64], ...]:
    """`hists` and `ref` checked (:func:`_histograms`, :func:`_reference`), and their bins alike.

    Bins that differ name both: a number given as `hists` (a NaN) is refused as one, and a
    row length other than `ref`'s says whose length `ref` was held to (was the core's ``ref
    size is 3, expected 1`` for either, a number taken for one 1-bin histogram).
    """
    h, r = _histograms(hists, fn), _reference(ref, fn)
    if r.size and h.shape[1] != r.size:  # an empty ref: the core's own message
        if np.ndim(hists) == 0:
            raise ValueError(
                f"{fn}: hists is one number ({brief(hists)}), expected (K, {r.size}) "
                f"histograms, one a row, of ref's {r.size} bins"
            )
        raise ValueError(
            f"{fn}: ref size is {r.size}, expected {h.shape[1]}, the length of hists' rows"
        )
    return h, r


def bhattacharyya_coefficient(hists: ArrayLike, ref: ArrayLike) -> NDArray[np.float64]:
    """``rho = Σ_n sqrt(q*(n) q(n))`` of each row of `hists` (K, B) against `ref` (B,).

    `ref` and each row of `hists` are normalised to sum 1 first (a row of zeros has rho 0), so
    pixel counts serve as well as histograms: rho is in [0, 1], 1 for the same distribution.

    Parameters
    ----------
    hists : (K, B) array_like of float
        Histograms, one per row (a 1-D array is one row; K may be 0): bin counts or
        frequencies, finite and >= 0.
    ref : (B,) array_like of float
        Reference histogram (counts or frequencies), finite, >= 0, not all 0.

    Returns
    -------
    (K,) ndarray of float64
        The Bhattacharyya coefficient of each row.

    Raises
    ------
    TypeError
        `hists` or `ref` not real numbers (text, objects, complex numbers).
    ValueError
        `hists` of more than 2 dimensions, `ref` not 1-D or not of the rows' length B, `ref`
        empty; an entry negative or not finite; `ref` all 0; a row or `ref` whose sum
        overflows.

    Examples
    --------
    >>> from pftrack import bhattacharyya_coefficient
    >>> bhattacharyya_coefficient([[1, 1, 0], [2, 0, 0], [0, 0, 0]], [1, 0, 0])
    array([0.70710678, 1.        , 0.        ])
    """
    fn = "bhattacharyya_coefficient"
    return _core.bhattacharyya_coefficient(*_pair(hists, ref, fn))


def bhattacharyya_distance(hists: ArrayLike, ref: ArrayLike) -> NDArray[np.float64]:
    """Bhattacharyya distance ``D = sqrt(1 - rho)`` of each row of `hists` to `ref`.

    Rows and `ref` normalised as by :func:`bhattacharyya_coefficient`.

    Parameters
    ----------
    hists : (K, B) array_like of float
        Histograms, one per row (a 1-D array is one row; K may be 0): bin counts or
        frequencies, finite and >= 0.
    ref : (B,) array_like of float
        Reference histogram (counts or frequencies), finite, >= 0, not all 0.

    Returns
    -------
    (K,) ndarray of float64
        The distance of each row, in [0, 1] (0: the same distribution; 1: no common bin, or a
        row of zeros).

    Raises
    ------
    TypeError
        `hists` or `ref` not real numbers (text, objects, complex numbers).
    ValueError
        `hists` of more than 2 dimensions, `ref` not 1-D or not of the rows' length B, `ref`
        empty; an entry negative or not finite; `ref` all 0; a row or `ref` whose sum
        overflows.

    Examples
    --------
    >>> from pftrack import bhattacharyya_distance
    >>> bhattacharyya_distance([[1, 1, 0], [2, 0, 0], [0, 0, 1]], [1, 0, 0])
    array([0.5411961, 0.       , 1.       ])
    """
    fn = "bhattacharyya_distance"
    return _core.bhattacharyya_distance(*_pair(hists, ref, fn))


def bhattacharyya_weights(
    hists: ArrayLike, ref: ArrayLike, lam: float = 20.0
) -> NDArray[np.float64]:
    """Normalised particle weights ``w ∝ exp(-λ D²)``, computed in log space.

    Parameters
    ----------
    hists : (K, B) array_like of float
        Candidate histograms, one per particle: bin counts or frequencies, >= 0. Each row is
        normalised to sum 1 (as `ref`), so counts give the same weights as their frequencies;
        a row of zeros (no pixel counted) has ``D = 1``.
    ref : (B,) array_like of float
        Reference histogram of the object (counts or frequencies; normalised to sum 1).
    lam : float
        λ > 0, the sharpness of the likelihood (20 by default, as in Pérez et al.).

    Returns
    -------
    (K,) ndarray of float
        Weights summing to 1.

    Raises
    ------
    TypeError
        `lam` is not a real number (a string, None, a bool), or the histograms hold no numbers.
    ValueError
        `lam` is not finite and > 0; no rows in `hists`; shapes that do not match (`ref` not
        1-D); a negative or non-finite entry; `ref` all zeros.

    Examples
    --------
    >>> from pftrack import bhattacharyya_weights
    >>> w = bhattacharyya_weights([[1, 1, 0], [2, 0, 0], [0, 0, 1]], [1, 0, 0], lam=20.0)
    >>> w.round(6), round(float(w.sum()), 12)
    (array([0.002849, 0.997151, 0.      ]), 1.0)
    """
    fn = "bhattacharyya_weights"
    lam = _lam(lam, fn)
    h, r = _pair(hists, ref, fn)
    if len(h) == 0:  # box_histograms of no boxes: a coefficient each, but no weights to sum to 1
        raise ValueError(f"{fn}: hists has no rows: weights that sum to 1 need a particle")
    return _core.bhattacharyya_weights(h, r, lam)


def _lam(lam: object, fn: str) -> float:
    """`lam` as a float: a real number (not a bool, not text), finite and > 0."""
    if isinstance(lam, bool) or not isinstance(lam, numbers.Real):
        raise TypeError(f"{fn}: lam must be a real number, got {shown(lam)}")
    try:
        value = float(lam)
    except OverflowError:  # an int beyond a float's range (10**400)
        value = math.inf
    if not (math.isfinite(value) and value > 0):
        raise ValueError(f"{fn}: lam is {lam}, expected a finite number > 0")
    return value


def box_weights(
    image: BinnedImage,
    boxes_cxcywh: ArrayLike,
    ref: ArrayLike,
    lam: float = 20.0,
    kernel: str = "uniform",
) -> NDArray[np.float64]:
    """Particle weights ``w ∝ exp(-λ D²)`` of boxes, straight from their pixel counts.

    The same weights as ``bhattacharyya_weights(box_histograms(image, boxes), ref, lam)`` (to
    round-off: ``rtol=1e-9`` in the tests) in one call that never builds the (K, B) histogram
    matrix: the colour particle filters weigh their particles this way. The fastest path for
    many boxes of one reference.

    Parameters
    ----------
    image : BinnedImage
        From :func:`hsv_bins`.
    boxes_cxcywh : (K, 4) array_like of float
        Candidate boxes, one per particle (K >= 1), as centre x, centre y, width, height in
        pixels, clipped to the image as by :func:`box_histograms`. A box with nothing to
        count (outside the image, or only background) has ``D = 1``.
    ref : (B,) array_like of float
        Reference histogram of the object (counts or frequencies; normalised to sum 1), with
        as many bins B as the image.
    lam : float
        λ > 0, the sharpness of the likelihood (20 by default, as in Pérez et al.).
    kernel : {"uniform", "epanechnikov"}
        Pixel weights, as :func:`box_histograms` takes them.

    Returns
    -------
    (K,) ndarray of float64
        Weights summing to 1.

    Raises
    ------
    TypeError
        `image` is not a :class:`BinnedImage` (the frame itself: bin it with
        :func:`hsv_bins`); boxes or `ref` not real numbers; `lam` not a real number (a
        string, None, a bool); `kernel` not a string.
    ValueError
        Boxes not of shape (K, 4) or no box; a box value not finite or beyond ±1e9 px, a
        negative width or height; `ref` not 1-D, not of the image's bin count, with a
        negative or non-finite entry, or all zeros; `lam` not finite and > 0; an unknown
        kernel.

    Notes
    -----
    ``rho = Σ_b sqrt(c_b) sqrt(q_b) / sqrt(n)`` from each box's integer counts ``c_b`` (``n``
    counted pixels); with the uniform kernel the counts of overlapping boxes may come from one
    integral histogram of their union [1]_, exactly the same counts.

    References
    ----------
    .. [1] Porikli, F. (2005). Integral histogram: a fast way to extract histograms in
       Cartesian spaces. CVPR 2005, 829-836.

    Examples
    --------
    >>> import numpy as np
    >>> from pftrack import box_weights, hsv_bins
    >>> frame = np.zeros((4, 6, 3), np.uint8)
    >>> frame[:, 3:] = (0, 0, 255)  # left half black (bin 100), right half red (bin 9)
    >>> ref = np.zeros(110)
    >>> ref[9] = 1.0  # all red
    >>> w = box_weights(hsv_bins(frame), [[4.5, 2, 3, 4], [3, 2, 6, 4], [1.5, 2, 3, 4]], ref)
    >>> w.round(6)
    array([0.997151, 0.002849, 0.      ])
    """
    fn = "box_weights"
    error = not_binned(image, f"{fn}: image")
    if error is not None:
        raise error
    lam = _lam(lam, fn)
    if not isinstance(kernel, str):  # pybind11 would list its signatures
        raise TypeError(f"{fn}: kernel must be 'uniform' or 'epanechnikov', got {shown(kernel)}")
    b = _boxes(boxes_cxcywh, fn)
    if len(b) == 0:
        raise ValueError(f"{fn}: boxes has no rows: weights that sum to 1 need a particle")
    return _core.box_weights(image, b, _reference(ref, fn), lam, kernel)
