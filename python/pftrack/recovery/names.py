"""The recovery methods by name.

Constants only, so that the command line can list them without loading the methods (and SciPy).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Final

if TYPE_CHECKING:  # the command line lists the names without loading NumPy
    from pftrack._typing import RecoveryMethod

__all__ = ["DEFAULT_METHOD", "GOAL_DIRECTED_METHODS", "METHODS", "NEIGHBOUR_METHODS"]

#: Every method, in the order tables list them.
METHODS: tuple[RecoveryMethod, ...] = (
    "auto", "gdt", "gdt-bi", "gdt-mix", "gdt-fixed", "linear", "cubic", "bspline", "gsi", "rts",
    "linear-nb", "rts-nb",
)  # fmt: skip
#: A baseline corrected by the errors of the other tracks seen over the gap's frames
#: (:mod:`pftrack.recovery.neighbours`): they read the whole file, as ``"auto"`` does.
NEIGHBOUR_METHODS: tuple[RecoveryMethod, ...] = ("linear-nb", "rts-nb")
#: The methods solved for all gaps at once (pftrack's own and the calibrated ``"auto"``).
GOAL_DIRECTED_METHODS: tuple[RecoveryMethod, ...] = (
    "auto",
    "gdt",
    "gdt-bi",
    "gdt-mix",
    "gdt-fixed",
)
#: The method of :func:`~pftrack.recovery.recover_gap`, ``recover_gaps``, ``fill_gaps`` and
#: ``pftrack recover``.
DEFAULT_METHOD: Final = "auto"
