"""The NumPy models of ``experiments.recovery_variants`` (behind docs/recovery.md)."""

from __future__ import annotations

import numpy as np
import pytest

from experiments import recovery_variants as rv
from pftrack.kalman import cv_transition_xy, wna_Q_xy
from pftrack.recovery import recover_gap


def test_ou_velocity_without_reversion_is_white_noise_acceleration() -> None:
    F, Q = rv.iou_model(0.3, np.inf)
    A = cv_transition_xy(1.0)
    np.testing.assert_allclose(F, A[np.ix_([0, 2], [0, 2])], atol=1e-12)
    np.testing.assert_allclose(Q, wna_Q_xy((0.3, 0.3))[np.ix_([0, 2], [0, 2])], atol=1e-12)


def test_ou_velocity_decays_and_noise_is_stationary() -> None:
    tau, q = 5.0, 0.2
    F, Q = rv.iou_model(q, tau)
    assert F[1, 1] == pytest.approx(np.exp(-1.0 / tau))
    assert F[0, 1] == pytest.approx(tau * (1.0 - np.exp(-1.0 / tau)))
    # stationary velocity variance q tau / 2 is kept by one step
    s = q * tau / 2.0
    assert F[1, 1] ** 2 * s + Q[1, 1] == pytest.approx(s)
    assert np.all(np.linalg.eigvalsh(Q) > 0)


def test_smoother_recovers_a_line_like_gdt_bi() -> None:
    t = np.arange(40.0)
    track = np.column_stack([t, 3.0 + 1.5 * t, 10.0 - 0.5 * t])
    a, b, truth = track[:15], track[25:], track[15:25]
    F, Q = rv.iou_model(0.1, np.inf)
    for axis in range(2):
        path, ll = rv.smooth_gap(F, Q, 0.01, a, b, axis)
        np.testing.assert_allclose(path, truth[:, 1 + axis], atol=1e-6)
        assert np.isfinite(ll)
    np.testing.assert_allclose(recover_gap(a, b, method="gdt-bi"), truth[:, 1:3], atol=1e-6)
