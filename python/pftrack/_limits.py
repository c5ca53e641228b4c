"""The samplers' limits, one constant each, shared by the CLI and the Python API.

No imports: ``pftrack track --help`` states them without importing the tracker, and
:class:`pftrack.Tracker`, :class:`~pftrack.tracking.TrackerConfig` and the command check against
the same numbers (docs/samplers.md, "Options of the samplers").
"""

from __future__ import annotations

import math
from collections.abc import Sequence

__all__ = [
    "CHAIN_SETTINGS",
    "DEFAULT_BURN_IN",
    "DEFAULT_MH_ITER",
    "DEFAULT_MH_PROPOSAL",
    "DEFAULT_MH_RW_SIGMA",
    "DEFAULT_MOVES",
    "MAX_BURN_IN",
    "MAX_JOINT_SAMPLES",
    "MAX_MH_ITER",
    "MAX_MH_RW_SIGMA",
    "MAX_PARTICLES",
    "MH_PROPOSALS",
    "MOVES",
    "MOVES_RULE",
    "joint_samples_error",
    "moves_error",
    "proposal_error",
    "unread_error",
]

#: Most particles one object's filter may have (sis and mh; 48 MB of state per object).
MAX_PARTICLES = 1_000_000
#: Most kept samples of the tracker's joint RJ-MCMC chain (``sampler="rjmcmc"``, where
#: ``particles`` is its N). Its cost per frame grows as N²: each update move evaluates the
#: predictive prior, a mixture over the previous frame's N kept samples; 10000 costs about
#: 0.15 s of CPU a frame with 5 objects (docs/samplers.md). ``RJMCMCFilter`` on its own (a
#: component, for timing the chain) takes up to 2147483647.
MAX_JOINT_SAMPLES = 10_000
#: Most Metropolis-Hastings iterations per particle and frame (``sampler="mh"``): a step
#: evaluates the likelihood ``particles * (mh_iter + 1)`` times per object.
MAX_MH_ITER = 1000
#: Most burn-in iterations of the joint chain per frame: a frame costs O((B + N) N).
MAX_BURN_IN = 100_000
#: MH iterations per particle and frame by default (the paper's setting).
DEFAULT_MH_ITER = 1
#: Burn-in iterations of the joint chain by default (``RJMCMCConfig.burn_in``).
DEFAULT_BURN_IN = 50
#: The Metropolis-Hastings filter's proposals (``sampler="mh"``): a fresh draw of the AR(2)
#: dynamics from a parent chosen at random (the paper's), or a Gaussian random walk from the
#: chain's current state (``pftrack._core.mh_step``'s `proposal`).
MH_PROPOSALS = ("dynamics", "random_walk")
#: The MH proposal by default.
DEFAULT_MH_PROPOSAL = "dynamics"
#: Standard deviations (cx px, cy px, scale) of the random-walk proposal by default (the core's).
DEFAULT_MH_RW_SIGMA = (2.0, 2.0, 0.01)
#: Largest standard deviation of a random-walk step, in any component.
MAX_MH_RW_SIGMA = 10_000.0
#: The joint chain's moves, in the order of ``moves`` (Tracker) and ``--moves`` (CLI).
MOVES = ("birth", "death", "update", "swap")
#: The rule of the birth and death moves, in these words wherever it is stated: ``--moves``'
#: help and refusal, ``RJMCMCConfig``'s docstring and refusal, docs/samplers.md.
MOVES_RULE = "birth and death both > 0 or both 0 (a birth is undone by a death: reversibility)"
#: Their probabilities by default (``RJMCMCConfig``'s ``p_birth``, ``p_death``, ``p_update``,
#: ``p_swap``).
DEFAULT_MOVES = (0.1, 0.1, 0.7, 0.1)


def joint_samples_error(n: int, particles: str, sampler: str) -> str | None:
    """The message refusing `n` kept samples for the joint chain, or None if `n` is taken.

    `particles` and `sampler` name the options as the caller knows them (``--particles`` and
    ``--sampler rjmcmc`` on the command line, ``particles`` and ``sampler='rjmcmc'`` in Python).
    """
    if n <= MAX_JOINT_SAMPLES:
        return None
    return (
        f"{particles} {n} with {sampler}: at most {MAX_JOINT_SAMPLES}. The joint chain's cost "
        "per frame grows as the square of its samples (each of its burn-in + N iterations "
        "weighs a mixture over the previous frame's N samples): about 0.15 s a frame at 10000 "
        "with 5 objects, 1.4 s at 32000"
    )


def moves_error(moves: Sequence[float], what: str) -> str | None:
    """The message refusing the joint chain's move probabilities `moves`, or None if taken.

    `moves` are the probabilities of birth, death, update and swap (:data:`MOVES`), normalised
    by the chain: 4 finite numbers >= 0, not all 0, :data:`MOVES_RULE`. `what` names the option
    (``--moves``, ``moves``).
    """
    shown = " ".join(f"{v:g}" for v in moves)
    if len(moves) != len(MOVES):
        return f"{what} is {shown}, expected 4 probabilities: birth, death, update, swap"
    if not all(math.isfinite(v) and v >= 0 for v in moves):
        return f"{what} is {shown}, expected 4 finite numbers >= 0 (birth, death, update, swap)"
    if sum(moves) <= 0:
        return f"{what} is {shown}: all 0, expected at least one > 0 (birth, death, update, swap)"
    if (moves[0] > 0) != (moves[1] > 0):
        return (
            f"{what} is {shown}: birth {moves[0]:g} and death {moves[1]:g}, expected {MOVES_RULE}"
        )
    return None


def proposal_error(
    proposal: str, rw_sigma: Sequence[float], what: tuple[str, str], *, cli: bool
) -> str | None:
    """The message refusing the MH proposal settings, or None if they are taken.

    `proposal` one of :data:`MH_PROPOSALS`; `rw_sigma` 3 finite numbers in [0,
    :data:`MAX_MH_RW_SIGMA`] (cx, cy in pixels, scale), and only with ``"random_walk"``: the
    dynamics proposal does not read them. `what` names the two options (``("--mh-proposal",
    "--mh-rw-sigma")``, ``("mh_proposal", "mh_rw_sigma")``); `cli` formats the proposal as a
    flag's value (``--mh-proposal dynamics``) instead of a Python string.
    """
    if proposal not in MH_PROPOSALS:
        return f"{what[0]} is {proposal!r}, expected 'dynamics' or 'random_walk'"
    shown = " ".join(f"{v:g}" for v in rw_sigma)
    if len(rw_sigma) != 3:
        return f"{what[1]} is {shown}, expected 3 standard deviations: cx, cy (pixels), scale"
    if not all(math.isfinite(v) and 0 <= v <= MAX_MH_RW_SIGMA for v in rw_sigma):
        return (
            f"{what[1]} is {shown}, expected 3 finite numbers in [0, {MAX_MH_RW_SIGMA:g}] (cx, "
            "cy in pixels, scale)"
        )
    if proposal != "random_walk" and tuple(rw_sigma) != DEFAULT_MH_RW_SIGMA:

        def named(value: str) -> str:
            return f"{what[0]} {value}" if cli else f"{what[0]} {value!r}"

        return (
            f"{what[1]} {shown}: only the random-walk proposal reads it, so it does nothing "
            f"with {named(proposal)}: drop it, or use {named('random_walk')}"
        )
    return None


#: The chain settings one sampler alone reads, by sampler, with their defaults.
CHAIN_SETTINGS: dict[str, dict[str, object]] = {
    "mh": {
        "mh_iter": DEFAULT_MH_ITER,
        "mh_proposal": DEFAULT_MH_PROPOSAL,
        "mh_rw_sigma": DEFAULT_MH_RW_SIGMA,
    },
    "rjmcmc": {"burn_in": DEFAULT_BURN_IN, "moves": DEFAULT_MOVES},
}


def unread_error(sampler: str, settings: dict[str, object], *, cli: bool) -> str | None:
    """The message refusing a chain setting that `sampler` does not read, or None.

    `settings` maps the names of :data:`CHAIN_SETTINGS` (``mh_iter``, ``mh_proposal``,
    ``mh_rw_sigma``, ``burn_in``, ``moves``)
    to the values given; one that is not its default while another sampler than its own runs
    would do nothing, so it is refused (the settings of one other sampler are named at a time).
    `cli` names the options as flags (``--mh-iter 5``, ``--sampler mh``), else as ``Tracker``'s
    arguments (``mh_iter 5``, ``sampler 'mh'``).
    """

    def named(key: str) -> str:
        return f"--{key.replace('_', '-')}" if cli else key

    def sampler_named(name: str) -> str:
        return f"--sampler {name}" if cli else f"sampler {name!r}"

    for reader, defaults in CHAIN_SETTINGS.items():
        if reader == sampler:
            continue
        unread = []
        for key, default in defaults.items():
            value = settings.get(key, default)
            if value is None:
                continue
            if isinstance(value, (tuple, list)):
                if tuple(float(v) for v in value) == default:
                    continue
                shown = " ".join(f"{float(v):g}" for v in value)
            elif value == default:
                continue
            else:
                shown = f"{value}"
            unread.append(f"{named(key)} {shown}")
        if unread:
            one = len(unread) == 1
            return (
                f"{', '.join(unread)}: only {sampler_named(reader)} reads "
                f"{'it' if one else 'them'}, so {'it does' if one else 'they do'} nothing with "
                f"{sampler_named(sampler)}: drop {'it' if one else 'them'}, or use "
                f"{sampler_named(reader)}"
            )
    return None
