"""A batch's ``--render`` replaces only a video pftrack wrote, as ``pftrack track --render`` does.

Stop 70's trial: a user's own video copied to ``results/scene.mp4``, where an earlier batch's
render had been, was replaced by the next ``pftrack batch --render`` (exit 0, with a "redone"
note at best): the sidecar named the file, and a file a sidecar names was taken as the batch's
whatever it held.
"""

from __future__ import annotations

import hashlib
from dataclasses import replace
from pathlib import Path

import pytest

from pftrack.batch import TrackOptions, track_many
from pftrack.cli import main
from pftrack.io.video_writer import is_render
from pftrack.synthetic import make_scene
from pftrack.tracking import TrackerConfig


def _options() -> TrackOptions:
    base = TrackerConfig()
    return TrackOptions(
        config=replace(base, filter=replace(base.filter, n_particles=30)), render=".mp4"
    )


def _sha(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


@pytest.fixture
def rendered(tmp_path: Path) -> tuple[Path, Path, Path]:
    """A folder of one video, a batch's results with its render, and a user's own video."""
    videos = tmp_path / "videos"
    videos.mkdir()
    make_scene(n_frames=12, width=160, height=120, n_walkers=2, rng=3).write_video(
        videos / "walk.mp4"
    )
    out = tmp_path / "results"
    first = track_many(videos, out, options=_options(), n_workers=0)
    assert first.entries[0]["status"] == "done" and is_render(out / "walk.mp4")
    mine = tmp_path / "mine.mp4"  # a video pftrack did not write (OpenCV's mp4v, no mark)
    make_scene(n_frames=5, width=160, height=120, n_walkers=1, rng=4).write_video(mine)
    assert not is_render(mine)
    return videos, out, mine


@pytest.mark.parametrize("txt", ["kept", "missing"])
def test_a_users_video_where_a_batch_render_was_is_refused(
    rendered: tuple[Path, Path, Path], txt: str, capsys: pytest.CaptureFixture[str]
) -> None:
    videos, out, mine = rendered
    (out / "walk.mp4").write_bytes(mine.read_bytes())
    if txt == "missing":  # the sequence is to be redone anyway
        (out / "walk.txt").unlink()
    before = _sha(out / "walk.mp4")
    argv = ["batch", str(videos), "--out", str(out), "--render", "--workers", "0", "-q"]
    argv += ["--particles", "30"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err == (
        f"pftrack batch: error: --render's output {out / 'walk.mp4'} is a video pftrack did not "
        "write (a video of yours, put where an earlier batch's was?); this run would replace "
        "it: move it, write elsewhere, or give --force\n"
    )
    assert _sha(out / "walk.mp4") == before  # the user's video as it was
    with pytest.raises(ValueError, match=r"give force=True$"):
        track_many(videos, out, options=_options(), n_workers=0)
    assert _sha(out / "walk.mp4") == before
    # --force replaces it with the batch's render
    assert main([*argv, "--force"]) == 0
    assert is_render(out / "walk.mp4")


def test_a_batch_render_an_empty_file_or_pftrack_render_is_still_replaced(
    rendered: tuple[Path, Path, Path],
) -> None:
    videos, out, _ = rendered
    assert track_many(videos, out, options=_options(), n_workers=0).entries[0]["status"] == (
        "skipped"
    )
    (out / "walk.mp4").write_bytes(b"")  # emptied: redone, as before
    again = track_many(videos, out, options=_options(), n_workers=0)
    assert again.entries[0]["status"] == "done" and is_render(out / "walk.mp4")
    # pftrack render's own video there (the same mark): taken as a render to redo
    argv = ["render", str(videos / "walk.mp4"), str(out / "walk.txt"), "--trail", "3"]
    assert main([*argv, "--out", str(out / "other.mp4"), "-q"]) == 0
    (out / "other.mp4").replace(out / "walk.mp4")
    again = track_many(videos, out, options=_options(), n_workers=0)
    assert again.entries[0]["status"] == "done" and is_render(out / "walk.mp4")
