"""``experiments.perturbed_gaps``: the perturbations and the table, on tiny synthetic scenes."""

from __future__ import annotations

import numpy as np
import pytest

from experiments import perturbed_gaps as ex
from pftrack.recovery.experiment import run_sequence, trajectories
from pftrack.synthetic import make_scene


@pytest.fixture(scope="module")
def rows() -> np.ndarray:
    return make_scene(n_frames=60, n_walkers=4, rng=2).truth


def test_pan_moves_every_box_of_a_frame_alike_and_draws_nothing(rows: np.ndarray) -> None:
    a = ex.perturbed("s", rows, 480.0, 360.0, 10.0, "pan", seed=0)
    b = ex.perturbed("s", rows, 480.0, 360.0, 10.0, "pan", seed=5)
    np.testing.assert_array_equal(a, b)
    shift = a[:, 2:4] - rows[:, 2:4]
    for f in np.unique(rows[:, 0]):
        s = shift[rows[:, 0] == f]
        np.testing.assert_allclose(s, np.broadcast_to(s[0], s.shape), atol=1e-9)
    assert np.abs(shift[:, 0]).max() > 0.05 * 480  # a pan of up to 8 % of the width
    np.testing.assert_array_equal(a[:, 4:], rows[:, 4:])  # sizes, ids, frames as they were


def test_shake_is_seeded_and_per_frame(rows: np.ndarray) -> None:
    a = ex.perturbed("s", rows, 480.0, 360.0, 10.0, "shake", seed=1)
    np.testing.assert_array_equal(a, ex.perturbed("s", rows, 480.0, 360.0, 10.0, "shake", seed=1))
    assert not np.array_equal(a, ex.perturbed("s", rows, 480.0, 360.0, 10.0, "shake", seed=2))
    assert not np.array_equal(a, ex.perturbed("t", rows, 480.0, 360.0, 10.0, "shake", seed=1))
    shift = a[:, 2:4] - rows[:, 2:4]
    first = rows[:, 0] == rows[0, 0]
    np.testing.assert_allclose(shift[first], np.broadcast_to(shift[first][0], shift[first].shape))


def test_half_fps_keeps_odd_frames_renumbered(rows: np.ndarray) -> None:
    a = ex.perturbed("s", rows, 480.0, 360.0, 10.0, "halffps", seed=0)
    odd = rows[rows[:, 0] % 2 == 1]
    np.testing.assert_array_equal(a[:, 1:], odd[:, 1:])
    np.testing.assert_array_equal(a[:, 0], (odd[:, 0] + 1) // 2)
    assert a[:, 0].min() == 1


def test_jitter_scales_with_box_height(rows: np.ndarray) -> None:
    a = ex.perturbed("s", rows, 480.0, 360.0, 10.0, "jitter", seed=0)
    d = (a[:, 2:4] - rows[:, 2:4]) / rows[:, 5:6]
    assert 0.015 < float(np.std(d)) < 0.025  # N(0, (0.02 h)^2) per axis
    np.testing.assert_array_equal(a[:, 4:], rows[:, 4:])


def test_table_marks_auto_worse_than_linear_and_pools_by_gaps(rows: np.ndarray) -> None:
    res = {
        how: [
            run_sequence(
                f"tiny-{how}",
                trajectories(ex.perturbed("tiny", rows, 480.0, 360.0, 10.0, how, 0)),
                480.0,
                360.0,
                ("auto", "linear", "rts"),
            )
        ]
        for how in ("pan", "halffps")
    }
    text = ex.format_table(res)
    for how, (r,) in res.items():
        assert r.n_gaps > 0
        line = next(ln for ln in text.splitlines() if ln.startswith(f"tiny-{how} "))
        assert f"{r.mmae('auto'):.3f}" in line and f"{r.mmae('linear'):.3f}" in line
        assert ("<" in line) == (r.mmae("auto") > r.mmae("linear"))
        pooled = next(ln for ln in text.splitlines() if ln.startswith(f"pooled {how} "))
        assert f"{r.mmae('auto'):.3f}" in pooled  # one sequence: its own figures
    worse = [r.name for rs in res.values() for r in rs if r.mmae("auto") > r.mmae("linear")]
    assert text.splitlines()[-1] == f"worse than linear: {', '.join(worse) or 'none'}"


def test_help_shows_the_seed_default(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as e:
        ex.main(["--help"])
    assert e.value.code == 0
    assert "seed of shake and jitter (default: 0)" in " ".join(capsys.readouterr().out.split())


def test_negative_seed_is_refused(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as e:
        ex.main(["--seed", "-1"])
    assert e.value.code == 2
    assert "--seed is -1, expected >= 0" in capsys.readouterr().err
