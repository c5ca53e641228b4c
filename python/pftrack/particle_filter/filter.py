"""One colour particle filter per object: sequential importance sampling with resampling."""

from __future__ import annotations

import re
import threading
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pftrack import _core, _limits
from pftrack._check import (
    MAX_COORD,
    byte_order_hint,
    generator,
    instance,
    integer,
    number,
    option,
    real_array,
    shown,
)
from pftrack._typing import F64, RngLike
from pftrack.particle_filter.colour import HsvBinning, not_binned
from pftrack.particle_filter.dynamics import MAX_SIGMA_XY, Ar2Model

__all__ = [
    "ColourParticleFilter",
    "FilterConfig",
    "FilterState",
    "reinitialise_filters",
    "step_filters",
    "step_filters_summary",
]


#: Most particles one object's filter may have (48 MB of state; more is refused, not tried):
#: :data:`pftrack._limits.MAX_PARTICLES`, the limit of ``pftrack track --particles`` too.
MAX_PARTICLES = _limits.MAX_PARTICLES


@dataclass(frozen=True)
class FilterConfig:
    """Configuration of a :class:`ColourParticleFilter`.

    Attributes
    ----------
    n_particles : int
        Particles per object (N).
    model : Ar2Model
        Dynamic model (eq. 7, or eq. 8 with ``use_means``).
    lam : float
        λ > 0 of the likelihood ``exp(-λ D²)`` (as :func:`bhattacharyya_weights`: λ = 0 would
        weigh every particle the same, and the filter would not follow colour).
    kernel : {"uniform", "epanechnikov"}
        Pixel weighting inside a box.
    estimate : {"mean", "map"}
        Report the weighted mean, or the maximum-weight particle (the paper's eq. 2).
    min_samples : int
        Count a large box's colours on a lattice (every k-th pixel of every k-th row, the same
        k for all particles of a step) that keeps at least this many of its pixels, so that a
        step costs about the same at 1920x1080 as at 480x360: k = floor(sqrt(area /
        min_samples)) for the box of the previous mean state, k > 1 from 4 ``min_samples``
        pixels on, at most 64 and at most half the box's shorter side (a thin box keeps
        pixels across it). The default 2048 keeps more pixels per box than a walker of PETS09-S2L1
        (about 30x80 at 480x360) has in full, so those boxes are counted in full. 0 counts
        every pixel of every box. The Metropolis-Hastings filter counts on the same lattice.

    Raises
    ------
    TypeError
        `n_particles` or `min_samples` not an int (a string, a float, a bool), `lam` not a
        number.
    ValueError
        `n_particles` not in [1, 1000000], `min_samples` negative, `lam` not finite and >= 0,
        an unknown `kernel` or `estimate`.
    """

    n_particles: int = 100
    model: Ar2Model = field(default_factory=Ar2Model)
    lam: float = 20.0
    kernel: str = "uniform"
    estimate: str = "mean"
    min_samples: int = 2048

    def __post_init__(self) -> None:
        integer(self.n_particles, "FilterConfig: n_particles", 1, MAX_PARTICLES)
        instance(self.model, "FilterConfig: model", Ar2Model)
        integer(self.min_samples, "FilterConfig: min_samples", 0, 2**31 - 1)  # 0: every pixel
        lam = number(self.lam, "FilterConfig: lam", finite=False)
        if not (np.isfinite(lam) and lam > 0):  # as bhattacharyya_weights: 0 ignores colour
            raise ValueError(
                f"FilterConfig: lam is {lam}, expected a finite number > 0 (0 would give every "
                "particle the same weight: the filter would not follow colour)"
            )
        option(self.kernel, "FilterConfig: kernel", ("uniform", "epanechnikov"))
        option(self.estimate, "FilterConfig: estimate", ("mean", "map"))
        if self.kernel not in ("uniform", "epanechnikov"):
            raise ValueError(
                f"FilterConfig: kernel is {self.kernel!r}, expected 'uniform' or 'epanechnikov'"
            )
        if self.estimate not in ("mean", "map"):
            raise ValueError(
                f"FilterConfig: estimate is {self.estimate!r}, expected 'mean' or 'map'"
            )


@dataclass(frozen=True)
class FilterState:
    """What one step of a filter reports.

    Attributes
    ----------
    box_cxcywh : (4,) ndarray
        Estimated box (centre x, centre y, width, height).
    rho : float
        Weight-averaged Bhattacharyya coefficient of the particles to the reference: how well
        the colour model explains the object now (near 1: well; low: occluded or lost).
    rho_max : float
        Best particle's coefficient.
    ess : float
        Effective sample size of the new weights.
    foreground : float
        Weight-averaged number of counted (foreground) pixels in the particles' boxes.
    """

    box_cxcywh: NDArray[np.float64]
    rho: float
    rho_max: float
    ess: float
    foreground: float


def _box(box_cxcywh: ArrayLike, who: str) -> NDArray[np.float64]:
    """A box ``(cx, cy, w, h)`` the filter can follow: :func:`box_histograms`' rule, w, h > 0.

    Raises
    ------
    TypeError
        Not real numbers.
    ValueError
        Not 4 values, a non-finite one, w or h <= 0, or a value beyond ±1e9 px (which
        :func:`~pftrack.particle_filter.box_histograms` refuses at the first step).
    """
    b = real_array(box_cxcywh, f"{who}: box").reshape(-1)
    if b.shape != (4,) or not (_bounded(b) and b[2] > 0 and b[3] > 0):
        raise ValueError(
            f"{who}: box is {b.tolist()}, expected finite (cx, cy, w, h) with w, h > 0, each value "
            f"within ±{MAX_COORD:g} px"
        )
    return b


def _bounded(values: NDArray[np.float64]) -> bool:
    """Every value finite and within ``±MAX_COORD`` (strictly, as the core's box rule)."""
    return bool((np.abs(values) < MAX_COORD).all())  # NaN fails


def _velocity(velocity: ArrayLike, who: str) -> NDArray[np.float64]:
    """A velocity ``(vx, vy)`` in pixels per frame: 2 finite values within ``±MAX_COORD``.

    Raises
    ------
    TypeError
        Not real numbers.
    ValueError
        Not shape (2,) (a third value would be dropped), or a value not finite or beyond
        ±1e9 px per frame.
    """
    v = real_array(velocity, f"{who}: velocity")
    if v.shape != (2,):
        raise ValueError(
            f"{who}: velocity must have shape (2,) (vx, vy), got {v.shape}: {v.tolist()}"
        )
    if not _bounded(v):
        raise ValueError(
            f"{who}: velocity is {v.tolist()}, expected finite (vx, vy) within "
            f"±{MAX_COORD:g} px per frame"
        )
    return v


def _spread(spread: object, model: Ar2Model) -> float:
    """`spread` of :meth:`ColourParticleFilter.reinitialise`, checked against `model`.

    A finite number >= 0 whose position spread ``spread * model.sigma_xy`` is at most
    :data:`MAX_SIGMA_XY` px, the bound of ``Ar2Model.sigma_xy`` itself: re-seeded particles
    stay within a few 1e6 px of their box, so within the ±1e9 px a filter's boxes may span
    (``spread=1e300`` put them at 1e301 px).
    """
    s = number(spread, "spread")
    if s < 0:
        raise ValueError(f"spread is {s:g}, expected a finite number >= 0")
    if s * model.sigma_xy > MAX_SIGMA_XY:
        raise ValueError(
            f"spread is {s:g}, expected at most {MAX_SIGMA_XY / model.sigma_xy:g}: the "
            f"particles' position spread, spread * model.sigma_xy ({model.sigma_xy:g} px), is "
            f"at most {MAX_SIGMA_XY:g} px"
        )
    return s


def _in_use(owner: object, method: str, what: str | None = None) -> RuntimeError:
    """The error of a second thread that would use `owner` while another thread is inside it.

    Worded as :class:`pftrack.Tracker`'s: ``ColourParticleFilter.step: this
    ColourParticleFilter is in use by another thread (...)``; `what` names the object otherwise
    (``step_filters: filters[1] is in use ...``).
    """
    kind = type(owner).__name__
    return RuntimeError(
        f"{method}: {what or f'this {kind}'} is in use by another thread (use one {kind} per "
        "thread, or a lock around it)"
    )


#: The core's words for a reference of another length than the image's bins.
_REF_SIZE = re.compile(r"ref size is (\d+), expected (\d+)")


def _public_error(exc: ValueError, internal: str, public: str) -> ValueError | None:
    """`exc` of the core's step `internal`, named by the public function that called it.

    ``sis_step: what`` becomes ``ColourParticleFilter.step: what`` (`public`); None when `exc`
    is not the core's step's. Asked only once the core has refused the arguments, so the step
    itself pays nothing.
    """
    text = str(exc)
    head = f"{internal}: "
    if not text.startswith(head):
        return None
    return ValueError(f"{public}: {_plain(text[len(head) :])}")


def _plain(what: str) -> str:
    """A core message about the step's values, in the public API's words."""
    return _REF_SIZE.sub(
        lambda m: (
            f"reference has {m[1]} bins, the image {m[2]} (a reference of another binning than "
            "the image's: bin both with the same HsvBinning)"
        ),
        what,
    )


def _take(filters: Sequence[ColourParticleFilter], fn: str) -> None:
    """Take every filter's lock without waiting, or none of them (RuntimeError naming `fn`).

    A step runs in the core without the GIL and updates the filter's arrays in place: a second
    thread inside the same filter would mix two steps' particles and reuse a step number.
    """
    for k, f in enumerate(filters):
        if not f._busy.acquire(blocking=False):
            for g in filters[:k]:
                g._busy.release()
            raise _in_use(f, fn, f"filters[{k}]")


def _release(filters: Sequence[ColourParticleFilter]) -> None:
    for f in filters:
        f._busy.release()


def _once(filters: Sequence[object], fn: str) -> None:
    """Each filter at most once in `filters` (a repeat would step it twice on the same arrays)."""
    if len({id(f) for f in filters}) == len(filters):  # the usual case, without the loop below
        return
    seen: dict[int, int] = {}
    for k, f in enumerate(filters):
        j = seen.setdefault(id(f), k)
        if j != k:
            raise ValueError(
                f"{fn}: filters[{k}] is filters[{j}], the same filter twice (each filter steps "
                "once per frame)"
            )


def _step_argument_error(
    image: object, *filters: ColourParticleFilter, names: Sequence[str] | None = None
) -> TypeError | None:
    """What the core could not take in a step of `filters` on `image` (None: nothing found).

    Asked only once the core has refused the arguments (pybind11's list of signatures, or
    ``sis_step_batch``'s ValueError naming an item's dtype), so the step itself pays nothing
    for it. `names` names each filter in the message (default: its class).
    """
    error = not_binned(image, "image")
    if error is not None:
        return error
    for i, f in enumerate(filters):
        who = type(f).__name__ if names is None else names[i]
        for name in ("particles", "weights", "means"):
            a = getattr(f, name)
            if not isinstance(a, np.ndarray):
                got = type(a).__name__
            elif a.dtype != np.float64 or not a.flags.c_contiguous or not a.flags.writeable:
                order = "C-contiguous" if a.flags.c_contiguous else "not C-contiguous"
                got = f"{a.dtype} {a.shape}, {order}{'' if a.flags.writeable else ', read-only'}"
                got += byte_order_hint(a, f"filter.{name}")
            else:
                continue
            return TypeError(
                f"{who}.{name} must be a C-contiguous, writeable float64 array "
                f"(the step updates it in place), got {got}"
            )
        ref = f.reference
        if not (isinstance(ref, np.ndarray) and ref.dtype == np.float64 and ref.ndim == 1):
            got = type(ref).__name__
            if isinstance(ref, np.ndarray):
                got = f"{ref.dtype} {ref.shape}"
            return TypeError(
                f"{who}.reference must be a (B,) float64 array (set_reference), got {got}"
            )
    return None


class ColourParticleFilter:
    """Sequential importance sampling colour particle filter for one object.

    Each :meth:`step` is one call into the C++ core: systematic resampling, AR(2) propagation of
    centre and scale, one HSV histogram per particle box (foreground pixels only when the binned
    image was masked), Bhattacharyya weights ``w ∝ exp(-λ D²)`` and the estimate.

    Parameters
    ----------
    box_cxcywh : (4,) array_like
        Initial box; its size is the base size ``(w0, h0)`` that the scale multiplies.
    reference : (B,) array_like
        Reference colour histogram of the object (need not be normalised).
    config : FilterConfig, optional
        Particles, dynamics, likelihood (default ``FilterConfig()``).
    rng : numpy.random.Generator, int or None
        Seeds the filter: same seed, same particles, whatever the thread count.
    velocity : (2,) array_like, optional
        Initial velocity (pixels per frame) of the centre.
    binning : HsvBinning, optional
        The binning of the images the filter will step on (keyword only): the reference must
        then have its ``n_bins`` bins, checked here rather than at the first step. Without
        it, the first reference's length is the filter's bin count, which
        :meth:`set_reference` holds later references to.

    Raises
    ------
    TypeError
        A box, reference or velocity that is not real numbers, a `binning` that is not an
        HsvBinning.
    ValueError
        A box that is not 4 finite values with w, h > 0, or a velocity that is not 2 finite
        values, any value beyond ±1e9 px (the rule of
        :func:`~pftrack.particle_filter.box_histograms`); a reference that is negative, not
        finite or all zero, or whose length is not `binning`'s ``n_bins``.

    References
    ----------
    .. [1] Pérez, P. et al. (2002). Color-based probabilistic tracking. ECCV 2002.
    .. [2] Isard, M. & Blake, A. (1998). CONDENSATION. IJCV 29(1), 5-28.
    """

    def __init__(
        self,
        box_cxcywh: ArrayLike,
        reference: ArrayLike,
        config: FilterConfig | None = None,
        rng: RngLike = None,
        velocity: ArrayLike = (0.0, 0.0),
        *,
        binning: HsvBinning | None = None,
    ) -> None:
        if config is not None and not isinstance(config, FilterConfig):
            raise TypeError(
                f"ColourParticleFilter: config must be a FilterConfig, got {type(config).__name__}"
            )
        if binning is not None and not isinstance(binning, HsvBinning):
            raise TypeError(
                f"{type(self).__name__}: binning must be an HsvBinning, got {shown(binning)}"
            )
        self.config = config if config is not None else FilterConfig()
        self._busy = threading.Lock()  # held by a step (one thread at a time; see _in_use)
        self._rng = generator(rng, "rng")
        self._seed = int(self._rng.integers(2**63))
        self._step = 0
        who = type(self).__name__  # the messages name the class made (MHColourParticleFilter)
        b = _box(box_cxcywh, who)
        v0 = _velocity(
            velocity, who
        )  # None here is no velocity: refused (reinitialise's None keeps)
        self.w0, self.h0 = float(b[2]), float(b[3])
        self._set_reference(
            reference,
            None if binning is None else binning.n_bins,
            "the binning's n_h * n_s + n_v",
        )
        n = self.config.n_particles
        self.particles = np.empty((n, 6))
        self.weights = np.full(n, 1.0 / n)
        self.means = np.empty((2, 3))
        self.reinitialise(b, velocity=v0)
        self._last: FilterState | None = None  # see last
        # (row of sis_step_batch's output, the estimate's column, w0, h0) not yet made a state
        self._last_row: tuple[list[float], int, float, float] | None = None

    def __getstate__(self) -> dict[str, Any]:
        """The filter's state for pickle and ``copy`` (not while another thread steps it)."""
        if not self._busy.acquire(blocking=False):
            raise _in_use(self, f"{type(self).__name__}.__getstate__")
        try:
            state = self.__dict__.copy()
        finally:
            self._busy.release()
        del state["_busy"]
        return state

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__dict__.update(state)
        self._busy = threading.Lock()

    def __copy__(self) -> ColourParticleFilter:
        """Refused: a shallow copy would share the particle arrays with the original.

        (Was: taken, each with a lock of its own, so two threads stepped one set of particles
        at once, and ``step_filters([f, copy.copy(f)])`` stepped it twice; a user trial.)
        """
        raise TypeError(
            f"copy.copy({type(self).__name__}) would share the particles, weights and means with "
            "the original; use copy.deepcopy(filter) for an independent copy"
        )

    @property
    def last(self) -> FilterState | None:
        """The state the last step reported (None before the first step).

        A batched step (:func:`step_filters_summary`) keeps only its row of numbers; the
        state is made from it on first reading.
        """
        pending = self._last_row
        if pending is not None:
            row, col, w0, h0 = pending
            cx, cy, s = row[col : col + 3]
            self._last = FilterState(
                box_cxcywh=np.array([cx, cy, s * w0, s * h0]),
                rho=row[9],
                rho_max=row[8],
                ess=row[7],
                foreground=row[10],
            )
            self._last_row = None
        return self._last

    @last.setter
    def last(self, state: FilterState | None) -> None:
        self._last, self._last_row = state, None

    def set_reference(self, reference: ArrayLike) -> None:
        """Replace the reference histogram (e.g. a slow blend with the current appearance).

        Raises
        ------
        TypeError
            Not real numbers.
        ValueError
            Not one dimension (B,), not as many bins as the filter's reference (the filter's
            binning: a histogram of another binning would be refused only at the next step),
            a value not finite or negative, or all zero.
        """
        have = getattr(self, "reference", None)
        n_bins = len(have) if isinstance(have, np.ndarray) and have.ndim == 1 else None
        self._set_reference(reference, n_bins, "the filter's bin count")

    def _set_reference(self, reference: ArrayLike, n_bins: int | None, source: str) -> None:
        """:meth:`set_reference`, holding the length to `n_bins` (None: any), named `source`."""
        who = type(self).__name__
        r = np.ascontiguousarray(real_array(reference, f"{who}: reference"))
        if r.ndim != 1:  # a (1, B) or (K, B) array would be taken as one long histogram
            raise ValueError(f"{who}: reference has shape {r.shape}, expected (B,) bins")
        if n_bins is not None and len(r) != n_bins:
            raise ValueError(
                f"{who}: reference has {len(r)} bins, expected {n_bins} ({source}; a histogram "
                "of another HsvBinning?)"
            )
        if not np.all(np.isfinite(r)) or np.any(r < 0) or r.sum() <= 0:
            raise ValueError(f"{who}: reference histogram must be finite, >= 0 and not all zero")
        self.reference = r / r.sum()

    def reinitialise(
        self, box_cxcywh: ArrayLike, velocity: ArrayLike | None = None, spread: float = 0.5
    ) -> None:
        """Re-seed the particles around a box (e.g. a detection associated with the track).

        Parameters
        ----------
        box_cxcywh : (4,) array_like
            Centre of the new particle cloud; its size sets the scale relative to the base size.
        velocity : (2,) array_like, optional
            Velocity to give the particles; by default the filter's current velocity estimate.
        spread : float
            Position spread as a multiple of ``model.sigma_xy``: a finite number >= 0 with
            ``spread * model.sigma_xy`` at most 1e6 px (the bound of ``Ar2Model.sigma_xy``,
            which keeps the particles within ±1e9 px).

        Raises
        ------
        TypeError
            A box or velocity that is not real numbers, a spread that is not a number.
        ValueError
            A box or velocity the filter cannot follow (see the class), a spread < 0, NaN,
            infinite or above ``1e6 / model.sigma_xy``.
        RuntimeError
            Another thread is inside this filter's ``step`` or ``reinitialise``.
        """
        who = f"{type(self).__name__}.reinitialise"
        b = _box(box_cxcywh, who)
        v = None if velocity is None else _velocity(velocity, who)
        spread = _spread(spread, self.config.model)
        if not self._busy.acquire(blocking=False):
            raise _in_use(self, f"{type(self).__name__}.reinitialise")
        try:
            self._reseed(b, self.velocity if v is None else v, spread)
        finally:
            self._busy.release()

    def _reseed(self, b: F64, v: F64, spread: float) -> None:
        """:meth:`reinitialise` of checked arguments, the filter's lock held."""
        _reseed_batch([self], self.config, np.reshape(b, (1, 4)), np.reshape(v, (1, 2)), spread)

    @property
    def velocity(self) -> NDArray[np.float64]:
        """Centre velocity of the particle-set mean, pixels per frame."""
        return self.means[0, :2] - self.means[1, :2]

    @property
    def box_cxcywh(self) -> NDArray[np.float64]:
        """Current estimate as a box (from the particle-set mean)."""
        cx, cy, s = self.means[0]
        return np.array([cx, cy, s * self.w0, s * self.h0])

    def step(self, image: _core.BinnedImage) -> FilterState:
        """Advance one frame: resample, propagate, weigh against `image`, estimate.

        Raises
        ------
        TypeError
            `image` is not a :class:`~pftrack.particle_filter.BinnedImage` (a raw frame: bin
            it with :func:`~pftrack.particle_filter.hsv_bins`), or ``particles``, ``weights``
            or ``means`` were replaced by arrays the step cannot update in place (not
            float64, not C-contiguous, read-only).
        ValueError
            Arrays of the wrong shape, non-finite particles.
        RuntimeError
            Another thread is inside this filter's ``step`` or ``reinitialise`` (one filter
            in one thread at a time: the step updates the arrays in place without the GIL).
        """
        m = self.config.model

        def sis_step() -> dict[str, Any]:
            return _core.sis_step(
                self.particles, self.weights, self.means, image, self.reference,
                self.w0, self.h0, m.a, m.b, m.sigma, m.s_min, m.s_max, m.use_means,
                self.config.lam, self.config.kernel, True, self._seed, self._step,
                float(self.config.min_samples),
            )  # fmt: skip

        return self._advance(image, "sis_step", sis_step)

    def _advance(
        self, image: _core.BinnedImage, core: str, kernel: Callable[[], dict[str, Any]]
    ) -> FilterState:
        """One :meth:`step`: `kernel` (a call of the core's step `core` on `image`), then its state.

        Under the filter's lock (RuntimeError when another thread holds it); the core's
        refusals are said in the public API's words (a TypeError naming the argument it could
        not take, a ValueError naming ``Class.step`` instead of `core`). On success the step
        counter moves on and the state is :attr:`last`.
        """
        if not self._busy.acquire(blocking=False):
            raise _in_use(self, f"{type(self).__name__}.step")
        try:
            try:
                r = kernel()
            except TypeError:
                error = _step_argument_error(image, self)
                if error is None:
                    raise
                raise error from None
            except ValueError as exc:  # "sis_step: what" -> "ColourParticleFilter.step: what"
                # an array the step updates in place that the core cannot (its layout is a
                # ValueError there): the TypeError naming the filter's attribute, as for a dtype
                error = _step_argument_error(image, self)
                if error is not None:
                    raise error from None
                renamed = _public_error(exc, core, f"{type(self).__name__}.step")
                if renamed is None:
                    raise
                raise renamed from None
            self._step += 1
            cx, cy, s = r["map"] if self.config.estimate == "map" else r["mean"]
            state = FilterState(
                box_cxcywh=np.array([cx, cy, s * self.w0, s * self.h0]),
                rho=float(r["rho_mean"]),
                rho_max=float(r["rho_max"]),
                ess=float(r["ess"]),
                foreground=float(r["fg_mean"]),
            )
            self.last = state
        finally:
            self._busy.release()
        return state


#: How the core names a batch's bad entry: ``sis_step_batch: entry K: what is wrong``.
_ENTRY = re.compile(r"sis_step_batch: entry (\d+): (.*)", re.DOTALL)
#: ... and a bad array of one: ``sis_step_batch: weights[K] must have shape (N,), ...``.
_ITEM = re.compile(r"sis_step_batch: (particles|weights|means|refs)\[(\d+)\] (.*)", re.DOTALL)


def step_filters(
    filters: Sequence[ColourParticleFilter], image: _core.BinnedImage
) -> list[FilterState]:
    """Advance many filters one frame on the same image, in one call into the C++ core.

    The same as ``[f.step(image) for f in filters]``, particle for particle (each filter keeps
    its own counter-based random stream), with one call (the GIL released) instead of one per
    filter. Filters whose class overrides :meth:`ColourParticleFilter.step` (e.g. the
    Metropolis-Hastings one), or whose configuration differs from the first one's, step one by
    one.

    Parameters
    ----------
    filters : sequence of ColourParticleFilter
        The filters, advanced in place.
    image : pftrack._core.BinnedImage
        This frame's bins.

    Returns
    -------
    list of FilterState
        One per filter, in order.

    Raises
    ------
    TypeError
        An element that is not a ColourParticleFilter; `image` not a BinnedImage; a filter
        whose particles, weights or means are not C-contiguous, writeable float64 arrays
        (``step_filters: filters[k].particles must be ...``, as
        :meth:`ColourParticleFilter.step` says it).
    ValueError
        The same filter twice in `filters`; a filter whose particles, weights or reference
        the core refuses (``step_filters: filters[k]: reference has 20 bins, the image
        110 (...)``: a reference of another binning than the image's), found before any filter
        of the batch has stepped (a filter that steps one by one, e.g. a Metropolis-Hastings
        one, is named the same way, after the filters before it have stepped).
    RuntimeError
        Another thread is inside one of the filters (``step_filters: filters[k] is in use by
        another thread``); then no filter has stepped.
    """
    step_filters_summary(filters, image)
    return [f.last for f in filters if f.last is not None]


def step_filters_summary(filters: Sequence[ColourParticleFilter], image: _core.BinnedImage) -> F64:
    """:func:`step_filters`, returning the numbers a tracker reads from the states as one array.

    Each filter's :attr:`ColourParticleFilter.last` is its new state, as after
    :func:`step_filters` (made when first read).

    Returns
    -------
    (K, 4) ndarray
        Per filter: the estimate's centre ``cx, cy``, ``rho`` and ``rho_max`` (the same floats
        as in the states, without making K objects).
    """
    summary = np.empty((len(filters), 4))
    if not filters:
        return summary
    for k, f in enumerate(filters):
        if not isinstance(f, ColourParticleFilter):
            raise TypeError(
                f"step_filters: filters[{k}] is {type(f).__name__}, expected a ColourParticleFilter"
            )
    _once(filters, "step_filters")
    cfg = filters[0].config
    batch = [
        k
        for k, f in enumerate(filters)
        if type(f).step is ColourParticleFilter.step and (f.config is cfg or f.config == cfg)
    ]
    if batch:
        fs = [filters[k] for k in batch]
        col = 3 if cfg.estimate == "map" else 0
        _take(fs, "step_filters")
        try:
            try:
                out = _step_batch(fs, cfg, image)
            except (TypeError, ValueError) as exc:  # a bad entry, before any filter stepped
                # an argument of another type, dtype or layout is a TypeError, as from the
                # filter's step (the core's batch said ValueError: "particles[1] dtype is
                # float32"), naming the filter by its place
                names = [f"step_filters: filters[{k}]" for k in batch]
                wrong = _step_argument_error(image, *fs, names=names)
                if wrong is not None:
                    raise wrong from None
                if isinstance(exc, TypeError):
                    raise
                raise _batch_error(exc, batch) from None
            for f, row in zip(fs, out.tolist(), strict=True):
                f._last, f._last_row = None, (row, col, f.w0, f.h0)
        finally:
            _release(fs)
        at = slice(None) if len(batch) == len(filters) else batch
        summary[at, 0:2] = out[:, col : col + 2]
        summary[at, 2] = out[:, 9]
        summary[at, 3] = out[:, 8]
    if len(batch) < len(filters):
        done = set(batch)
        for k, f in enumerate(filters):
            if k not in done:
                try:
                    st = f.step(image)
                except ValueError as exc:  # "X.step: what" -> "step_filters: filters[k]: what"
                    renamed = _public_error(
                        exc, f"{type(f).__name__}.step", f"step_filters: filters[{k}]"
                    )
                    if renamed is None:
                        raise
                    raise renamed from None
                summary[k] = (st.box_cxcywh[0], st.box_cxcywh[1], st.rho, st.rho_max)
    return summary


def _batch_error(exc: ValueError, batch: Sequence[int]) -> ValueError:
    """``sis_step_batch``'s error `exc` as step_filters' (``step_filters: filters[k]: what``).

    k is the filter's index in step_filters' argument; `batch` maps the batch's to it.
    """
    text = str(exc)
    named = _ENTRY.match(text)
    if named is not None:
        return ValueError(f"step_filters: filters[{batch[int(named[1])]}]: {_plain(named[2])}")
    item = _ITEM.match(text)
    if item is not None:
        name = "reference" if item[1] == "refs" else item[1]
        return ValueError(f"step_filters: filters[{batch[int(item[2])]}].{name} {item[3]}")
    return _public_error(exc, "sis_step_batch", "step_filters") or exc


def _step_batch(
    fs: Sequence[ColourParticleFilter], cfg: FilterConfig, image: _core.BinnedImage
) -> F64:
    """``sis_step_batch`` of filters of configuration `cfg`, their locks held; counts the step."""
    m = cfg.model
    out: F64 = _core.sis_step_batch(
        [f.particles for f in fs], [f.weights for f in fs], [f.means for f in fs],
        image, [f.reference for f in fs], np.array([f.w0 for f in fs]),
        np.array([f.h0 for f in fs]), m.a, m.b, m.sigma, m.s_min, m.s_max, m.use_means,
        cfg.lam, cfg.kernel, True, [f._seed for f in fs], [f._step for f in fs],
        float(cfg.min_samples),
    )  # fmt: skip
    for f in fs:
        f._step += 1
    return out


def reinitialise_filters(
    filters: Sequence[ColourParticleFilter],
    boxes_cxcywh: ArrayLike,
    velocities: ArrayLike,
    spread: float = 0.5,
) -> None:
    """:meth:`ColourParticleFilter.reinitialise` of many filters, as arrays over the filters.

    The same numbers as ``f.reinitialise(box, velocity=v, spread=spread)`` for each filter in
    turn (each filter draws its own noise from its own generator, in order); filters whose
    configurations differ from the first one's are re-seeded one by one.

    Parameters
    ----------
    filters : sequence of ColourParticleFilter
        Re-seeded in place.
    boxes_cxcywh : (K, 4) array_like
        One box per filter: centre of its new particle cloud, and its size.
    velocities : (K, 2) array_like
        Velocity to give each filter's particles, pixels per frame.
    spread : float
        Position spread as a multiple of ``model.sigma_xy``, as
        :meth:`ColourParticleFilter.reinitialise` takes it.

    Raises
    ------
    TypeError
        Boxes or velocities that are not real numbers, a spread that is not a number.
    ValueError
        Not one box (K, 4) and one velocity (K, 2) per filter, each as
        :meth:`ColourParticleFilter.reinitialise` takes it; a spread it refuses (< 0, NaN,
        infinite, above ``1e6 / model.sigma_xy``).
    RuntimeError
        Another thread is inside one of the filters; then no filter has been re-seeded.
    """
    k = len(filters)
    b = real_array(boxes_cxcywh, "boxes_cxcywh")
    v = real_array(velocities, "velocities")
    spread = _spread(spread, filters[0].config.model if k else Ar2Model())
    if k == 0 and b.size == 0 and v.size == 0:
        return
    if b.shape != (k, 4) or v.shape != (k, 2):
        raise ValueError(
            f"boxes_cxcywh {b.shape} and velocities {v.shape} for {k} filters, expected "
            f"({k}, 4) and ({k}, 2)"
        )
    # each test first over all values at once (NaN fails it): the per-row search that names
    # the bad one runs only when there is one (the tracker calls this every frame)
    if not np.abs(v).max() < MAX_COORD:
        bad_v = ~(np.abs(v) < MAX_COORD).all(axis=1)
        k_v = int(np.flatnonzero(bad_v)[0])
        _velocity(v[k_v], f"reinitialise_filters: filters[{k_v}]")  # raises, naming it
    cfg = filters[0].config
    one_config = all(f.config is cfg or f.config == cfg for f in filters)
    if not one_config:
        for f in filters:  # every filter's own bound, before any is re-seeded
            _spread(spread, f.config.model)
    if not (np.abs(b).max() < MAX_COORD and b[:, 2:].min() > 0):
        bad = ~((np.abs(b) < MAX_COORD).all(axis=1) & (b[:, 2] > 0) & (b[:, 3] > 0))
        k_b = int(np.flatnonzero(bad)[0])
        _box(b[k_b], f"reinitialise_filters: filters[{k_b}]")  # raises, naming the box
    held = list({id(f): f for f in filters}.values())  # a filter given twice: one lock
    _take(held, "reinitialise_filters")
    try:
        if one_config:
            _reseed_batch(filters, cfg, b, v, spread)
        else:
            for f, box, vel in zip(filters, b, v, strict=True):
                f._reseed(box, vel, spread)
    finally:
        _release(held)


def _reseed_batch(
    filters: Sequence[ColourParticleFilter], cfg: FilterConfig, b: F64, v: F64, spread: float
) -> None:
    """:func:`reinitialise_filters` of checked arguments, one configuration, the locks held.

    Each filter draws its noise from its own generator, in order; one core call
    (``reseed_batch``) then writes the particles, weights and means of all of them, the floats
    of the NumPy reference (tests/core/test_reseed.py; was NumPy over (K, N, 6) arrays: about
    60 calls on small arrays a frame). :meth:`ColourParticleFilter.reinitialise` is this for one
    filter.
    """
    m = cfg.model
    n = cfg.n_particles
    noise = np.empty((len(filters) * n, 3))
    for i, f in enumerate(filters):  # each filter's own draws, as reinitialise takes them
        f._rng.standard_normal(out=noise[i * n : (i + 1) * n])
    _core.reseed_batch(
        [f.particles for f in filters], [f.weights for f in filters], [f.means for f in filters],
        b, v, np.array([f.w0 for f in filters]), np.array([f.h0 for f in filters]), noise,
        spread * m.sigma_xy, spread * m.sigma_s, m.s_min, m.s_max,
    )  # fmt: skip
