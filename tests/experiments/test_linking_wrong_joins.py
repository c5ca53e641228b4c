"""The fragments and the wrong-join count of ``experiments.linking_wrong_joins``."""

from __future__ import annotations

import numpy as np

from experiments.linking_wrong_joins import fragment, mixed


def _gt() -> np.ndarray:
    rows = []
    for tid in (1, 2):
        f = np.arange(1.0, 201.0)
        rows.append(np.column_stack([f, np.full(200, tid), 10 * tid + f, f, np.full((200, 2), 20.0),
                                     np.ones(200), -np.ones((200, 3))]))  # fmt: skip
    return np.vstack(rows)


def test_fragments_keep_their_identity_and_never_mix_without_swaps() -> None:
    frag = fragment(_gt(), np.random.default_rng(0))
    assert len(np.unique(frag[:, 1])) > 2 and mixed(frag) == 0
    for i in np.unique(frag[:, 1]):  # each fragment one identity, 10-59 rows
        own = frag[frag[:, 1] == i]
        assert len(np.unique(own[:, 7])) == 1 and 1 <= len(own) < 60
    assert set(np.unique(frag[:, 7])) == {1.0, 2.0}


def test_swapped_tails_are_counted_as_mixed() -> None:
    frag = fragment(_gt(), np.random.default_rng(0), swap=1.0)
    assert mixed(frag) > 0
    joined = frag.copy()
    joined[:, 1] = 7  # everything one id: one id holding two identities
    assert mixed(joined) == 1
