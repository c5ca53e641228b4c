"""Reversible-jump MCMC joint multi-object tracker (Smith, Gatica-Perez & Odobez 2005).

One Markov chain per frame over the joint configuration of a varying number of objects, with
birth, death, update and swap moves; the target combines the colour likelihood of every object,
a foreground-coverage term from the background subtraction, a pairwise interaction prior that
penalises overlapping boxes and each identity's predictive prior. The kernel, with the exact
acceptance ratios next to the equations, is cpp/include/pftrack/rjmcmc.hpp; see docs/samplers.md.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pftrack import _core
from pftrack._check import first_at, generator, integer, number, option, real_array, shown
from pftrack._limits import MOVES_RULE
from pftrack._typing import RngLike
from pftrack.particle_filter.colour import not_binned
from pftrack.particle_filter.filter import _in_use

#: Kernels of the colour histograms (``RJMCMCConfig.kernel``).
KERNELS = ("uniform", "epanechnikov")
#: Largest chain length a frame may have (``burn_in + n_samples``): the core's iteration count
#: is a 32-bit int.
MAX_ITERATIONS = 2**31 - 1


@dataclass(frozen=True)
class RJMCMCConfig:
    """Settings of the RJ-MCMC tracker.

    Parameters
    ----------
    burn_in, n_samples : int
        B burn-in iterations, then N kept samples per frame. A frame costs O((B + N) N): every
        update move evaluates an identity's predictive prior, a mixture over its kept samples
        of the previous frame (about 8 ms a frame at N = 2000 and 0.15 s at N = 10000 with 5
        objects and B = 50; docs/samplers.md).
    p_birth, p_death, p_update, p_swap : float
        Move probabilities, normalised by the chain: finite and >= 0, not all 0, birth and
        death both > 0 or both 0 (a birth is undone by a death: reversibility). ``--moves``
        and ``Tracker(moves=...)`` give them, with the same rule and words
        (:data:`pftrack._limits.MOVES_RULE`).
    a, b, sigma : tuple of 3 float
        AR2 dynamics per component (cx, cy, s); ``sigma`` > 0.
    s_min, s_max : float
        Scale bounds (the target is 0 outside).
    lam : float
        ``lambda`` of the colour likelihood ``exp(-lambda D^2)``.
    kernel : {"uniform", "epanechnikov"}
        Histogram kernel.
    interaction : float
        ``gamma``: the interaction prior is ``exp(-gamma sum_{i<j} IoU(b_i, b_j))``.
    coverage : float
        ``kappa``: the coverage term is ``exp(kappa (C - eta (A - C)) / F)`` with C the foreground
        and A the pixels covered by the union of the boxes, F the frame's foreground pixels.
    background_penalty : float
        ``eta``: weight of the background pixels covered, relative to the foreground.
    birth_prior : float
        ``beta``: prior odds of a newborn object.
    survival : float
        ``p_survive``: prior odds of an identity are ``e / (1 - e)``, ``e = p_survive`` x its
        existence probability in the previous frame.
    birth_sigma_xy, birth_sigma_s : float
        Spread of a newborn's prior around its candidate box (pixels, scale).
    birth_eps : float
        ``eps`` added to every birth weight.
    birth_gate : float
        A candidate whose box overlaps the predicted box of an identity with existence >= 1/2 by
        IoU >= this gets no newborn slot: it is that identity's detection (> 1: no gate).
    detection : float
        ``delta``: each object's target gains ``delta`` times its best IoU with a candidate box
        (the detections support the identities they overlap; 0: off).
    min_samples : int
        Boxes of more than 4 `min_samples` pixels are counted on a lattice that keeps at
        least `min_samples` of their points, as the SIS and MH filters count them
        (`FilterConfig.min_samples`; each identity's lattice is set once a frame, from its mean
        prediction's box, or its candidate's for a newborn); 0 counts every pixel.
    min_existence : float
        ``step`` reports identities whose existence probability is at least this.

    Raises
    ------
    TypeError
        A number setting that is not a number (text, a bool, None), or `a`, `b`, `sigma` not
        real numbers.
    ValueError
        A setting out of the range the core takes (checked here, not at the first step):
        `burn_in` an int >= 0 and `n_samples` an int >= 1, with ``burn_in + n_samples`` at most
        2147483647; move probabilities finite and >= 0, not all 0, birth and death both > 0
        or both 0; `a`, `b` 3 finite values and `sigma` 3 finite values > 0; finite
        ``0 < s_min <= s_max``; `lam`, `interaction`, `coverage`, `background_penalty`,
        `detection` finite and >= 0; `birth_prior`, `birth_sigma_xy`, `birth_sigma_s`,
        `birth_eps`, `birth_gate` finite and > 0; `survival` in (0, 1]; `min_existence` in
        [0, 1]; `kernel` not "uniform" or "epanechnikov"; `min_samples` (an int: TypeError
        otherwise) not in [0, 2147483647].
    """

    burn_in: int = 50
    n_samples: int = 200
    p_birth: float = 0.1
    p_death: float = 0.1
    p_update: float = 0.7
    p_swap: float = 0.1
    a: tuple[float, float, float] = (2.0, 2.0, 2.0)
    b: tuple[float, float, float] = (-1.0, -1.0, -1.0)
    sigma: tuple[float, float, float] = (4.0, 4.0, 0.02)
    s_min: float = 0.2
    s_max: float = 5.0
    lam: float = 10.0
    kernel: str = "uniform"
    interaction: float = 10.0
    coverage: float = 20.0
    background_penalty: float = 0.25
    birth_prior: float = 2.0
    survival: float = 0.95
    birth_sigma_xy: float = 3.0
    birth_sigma_s: float = 0.05
    birth_eps: float = 0.02
    birth_gate: float = 0.1
    detection: float = 20.0
    min_samples: int = 2048
    min_existence: float = 0.5

    def __post_init__(self) -> None:
        own = "RJMCMCConfig"
        integer(self.burn_in, f"{own}: burn_in", 0, MAX_ITERATIONS)
        integer(self.n_samples, f"{own}: n_samples", 1, MAX_ITERATIONS)
        if self.burn_in + self.n_samples > MAX_ITERATIONS:
            raise ValueError(
                f"{own}: burn_in + n_samples is {self.burn_in} + {self.n_samples}, expected at "
                f"most {MAX_ITERATIONS}"
            )
        moves = ("p_birth", "p_death", "p_update", "p_swap")
        for name in moves:
            _at_least(self, name, 0.0)
        if sum(getattr(self, name) for name in moves) <= 0:
            raise ValueError(f"{own}: p_birth, p_death, p_update and p_swap are all 0")
        if (self.p_birth > 0) != (self.p_death > 0):
            raise ValueError(
                f"{own}: p_birth is {self.p_birth} and p_death {self.p_death}, expected "
                f"{MOVES_RULE}"
            )
        for name in ("a", "b", "sigma"):
            v = real_array(getattr(self, name), f"{own}: {name}", booleans=False)
            positive = name != "sigma" or bool((v > 0).all())
            if v.shape != (3,) or not (np.isfinite(v).all() and positive):
                more = " > 0" if name == "sigma" else ""
                raise ValueError(
                    f"{own}: {name} is {v.tolist()}, expected 3 finite values{more} (cx, cy, s)"
                )
        for name in ("s_min", "s_max"):
            number(getattr(self, name), f"{own}: {name}", finite=False)
        if not (0 < self.s_min < np.inf):
            raise ValueError(f"{own}: s_min is {self.s_min}, expected a finite value > 0")
        if not (self.s_min <= self.s_max < np.inf):
            raise ValueError(
                f"{own}: s_max is {self.s_max}, expected a finite value >= s_min ({self.s_min})"
            )
        for name in ("lam", "interaction", "coverage", "background_penalty", "detection"):
            _at_least(self, name, 0.0)
        integer(self.min_samples, f"{own}: min_samples", 0, 2**31 - 1)  # 0: every pixel
        for name in ("birth_prior", "birth_sigma_xy", "birth_sigma_s", "birth_eps", "birth_gate"):
            _at_least(self, name, 0.0, strict=True)
        survival = number(self.survival, f"{own}: survival", finite=False)
        if not 0 < survival <= 1:
            raise ValueError(f"{own}: survival is {survival}, expected a value in (0, 1]")
        existence = number(self.min_existence, f"{own}: min_existence", finite=False)
        if not 0 <= existence <= 1:
            raise ValueError(f"{own}: min_existence is {existence}, expected a value in [0, 1]")
        option(self.kernel, f"{own}: kernel", KERNELS)
        if self.kernel not in KERNELS:
            raise ValueError(
                f"{own}: kernel is {self.kernel!r}, expected 'uniform' or 'epanechnikov'"
            )

    def core_kwargs(self) -> dict[str, Any]:
        """Keyword arguments of ``pftrack._core.RJMCMCTracker``."""
        out = {
            k: getattr(self, k)
            for k in (
                "burn_in",
                "n_samples",
                "p_birth",
                "p_death",
                "p_update",
                "p_swap",
                "s_min",
                "s_max",
                "lam",
                "kernel",
                "interaction",
                "coverage",
                "background_penalty",
                "birth_prior",
                "survival",
                "birth_sigma_xy",
                "birth_sigma_s",
                "birth_eps",
                "birth_gate",
                "detection",
                "min_samples",
            )
        }
        for k in ("a", "b", "sigma"):
            out[k] = np.asarray(getattr(self, k), dtype=np.float64)
        return out


def _at_least(config: RJMCMCConfig, name: str, lo: float, *, strict: bool = False) -> None:
    """`config.name` must be a finite number >= `lo` (> `lo` with `strict`)."""
    v = number(getattr(config, name), f"RJMCMCConfig: {name}", finite=False)
    if not (np.isfinite(v) and (v > lo if strict else v >= lo)):
        raise ValueError(
            f"RJMCMCConfig: {name} is {v}, expected a finite value {'>' if strict else '>='} {lo:g}"
        )


class RJTrack(NamedTuple):
    """One identity's estimate in a frame: id, box (cx, cy, w, h), existence probability."""

    id: int
    box_cxcywh: NDArray[np.float64]
    score: float


class RJMCMCFilter:
    """Joint RJ-MCMC tracker of a varying number of objects; its state lives in the object.

    Parameters
    ----------
    config : RJMCMCConfig, optional
        Settings (default ``RJMCMCConfig()``).
    rng : numpy.random.Generator, int or None
        Source of the seed of the C++ counter-based draws.

    Raises
    ------
    TypeError
        A `config` that is not an RJMCMCConfig, an `rng` that is not a Generator, a seed or
        None.
    ValueError
        A negative seed.

    References
    ----------
    .. [1] Smith, K., Gatica-Perez, D., Odobez, J.-M. (2005). Using particles to track varying
       numbers of interacting people. CVPR 2005.
    .. [2] Green, P. J. (1995). Reversible jump Markov chain Monte Carlo computation and Bayesian
       model determination. Biometrika 82(4).
    .. [3] Khan, Z., Balch, T., Dellaert, F. (2005). MCMC-based particle filtering for tracking a
       variable number of interacting targets. IEEE TPAMI 27(11).
    """

    def __init__(self, config: RJMCMCConfig | None = None, rng: RngLike = None) -> None:
        if config is not None and not isinstance(config, RJMCMCConfig):
            raise TypeError(f"RJMCMCFilter: config must be an RJMCMCConfig, got {shown(config)}")
        self.config = config if config is not None else RJMCMCConfig()
        option(self.config.kernel, "RJMCMCConfig: kernel", KERNELS)
        if self.config.kernel not in ("uniform", "epanechnikov"):
            raise ValueError(
                f"RJMCMCConfig: kernel is {self.config.kernel!r}, "
                "expected 'uniform' or 'epanechnikov'"
            )
        self._core = _core.RJMCMCTracker(**self.config.core_kwargs())
        self.seed = int(generator(rng, "RJMCMCFilter: rng").integers(2**63))
        self.n_steps = 0
        self.last: dict[str, Any] = {}
        # held by a step: the core refuses a second thread only while inside, and the step
        # number would be read twice between the two
        self._busy = threading.Lock()

    def step(
        self,
        binned: _core.BinnedImage,
        mask: ArrayLike,
        candidates_cxcywh: ArrayLike,
        candidate_hists: ArrayLike | None = None,
    ) -> list[RJTrack]:
        """Track into the next frame.

        Parameters
        ----------
        binned : pftrack._core.BinnedImage
            The frame's bins (foreground only: -1 = background).
        mask : (H, W) array_like of uint8 or bool
            Foreground mask of the background subtraction (non-zero = foreground).
        candidates_cxcywh : (K, 4) array_like of float
            Birth candidates (cx, cy, w, h), e.g. the detector's boxes; may be empty (``[]``),
            one may be given as (4,). Any other shape is refused ((4, 3) is not 3 boxes).
        candidate_hists : (K, B) array_like of float, optional
            Their reference histograms; computed from ``binned`` when omitted. A candidate without
            any counted pixel cannot be born.

        Returns
        -------
        list of RJTrack
            Identities whose existence probability is at least ``config.min_existence``, with their
            mean box over the kept samples containing them.

        Raises
        ------
        TypeError
            `binned` is not a :class:`~pftrack.particle_filter.BinnedImage` (a raw frame: bin
            it with :func:`~pftrack.particle_filter.hsv_bins`); a mask whose dtype is not
            uint8 or bool; candidates or histograms that are not real numbers.
        ValueError
            A mask not of the frame's shape; candidates not of shape (K, 4) or (4,), or a
            candidate not finite, beyond ±1e9 px or with w or h < 0;
            `candidate_hists` not (K, B) with the image's B bins, or a value not finite or
            negative (as :func:`~pftrack.particle_filter.bhattacharyya_coefficient` refuses).
        RuntimeError
            Another thread is inside this filter's ``step`` (one filter in one thread at a time).
        """
        fn = "RJMCMCFilter.step"
        error = not_binned(binned, "binned")
        if error is not None:
            raise error
        m = np.asarray(mask)
        if m.dtype == bool:
            m = m.view(np.uint8)
        elif m.dtype != np.uint8:  # as hsv_bins refuses it (the core said ValueError)
            raise TypeError(f"{fn}: mask dtype is {m.dtype}, expected uint8 or bool")
        m = np.ascontiguousarray(m)
        if m.shape != tuple(binned.shape):  # the core's message gave neither shape
            shape = tuple(binned.shape)
            raise ValueError(f"{fn}: mask has shape {m.shape}, expected the frame's {shape}")
        cands = real_array(candidates_cxcywh, f"{fn}: candidates_cxcywh")
        if cands.ndim == 1 and cands.size == 0:
            cands = np.zeros((0, 4))  # [] is no candidate, as np.zeros((0, 4))
        elif cands.shape == (4,):
            cands = cands[None, :]  # one candidate, as box_histograms takes one box
        if cands.ndim != 2 or cands.shape[1] != 4:
            raise ValueError(
                f"{fn}: candidates_cxcywh must have shape (K, 4) (cx, cy, w, h), got {cands.shape}"
            )
        cands = np.ascontiguousarray(cands)
        hists = None
        if candidate_hists is not None:
            hists = np.ascontiguousarray(real_array(candidate_hists, f"{fn}: candidate_hists"))
            if hists.ndim != 2:  # was pybind11's list of step()'s signatures (a 3-D array)
                raise ValueError(
                    f"{fn}: candidate_hists must have shape (K, B), one row of "
                    f"{binned.n_bins} bins per candidate, got {hists.shape}"
                )
            bad = ~(np.isfinite(hists) & (hists >= 0))
            if bad.any():
                k, at = first_at(bad)
                raise ValueError(
                    f"{fn}: candidate_hists{at} is {hists[k]:g}, expected a finite value >= 0"
                )
        if not self._busy.acquire(blocking=False):
            raise _in_use(self, "RJMCMCFilter.step")
        try:
            r = self._core.step(binned, m, cands, hists, seed=self.seed, step=self.n_steps)
            self.n_steps += 1
            self.last = dict(r)
        finally:
            self._busy.release()
        out = []
        for row in r["estimates"]:
            if row[5] >= self.config.min_existence:
                out.append(RJTrack(int(row[0]), row[1:5].copy(), float(row[5])))
        return out

    def __getstate__(self) -> dict[str, Any]:
        """The filter's state for pickle and deepcopy: a checkpoint of the run.

        The chain's kept identities and next id are read from the core (which has no pickled
        form of its own) and given back to a new core by :meth:`__setstate__`: the copy goes on
        exactly as the original (the same draws: the seed and step number are kept).
        """
        if not self._busy.acquire(blocking=False):
            raise _in_use(self, "RJMCMCFilter (pickle/deepcopy)")
        try:
            state = self.__dict__.copy()
            del state["_busy"]  # a lock is not copied: the copy is free
            core = state.pop("_core")
            state["_core_state"] = (core.tracks, core.next_id)
        finally:
            self._busy.release()
        return state

    def __setstate__(self, state: dict[str, Any]) -> None:
        tracks, next_id = state.pop("_core_state")
        self.__dict__.update(state)
        self._busy = threading.Lock()
        self._core = _core.RJMCMCTracker(**self.config.core_kwargs())
        self._core.restore(tracks, next_id)

    def warp(self, affine: ArrayLike) -> None:
        """Move the kept identities into the next frame by a similarity transform.

        Camera-motion compensation, as :func:`~pftrack.tracking.camera.warp_tracks` moves the
        per-object filters: every kept sample's current and previous centre is mapped by
        `affine`, each identity's base size multiplied by its zoom ``sqrt|det|``.

        Parameters
        ----------
        affine : (2, 3) array_like of float
            From the previous frame's pixels to the next frame's.

        Raises
        ------
        ValueError
            `affine` not a finite (2, 3) array, singular, or moving an identity beyond the
            finite numbers (the identities are then left as they were).
        RuntimeError
            Another thread is inside this filter.
        """
        a = np.ascontiguousarray(real_array(affine, "RJMCMCFilter.warp: affine"))
        if a.shape != (2, 3):  # was pybind11's list of warp()'s signatures (a 3-D array)
            raise ValueError(f"RJMCMCFilter.warp: affine must have shape (2, 3), got {a.shape}")
        if not self._busy.acquire(blocking=False):
            raise _in_use(self, "RJMCMCFilter.warp")
        try:
            self._core.warp(a)
        finally:
            self._busy.release()

    @property
    def acceptance(self) -> dict[str, float]:
        """Acceptance rate per move in the last frame (NaN for a move never proposed).

        Accepted / proposed over the `n_samples` kept iterations (burn-in left out); a move
        impossible in the chain's state (a death or update with no object, a swap with fewer
        than two, a birth with every slot present) leaves the chain as it is and is not counted
        as proposed. The counts are ``last["acceptance"][move] = (accepted, proposed)``.
        """
        acc = self.last.get("acceptance", {})
        return {k: (a / p if p else float("nan")) for k, (a, p) in acc.items()}

    @property
    def map_estimate(self) -> NDArray[np.float64]:
        """(Q, 5) id, cx, cy, w, h of the last frame's MAP sample."""
        return np.asarray(self.last.get("map", np.zeros((0, 5))))
