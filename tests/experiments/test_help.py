"""Every experiment's ``--help`` names it as it is run and states each option's default."""

from __future__ import annotations

import importlib

import pytest


@pytest.mark.parametrize(
    ("name", "shown"),
    [
        ("recovery_linking_pets", "--seed SEED (default: 0)"),  # 0: a default like any other
        ("soak", "(default: 10000)"),
        ("given_particles", "(default: 25)"),
        ("python_share", "--rounds ROUNDS rounds per case (default 7)"),
        ("peer_gap_filling", "--max-gap MAX_GAP most missing frames filled"),
    ],
)
def test_help_names_the_module_and_shows_defaults(
    name: str, shown: str, capsys: pytest.CaptureFixture[str]
) -> None:
    module = importlib.import_module(f"experiments.{name}")
    with pytest.raises(SystemExit) as e:
        module.main(["--help"])
    assert e.value.code == 0
    text = " ".join(capsys.readouterr().out.split())
    assert text.startswith(f"usage: python -m experiments.{name}")  # python_share: was its file
    assert shown in text
