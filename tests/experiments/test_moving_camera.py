"""The moving-camera experiment (``python -m experiments.moving_camera``) on a tiny sequence."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

from experiments import moving_camera as mc
from experiments._common import REPO, Source
from pftrack.cli import main as pftrack_main
from pftrack.eval import evaluate_mot
from pftrack.io.mot import read_mot
from pftrack.io.video import read_frames


def test_versions_move_frames_and_boxes_together(data: Path, tmp_path: Path) -> None:
    seq = Source("tiny", "img", 1.0)
    static = mc.make_version(seq, data, tmp_path, "static")
    moving = mc.make_version(seq, data, tmp_path, "moving")
    for folder in (static, moving):
        frames = read_frames(folder / "img1")
        assert len(frames) == 12 and frames[0].shape == (360, 480, 3)
        gt, det = read_mot(folder / "gt.txt"), read_mot(folder / "det.txt")
        np.testing.assert_allclose(gt[:, 2:6], det[:, 2:6])  # one warp for both files
        assert np.all(gt[:, 2:4] >= 0) and np.all(gt[:, 2] + gt[:, 4] <= 480)
    # the static version is the source zoomed by 1.35 about the centre (whole boxes only)
    src = read_mot(data / "tiny" / "gt.txt")
    g_static = read_mot(static / "gt.txt")
    c = np.array([240.0, 180.0])
    for row in g_static[(g_static[:, 4] > 20) & (g_static[:, 2] > 1) & (g_static[:, 2] < 400)]:
        orig = src[(src[:, 0] == row[0]) & (src[:, 1] == row[1])][0]
        want = c + 1.35 * (orig[2:4] + orig[4:6] / 2 - c)
        np.testing.assert_allclose(row[2:4] + row[4:6] / 2, want, atol=1e-6)
    # the moving version is not a fixed offset of it
    g_moving = read_mot(moving / "gt.txt")
    shift = [
        g_moving[(g_moving[:, 0] == f) & (g_moving[:, 1] == 1), 2:4]
        - g_static[(g_static[:, 0] == f) & (g_static[:, 1] == 1), 2:4]
        for f in (1, 12)
    ]
    assert not np.allclose(shift[0], shift[1], atol=1.0)


def test_refuses_an_output_inside_the_repository(data: Path) -> None:
    assert mc.main(["--data", str(data), "--out", str(REPO / "out" / "x")]) == 2


def test_original_row_notes_the_users_figure(
    data: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # the table's original row is a mean over seeds; the note under it must give seed 0's
    # figure, which is `pftrack track` with every default (what measure.sh and README quote)
    seq = Source("tiny", "img", 1.0)
    monkeypatch.setattr(mc, "SEQUENCES", (seq,))
    out = tmp_path / "mc"
    argv = ["--data", str(data), "--out", str(out), "--detections", "public", "--seeds", "2"]
    assert mc.main(argv) == 0
    user = tmp_path / "user.txt"
    det = data / "tiny" / "det.txt"
    assert pftrack_main(["-q", "track", str(data / "tiny" / "img"), "--detections", str(det),
                         "--out", str(user)]) == 0  # fmt: skip
    run = out / "tracks" / "tiny-original-public-auto-0.txt"
    assert run.read_bytes() == user.read_bytes()
    m = evaluate_mot(read_mot(data / "tiny" / "gt.txt"), read_mot(user))
    text = (out / "moving_camera.md").read_text()
    assert f"seed 0 (`pftrack track` with every default, as measure.sh runs it) " \
        f"{100 * m.mota:.1f} / {100 * m.idf1:.1f}; seeds 0-1" in text  # fmt: skip


def test_original_note_gives_seed_0_and_the_range_not_the_mean() -> None:
    scores = np.array([[52.1, 60.7], [39.3, 51.1], [47.1, 54.1]])  # TUD-Campus, built-in
    note = mc.original_note("tud-campus", "builtin", scores, same=True)
    assert "same bytes for every seed" in note
    assert (
        "measure.sh runs it) 52.1 / 60.7; seeds 0-2: MOTA 39.3 to 52.1, IDF1 51.1 to 60.7" in note
    )
    assert "DIFFERENT files" in mc.original_note("x", "public", scores, same=False)
    assert mc.summary(scores) == "46.2 ± 5.3 / 55.3 ± 4.0"  # np.std, ddof 0


@pytest.mark.parametrize(
    ("option", "value", "said"),
    [("--seeds", v, "--seeds") for v in ("0", "-1", "x")]
    + [
        ("--set", v, f"--set {v!r}")
        for v in ("lifecycle.nothing=1", "lifecycle.size_ratio=x", "size")
    ],
)
def test_refuses_bad_seeds_and_settings(
    data: Path, tmp_path: Path, option: str, value: str, said: str,
    capsys: pytest.CaptureFixture[str],
) -> None:  # fmt: skip
    with pytest.raises(SystemExit) as exc:
        mc.main(["--data", str(data), "--out", str(tmp_path), option, value])
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert said in err[-1] and "Traceback" not in "".join(err)
    assert not any(tmp_path.iterdir())  # refused before any work


def test_set_changes_every_runs_config_and_names_its_files(
    data: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # --set applies on top of pftrack track's own options (here --camera-motion) while the
    # runs are made, and its files and table get their own names beside the default's
    seen = []
    track = mc.track_command._track

    def spy(*args: Any, **kwargs: Any) -> Any:
        seen.append((kwargs["config"].lifecycle.size_ratio, kwargs["config"].camera_motion))
        return track(*args, **kwargs)

    monkeypatch.setattr(mc.track_command, "_track", spy)
    monkeypatch.setattr(mc, "SEQUENCES", (Source("tiny", "img", 1.0),))
    out = tmp_path / "mc"
    argv = ["--data", str(data), "--out", str(out), "--detections", "public", "--seeds", "1"]
    assert mc.main([*argv, "--set", "lifecycle.size_ratio=0.7"]) == 0
    assert sorted(seen) == [(0.7, "auto")] * 3 + [(0.7, "off")] * 3
    assert len(list((out / "tracks-lifecycle.size_ratio0.7").iterdir())) == 6
    assert (out / "moving_camera-lifecycle.size_ratio0.7.md").is_file()
    seen.clear()
    assert mc.main(argv) == 0  # without --set: every default, the files of old
    assert sorted(seen) == [(0.8, "auto")] * 3 + [(0.8, "off")] * 3
    assert len(list((out / "tracks").iterdir())) == 6 and (out / "moving_camera.md").is_file()
