"""experiments.person_size: every fit of the size model, and the rows under other sizes."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from experiments import person_size


@pytest.mark.filterwarnings("ignore:the video is grey:UserWarning")  # the case asked for
def test_fits_are_listed_and_the_last_size_gives_the_runs_rows(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # main() raises unless finalize() again with the last fit gives the run's own rows
    person_size.main(
        ["--sequences", "walkers", "--variants", "grey", "--fits", "--out", str(tmp_path)]
    )
    out = capsys.readouterr().out
    n = int(re.search(r"walkers grey: (\d+) fits", out).group(1))  # type: ignore[union-attr]
    fits = re.findall(r"fit +\d+: seen +\d+ held +\d+ feet \d+-\d+ .*h (-?[\d.]+) y", out)
    assert n == len(fits) >= 2
    # the diagnosis of docs/detection.md: the first fit, from the first walkers only (their
    # feet on a few rows, each walker its own size), learns a height slope above 1 in a scene
    # with no perspective; the last does not
    assert float(fits[0]) > 1.0 > float(fits[-1])
    scores = dict(re.findall(r"^  (\w+|1px[-+]) +(-?[\d.]+ / -?[\d.]+ / -?[\d.]+)", out, re.M))
    assert set(scores) == {*person_size.SIZES, "1px-", "1px+"}
    assert scores["median"] != scores["last"]
    assert (tmp_path / "person_size.txt").read_text() == out


def test_bad_arguments_are_one_line(capsys: pytest.CaptureFixture[str]) -> None:
    for args, message in (
        (["--hold-frames", "-1"], "--hold-frames is -1, expected 0 (off) or more"),
        (["--variants", "crop"], "unknown sequence(s) or variant(s): crop"),
    ):
        with pytest.raises(SystemExit) as e:
            person_size.main(["--sequences", "walkers", *args])
        assert e.value.code == 2, args
        assert message in capsys.readouterr().err
