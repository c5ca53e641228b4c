"""The sampler experiment (``python -m experiments.sampler_experiment``) on tiny inputs."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest

from experiments import sampler_experiment as se
from pftrack.synthetic import Scene, make_scene
from tests.conftest import dataset


@pytest.fixture(scope="module")
def scene() -> Scene:
    return make_scene(n_frames=24, n_walkers=2, rng=3, occluder=False)


def test_same_budget_and_only_the_sampler_differs() -> None:
    a, b = se.config_for("sis", 37), se.config_for("rjmcmc", 37)
    assert a.filter.n_particles == b.filter.n_particles == 37
    assert replace(a, sampler="rjmcmc") == b


def test_all_samplers_run_and_table_lists_them(scene: Scene) -> None:
    run = se.synthetic_run(scene)
    res = [
        se.run_sampler(
            run["source"],
            run["gt"],
            s,
            detections=None,
            gt_scale=1.0,
            image_size=run["image_size"],
            particles=30,
            sequence="syn",
            detector="own",
        )
        for s in se.SAMPLERS
    ]
    table = se.format_table(res).splitlines()
    assert len(table) == 2 + 3
    assert [r.sampler for r in res] == list(se.SAMPLERS)
    for r in res:
        assert 0.0 <= r.metrics.success_rate <= 1.0 and r.fps > 0
        assert r.metrics.num_objects == len(scene.truth)


def test_time_per_frame_grows_with_particles(scene: Scene) -> None:
    # SIS cost grows with N (sub-linearly at small N: integral histograms share work between
    # overlapping particle boxes). 128x the particles must cost clearly more, whatever the load:
    # measured 0.17 ms at 25 and 2.3 ms at 3200 particles per frame
    small = min(se.time_per_frame(scene, "sis", 25) for _ in range(3))
    large = min(se.time_per_frame(scene, "sis", 3200) for _ in range(3))
    assert large > 3 * small
    assert se.time_per_frame(scene, "rjmcmc", 25) > 0


def test_crossing_frame_is_where_walkers_1_and_2_overlap() -> None:
    s = make_scene(n_frames=120, n_walkers=2, rng=0)
    f = se.crossing_frame(s)
    rows = s.truth[s.truth[:, 0] == f]
    a, b = rows[rows[:, 1] == 1][0], rows[rows[:, 1] == 2][0]
    assert abs((a[2] + a[4] / 2) - (b[2] + b[4] / 2)) < (a[4] + b[4]) / 2


def test_figures_are_small_pngs(tmp_path: Path) -> None:
    s = make_scene(n_frames=60, n_walkers=2, rng=0)
    p = se.occlusion_figure(s, tmp_path / "occ.png", particles=30, offset=4)
    assert p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and p.stat().st_size < 300_000
    pts = {k: [(1.0, 1.0), (2.0, 2.5)] for k in se.SAMPLERS}
    q = se.plot_timing(pts, pts, tmp_path / "t.png", 30, 2)
    assert q.read_bytes()[:4] == b"\x89PNG" and q.stat().st_size < 300_000


@pytest.mark.dataset
def test_real_sequences_first_frames() -> None:
    runs = se.real_sequences(dataset("tud-campus").parent, max_frames=8)
    assert {r["sequence"] for r in runs} <= {"PETS09-S2L1", "TUD-Campus"}
    tud = [r for r in runs if r["sequence"] == "TUD-Campus"][0]
    assert len(tud["source"]) == 8 and tud["gt"][:, 0].max() <= 8
    res = se.run_sampler(
        tud["source"],
        tud["gt"],
        "rjmcmc",
        detections=tud["detections"],
        gt_scale=1.0,
        image_size=tud["image_size"],
        particles=30,
    )
    assert res.metrics.num_objects == len(tud["gt"]) and res.n_tracks >= 1


def test_the_figures_need_matplotlib_and_say_so_before_any_work(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    # was: the whole table run, then "ModuleNotFoundError: No module named 'PIL'"
    import importlib.util

    from experiments import sampler_experiment

    real = importlib.util.find_spec
    monkeypatch.setattr(
        importlib.util, "find_spec", lambda name, *a: None if name == "PIL" else real(name, *a)
    )
    monkeypatch.setattr(sampler_experiment, "real_sequences", _no_work)
    with pytest.raises(SystemExit) as exc:
        sampler_experiment.main(["--skip-timing"])
    assert exc.value.code == 2
    assert "the figures need PIL, which pftrack does not install" in capsys.readouterr().err


def _no_work(*args: object) -> list[object]:
    raise AssertionError("work started")


@pytest.mark.parametrize(
    ("args", "said"),
    [
        (["--particles", "0"], "argument --particles: expected an integer in [1, 10000], got 0"),
        (["--particles", "10001"], "expected an integer in [1, 10000], got 10001"),
        (["--seed", "-1"], "argument --seed: expected an integer >= 0, got -1"),
        (["--max-walkers", "0"], "argument --max-walkers: expected an integer in [1, 40], got 0"),
        (["--max-walkers", "41"], "expected an integer in [1, 40], got 41"),
        (["--max-frames", "0"], "argument --max-frames: expected an integer >= 1, got 0"),
    ],
)
def test_bad_values_are_refused_before_any_work(
    args: list[str], said: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Was: --particles 0 and --seed -1 a traceback (exit 1) after the sequences were read,
    --max-walkers 41 one after the whole table had run (make_scene takes 1..40), --max-walkers
    0 and --max-frames 0 taken (no timing rows; every frame)."""
    with pytest.raises(SystemExit) as e:
        se.main([*args, "--skip-timing", "--skip-figure", "--out", str(tmp_path / "out")])
    assert e.value.code == 2
    assert said in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


def test_the_chain_flags_reach_every_sampler(
    scene: Scene, monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    """``--mh-iter``, ``--mh-proposal``, ``--mh-rw-sigma``, ``--burn-in`` and ``--moves`` are
    ``pftrack track``'s flags (its defaults, ranges and checks) and reach the runs; the
    experiment had no flag for them (developer trial, 6 December)."""
    from pftrack.tracking import TrackerConfig

    seen: list[TrackerConfig | None] = []

    class Stop(Exception):
        pass

    def first_run(*args: object, base: TrackerConfig | None = None, **kwargs: object) -> None:
        seen.append(base)
        raise Stop

    monkeypatch.setattr(se, "run_sampler", first_run)
    monkeypatch.setattr(se, "real_sequences", lambda *a: [])
    monkeypatch.setattr(se, "make_scene", lambda **k: scene)
    common = ["--out", str(tmp_path), "--skip-timing", "--skip-figure"]
    chain = ["--mh-iter", "3", "--mh-proposal", "random_walk", "--mh-rw-sigma", "3", "3", "0.02",
             "--burn-in", "20", "--moves", "0.2", "0.2", "0.5", "0.1"]  # fmt: skip
    for argv in (common, [*common, *chain]):
        with pytest.raises(Stop):
            se.main(argv)
    default, given = seen
    assert default == TrackerConfig()  # today's values: the experiment's runs unchanged
    assert (given.mh_iter, given.mh_proposal, given.mh_rw_sigma) == (3, "random_walk",
                                                                     (3.0, 3.0, 0.02))  # fmt: skip
    r = given.rjmcmc
    assert (r.burn_in, r.p_birth, r.p_death, r.p_update, r.p_swap) == (20, 0.2, 0.2, 0.5, 0.1)
    cfg = se.config_for("mh", 30, given)
    assert (cfg.sampler, cfg.filter.n_particles, cfg.mh_iter) == ("mh", 30, 3)


@pytest.mark.parametrize(
    ("argv", "words"),
    [
        (["--moves", "0.1", "0", "0.7", "0.1"], "expected birth and death both > 0 or both 0"),
        (["--mh-rw-sigma", "3", "3", "0.02"], "only the random-walk proposal reads it"),
        (["--mh-iter", "0"], "argument --mh-iter: expected an integer in [1, 1000], got 0"),
        (["--mh-proposal", "gibbs"], "argument --mh-proposal: invalid choice: 'gibbs'"),
    ],
)
def test_a_bad_chain_flag_exits_2_before_any_work(
    argv: list[str], words: str, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    with pytest.raises(SystemExit) as stop:
        se.main(["--out", str(tmp_path), "--skip-timing", "--skip-figure", *argv])
    assert stop.value.code == 2
    assert words in capsys.readouterr().err.splitlines()[-1]


def test_time_per_frame_runs_the_configured_mh_chain(
    scene: Scene, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The timing's MH filters take the configuration's chain, as the tracker's do (they ran
    ``n_iter=1`` whatever it said)."""
    from pftrack.tracking import TrackerConfig

    made: list[tuple[int, str]] = []

    class Recording(se.MHColourParticleFilter):
        def __init__(self, *args: object, **kwargs: object) -> None:
            super().__init__(*args, **kwargs)  # type: ignore[arg-type]
            made.append((self.n_iter, self.proposal))

    monkeypatch.setattr(se, "MHColourParticleFilter", Recording)
    base = replace(TrackerConfig(), mh_iter=2, mh_proposal="random_walk")
    assert se.time_per_frame(scene, "mh", 20, base=base) > 0
    assert made and set(made) == {(2, "random_walk")}
