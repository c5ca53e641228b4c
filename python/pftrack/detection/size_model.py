"""A person-size model learned from the scene: box height and width as functions of image y.

On a ground plane seen by a fixed camera, the image height of a person standing with feet at
image row ``y`` is close to linear in ``y`` (``h = k (y - y_horizon)``, and so is the width);
seen from above both are about constant. `PersonSizeModel` fits both lines robustly (Theil-Sen,
`theil_sen`, refitted without its outliers) to the boxes of *isolated*
detections (no other box overlapping their columns), online; `merge_fragments` and
`split_count` use it to join the fragments of one person and to cut the blob of a group into
several people. There is no fixed aspect ratio: the width line is learnt as the height line is.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from pftrack import _core
from pftrack._check import integer, number
from pftrack._stats import median

__all__ = ["PersonSizeModel", "SizeModelConfig", "expected_size", "head_height", "theil_sen"]

#: Largest `SizeModelConfig.min_samples`, `max_samples` and `refit_every` (the ring buffer is
#: allocated up front: 24 MB at this size).
MAX_SAMPLES = 1_000_000


@dataclass(frozen=True)
class SizeModelConfig:
    """Settings of `PersonSizeModel`.

    Attributes
    ----------
    min_samples : int
        Isolated boxes needed before the model is used (before it, blobs are split by
        `BlobConfig.person_aspect` and nothing is merged); an int (NumPy's too, not a bool) in
        [3, 1000000], as `max_samples` (>= `min_samples`) and `refit_every` (>= 1).
    max_samples : int
        The most recent boxes kept for the fit (a ring buffer).
    refit_every : int
        Refit after this many new samples.
    split_ratio : float
        A box wider than ``split_ratio`` expected widths at its foot row is a group: cut into
        ``round(w / expected width)`` parts ...
    split_max_height : float
        ... unless it is taller than ``split_max_height`` expected heights at its foot row
        (the upper part of a nearer person whose legs went undetected, not a far group).
    merge_slack : float
        Two boxes whose columns overlap are one person's fragments when their union is at most
        ``merge_slack`` times the expected height and width at the union's foot row.
    max_cut_share : float
        A fit that would cut (`PersonSizeModel.split_count` > 1) more than this share of the
        isolated boxes it was fitted from is rejected: those boxes are single people but for a
        few groups, so such a fit contradicts its own samples (one person's many near-identical
        boxes, or a person's boxes truncated at the image's side, took it over). The previous
        fit stays and the next try comes ``refit_every`` samples later; with no previous fit,
        the next frame with an isolated box tries again. 1 accepts every fit.
    """

    min_samples: int = 30
    max_samples: int = 200
    refit_every: int = 50
    split_ratio: float = 1.6
    split_max_height: float = 1.5
    merge_slack: float = 1.2
    max_cut_share: float = 0.2

    def __post_init__(self) -> None:
        own = "SizeModelConfig"  # every message names the class, as the other configs' do
        for name in ("split_ratio", "split_max_height", "merge_slack", "max_cut_share"):
            number(getattr(self, name), f"{own}: {name}", finite=False)  # not an array's truth
        # ints, NumPy's too (were refused, ValueError), not bools (True was taken as 1)
        for name, lo in (("min_samples", 3), ("max_samples", 3), ("refit_every", 1)):
            v = integer(getattr(self, name), f"{own}: {name}", lo, MAX_SAMPLES)
            object.__setattr__(self, name, v)
        if self.max_samples < self.min_samples:
            raise ValueError(
                f"{own}: max_samples is {self.max_samples}, expected an int >= min_samples "
                f"({self.min_samples})"
            )
        if not (self.split_ratio > 1.0 and np.isfinite(self.split_ratio)):
            raise ValueError(
                f"{own}: split_ratio is {self.split_ratio}, expected a finite value > 1"
            )
        if not (self.split_max_height > 0.0 and np.isfinite(self.split_max_height)):
            raise ValueError(
                f"{own}: split_max_height is {self.split_max_height}, expected a finite value > 0"
            )
        if not (self.merge_slack >= 1.0 and np.isfinite(self.merge_slack)):
            raise ValueError(
                f"{own}: merge_slack is {self.merge_slack}, expected a finite value >= 1"
            )
        if not (0.0 <= self.max_cut_share <= 1.0):
            raise ValueError(
                f"{own}: max_cut_share is {self.max_cut_share}, expected a value in [0, 1]"
            )


def theil_sen(x: NDArray[np.float64], y: NDArray[np.float64]) -> tuple[float, float]:
    """Theil-Sen line: the median of the pairwise slopes, intercept ``median(y - slope x)``.

    ``scipy.stats.theilslopes(y, x, method="joint")`` without its confidence interval, which
    costs several sorts (tests hold the two equal). In C++ (``pftrack._core.theil_sen``:
    selection, not sorting, of the n (n - 1) / 2 slopes); ``tests/reference/blobs.py`` holds the
    NumPy statement it equals bit for bit.

    Parameters
    ----------
    x, y : (n,) ndarray of float64
        At least two distinct `x`.

    Returns
    -------
    slope, intercept : float

    Raises
    ------
    ValueError
        `x` and `y` of different lengths, values not finite, or no two distinct `x`.
    """
    return _core.theil_sen(np.asarray(x, np.float64), np.asarray(y, np.float64))


def expected_size(
    lines: NDArray[np.float64], foot_y: NDArray[np.float64] | float
) -> NDArray[np.float64]:
    """Expected ``(h, w)`` of a person at foot row(s) `foot_y`, at least 1 px.

    Parameters
    ----------
    lines : (2, 2) ndarray
        ``[[h_slope, h_intercept], [w_slope, w_intercept]]`` in the foot row
        (`PersonSizeModel.coefficients`).
    foot_y : float or ndarray
        Foot row(s).

    Returns
    -------
    (..., 2) ndarray
        ``h, w`` per foot row.
    """
    y = np.asarray(foot_y, np.float64)[..., None]
    return np.maximum(lines[:, 0] * y + lines[:, 1], 1.0)


def head_height(lines: NDArray[np.float64], top: NDArray[np.float64]) -> NDArray[np.float64]:
    """Height ``h_e`` of the person whose head is at row(s) `top`.

    ``h_e`` solves ``h = h_intercept + h_slope (top + h)``, as the C++ ``extend_legs`` does
    (`PersonSizeModel.extend_legs`).

    Parameters
    ----------
    lines : (2, 2) ndarray
        ``[[h_slope, h_intercept], [w_slope, w_intercept]]`` in the foot row, ``h_slope != 1``.
    top : ndarray
        Head (top) row(s).

    Returns
    -------
    ndarray
        ``h_e`` per row; not positive where there is no such person (a head below the horizon).
    """
    h_slope, h_icpt = lines[0]
    out: NDArray[np.float64] = (h_icpt + h_slope * top) / (1.0 - h_slope)
    return out


class PersonSizeModel:
    """Expected box height and width of one person as straight lines in the foot row ``y``.

    Parameters
    ----------
    config : SizeModelConfig, optional
        Settings (defaults documented there).
    """

    def __init__(self, config: SizeModelConfig | None = None) -> None:
        self.config = config if config is not None else SizeModelConfig()
        self._samples = np.zeros((self.config.max_samples, 3))  # foot y, h, w
        self._n = 0  # samples seen in all
        self._since_fit = 0
        self._coef: NDArray[np.float64] | None = None  # (2, 2): [h, w] x [slope, intercept]
        self._slopes: list[float] = []  # the height slope of every fit kept, in turn

    def reset(self) -> None:
        """Forget every sample and the fit."""
        self._n = 0
        self._since_fit = 0
        self._coef = None
        self._slopes = []

    def __setstate__(self, state: dict[str, object]) -> None:
        self.__dict__.update(state)
        if "_slopes" not in state:  # pickled before fits_agree (6 December): its fit alone
            coef = self._coef
            self._slopes = [] if coef is None else [float(coef[0, 0])]

    @property
    def fitted(self) -> bool:
        """Whether enough isolated boxes were seen for `expected` to answer."""
        return self._coef is not None

    @property
    def n_samples(self) -> int:
        """Isolated boxes currently held for the fit."""
        return min(self._n, self.config.max_samples)

    @property
    def coefficients(self) -> NDArray[np.float64] | None:
        """(2, 2) ``[[h_slope, h_intercept], [w_slope, w_intercept]]`` in foot row, or None.

        A read-only view of the fit (no copy: the blob pass reads it every frame).
        """
        if self._coef is None:
            return None
        view: NDArray[np.float64] = self._coef.view()
        view.flags.writeable = False
        return view

    def expected(self, foot_y: NDArray[np.float64] | float) -> NDArray[np.float64]:
        """Expected ``(h, w)`` at foot row(s) `foot_y`: shape ``(..., 2)``, at least 1 px.

        Raises
        ------
        ValueError
            Before the model is fitted.
        """
        if self._coef is None:
            raise ValueError("PersonSizeModel.expected: the model is not fitted yet")
        return expected_size(self._coef, foot_y)

    def observe(self, boxes: NDArray[np.float64], skip: NDArray[np.bool_] | None = None) -> None:
        """Add the isolated ones among `boxes` (K, 4) ``left, top, w, h`` to the fit.

        A box is isolated when no other box of the frame overlaps its columns: a person
        stacked over another blob (a fragment, or someone partly hidden) is not sampled.
        Boxes where `skip` (K,) is True are not sampled either (a person standing still:
        `pftrack.detection.hold.StopMemory.still`), but still make the others not isolated.
        """
        b = np.asarray(boxes, np.float64).reshape(-1, 4)
        if len(b) == 0:
            return
        left, right = b[:, 0], b[:, 0] + b[:, 2]
        overlap = (left[:, None] < right[None, :]) & (left[None, :] < right[:, None])
        np.fill_diagonal(overlap, False)
        alone = ~overlap.any(axis=1)
        if skip is not None:
            alone &= ~skip
        iso = b[alone]
        m, size = len(iso), self.config.max_samples
        # the ring buffer's next m slots at once; of more boxes than slots, the last ones
        # (those written in turn would overwrite the earlier)
        kept = iso[-size:]
        slots = (self._n + m - len(kept) + np.arange(len(kept))) % size
        self._samples[slots, 0] = kept[:, 1] + kept[:, 3]
        self._samples[slots, 1] = kept[:, 3]
        self._samples[slots, 2] = kept[:, 2]
        self._n += m
        self._since_fit += m
        # only with a sample new since the last try: a refused first fit is not redone, on
        # every frame, from the same samples (it would be refused again)
        if (
            self._since_fit > 0
            and self.n_samples >= self.config.min_samples
            and (self._coef is None or self._since_fit >= self.config.refit_every)
        ):
            self._fit()

    def _fit(self) -> None:
        """Both lines from the samples held, in C++ (``pftrack._core.size_fit``).

        Each is a Theil-Sen line of h (or w) against the foot row, refitted once on the
        points within 3 robust sigmas (1.4826 MAD, at least 1 px) of the first line: the refit
        removes the bias that groups and fragments (all wider, or all smaller) leave. Every
        foot on one row (spread under 1 px): a constant size, the median h and w.

        The new fit is kept only if it would cut at most `SizeModelConfig.max_cut_share` of the
        samples it came from. When more than half of them are one slow person's identical
        boxes, their robust sigma is 1 px and the refit drops every other person as an outlier
        (on `pftrack.synthetic.make_scene` seed 2: a width of 13 px where walkers are 31 px
        wide, which then cuts each walker into strips); such a fit cuts the other people's
        boxes it was given, and is refused.
        """
        samples = self._samples[: self.n_samples]
        coef: NDArray[np.float64] = _core.size_fit(samples)
        self._since_fit = 0
        c = self.config
        boxes = np.column_stack(
            [np.zeros(len(samples)), samples[:, 0] - samples[:, 1], samples[:, 2], samples[:, 1]]
        )  # left, top, w, h of each sample (left plays no part in the count)
        cut = _core.split_count(boxes, coef, c.split_ratio, c.split_max_height) > 1
        if cut.mean() <= c.max_cut_share:
            self._coef = coef
            self._slopes.append(float(coef[0, 0]))

    def fits_agree(self, share: float) -> bool:
        """Whether the fits kept over the video agree on the perspective (the height slope).

        They agree when the spread of their height slopes, over the foot rows of the boxes held
        (lowest to highest), moves a person's height by at most ``(1 - share)`` of the median
        height held: ``(max s - min s) (foot_max - foot_min) <= (1 - share) median h``, the band
        within which `pftrack.tracking.offline.complete_boxes` counts a box of `share` as whole.
        A camera at head height gives fits of one slope near 1 from the first boxes on; a scene
        without perspective gives fits whose slopes follow whichever people were seen (their
        differing sizes read as perspective). False before the model is fitted.

        Raises
        ------
        ValueError
            `share` not in (0, 1].
        """
        share = number(share, "PersonSizeModel.fits_agree: share")
        if not 0.0 < share <= 1.0:
            raise ValueError(f"PersonSizeModel.fits_agree: share is {share}, expected (0, 1]")
        if not self._slopes:
            return False
        held = self._samples[: self.n_samples]
        spread = (max(self._slopes) - min(self._slopes)) * float(np.ptp(held[:, 0]))
        return spread <= (1.0 - share) * median(held[:, 1])

    def split_count(self, boxes: NDArray[np.float64]) -> NDArray[np.int64]:
        """How many people each box (K, 4) holds side by side.

        ``round(w / w_exp)`` when ``w > split_ratio * w_exp`` and the box is no taller than
        ``split_max_height * h_exp`` (expected sizes at its foot row), else 1: a wide box much
        taller than a person standing at its foot row is the upper part of a nearer person
        whose legs went undetected, not a far group.
        """
        c = self.config
        split: NDArray[np.int64] = _core.split_count(
            np.asarray(boxes, np.float64).reshape(-1, 4),
            self._fitted_lines("split_count"),
            c.split_ratio,
            c.split_max_height,
        )
        return split

    def merge_fragments(self, boxes: NDArray[np.float64]) -> list[list[int]]:
        """Group the boxes (K, 4) that are fragments of one person.

        Greedily joins the pair whose union is smallest among those whose columns overlap
        (by at least half the narrower box) and whose union fits within ``merge_slack`` times
        the expected height and width at its foot row; repeats until no pair fits.

        Returns
        -------
        list of lists of int
            Indices of the boxes of each group (every box in exactly one group).
        """
        groups: list[list[int]] = _core.merge_fragments(
            np.asarray(boxes, np.float64).reshape(-1, 4),
            self._fitted_lines("merge_fragments"),
            self.config.merge_slack,
        )
        return groups

    def extend_legs(
        self,
        mask: NDArray[np.uint8],
        boxes: NDArray[np.float64],
        min_height: float,
        row_fill: float,
    ) -> NDArray[np.float64]:
        """Extend the boxes of people whose legs were lost down to the expected foot row.

        A box shorter than `min_height` times the height ``h_e`` of a person whose head is at
        the box's top row ``y`` (``h_e`` solves ``h = h_intercept + h_slope (y + h)``) grows down
        one row at a time while at least `row_fill` of its columns (and at least one) are
        non-zero in `mask` (foreground 255 or shadow 127) in the row just below it, and never
        past the expected foot row ``y + h_e``. ``h_slope > 1`` is a camera below head height
        (nearer people's heads are higher; TUD-Campus's ground truth gives 1.49); no box
        changes when ``h_slope = 1``, nor one whose ``h_e <= 0``. One C++ call
        (``pftrack._core.extend_legs``; ``tests/reference/blobs.py`` holds the NumPy statement
        it equals).

        Parameters
        ----------
        mask : (H, W) ndarray of uint8
            The cleaned mask with its shadow pixels (255 foreground, 127 shadow, 0 background).
        boxes : (K, 4) ndarray of float64
            ``left, top, w, h``.
        min_height : float
            Share of the expected height below which a box is extended (0: none is).
        row_fill : float
            Share of the box's columns a row below it must fill, in [0, 1].

        Returns
        -------
        (K, 4) ndarray of float64
            The boxes, only heights changed.

        Raises
        ------
        ValueError
            Before the model is fitted, or arguments out of range.
        """
        out: NDArray[np.float64] = _core.extend_legs(
            mask,
            np.asarray(boxes, np.float64).reshape(-1, 4),
            self._fitted_lines("extend_legs"),
            min_height,
            row_fill,
        )
        return out

    def _fitted_lines(self, fn: str) -> NDArray[np.float64]:
        if self._coef is None:
            raise ValueError(f"PersonSizeModel.{fn}: the model is not fitted yet")
        return self._coef
