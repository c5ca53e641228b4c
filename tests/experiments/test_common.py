"""What the experiment scripts share (``experiments._common``): finding the data's folders."""

from __future__ import annotations

from pathlib import Path

import pytest

from experiments import compare_trackers
from experiments._common import (
    NO_VIDEO,
    PETS,
    TUD,
    Source,
    data_folder,
    no_video_folders,
    video_folders,
)


def test_data_folder_is_the_folder_given_or_none_said_on_stderr(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert data_folder(tmp_path) == tmp_path
    assert capsys.readouterr().err == ""
    assert data_folder(tmp_path / "absent") is None
    assert capsys.readouterr().err == (
        f"data folder not found: {tmp_path / 'absent'} (set --data or PFTRACK_DATA)\n"
    )


def test_an_experiment_without_its_data_folder_exits_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert compare_trackers.main(["--data", str(tmp_path / "absent")]) == 2
    assert capsys.readouterr().err.startswith("data folder not found: ")


def test_video_folders_in_order_and_a_missing_one_said_where_it_would_stand(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / TUD.name).mkdir()
    (tmp_path / "tiny").mkdir()
    tiny = Source("tiny", "img", 1.0)
    found = []
    for src, folder in video_folders(tmp_path, (PETS, tiny, TUD)):
        print(f"ran {src.name}")
        found.append((src, folder))
    assert found == [(tiny, tmp_path / "tiny"), (TUD, tmp_path / TUD.name)]
    assert capsys.readouterr().out.splitlines() == [
        f"pets09-s2l1: not found under {tmp_path}, skipped",
        "ran tiny",
        "ran tud-campus",
    ]
    assert [src for src, _ in video_folders(tmp_path)] == [TUD]  # PETS09 and TUD by default


def test_no_video_folders_are_those_of_mot15_gt_present(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert NO_VIDEO == ("ADL-Rundle-6", "ETH-Sunnyday", "KITTI-17")
    (tmp_path / "mot15-gt" / "KITTI-17").mkdir(parents=True)
    assert list(no_video_folders(tmp_path)) == [("KITTI-17", tmp_path / "mot15-gt" / "KITTI-17")]
    assert capsys.readouterr().out.splitlines() == [
        f"{name}: not found under {tmp_path / 'mot15-gt'}, skipped"
        for name in ("ADL-Rundle-6", "ETH-Sunnyday")
    ]


@pytest.mark.parametrize("module", ["moving_camera", "slow_camera", "size_check", "person_size"])
def test_bad_usage_is_one_line_and_status_2(
    module: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """As ``pftrack``'s own commands (was: argparse's whole usage, four to six lines, first);
    an ``--out`` under a file (was: ``mkdir``'s traceback once the arguments were checked)."""
    import importlib

    main = importlib.import_module(f"experiments.{module}").main
    (tmp_path / "file").write_text("")
    for args, message in (
        (["--nonesuch"], "unrecognized arguments: --nonesuch"),
        (["--out", str(tmp_path / "file" / "out")], f"--out {tmp_path / 'file' / 'out'}: "
         f"{tmp_path / 'file'} is not a folder"),
    ):  # fmt: skip
        with pytest.raises(SystemExit) as e:
            main(args)
        err = capsys.readouterr().err
        assert e.value.code == 2
        assert err == f"python -m experiments.{module}: error: {message}\n"
