"""``pftrack batch`` prints each sequence's warnings as its outcome arrives, before the table.

Was: every warning after the summary table, once the whole batch was over, where ``pftrack
track`` prints its own as they are raised: a long batch's warnings said nothing while it ran.
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

import pftrack.batch.engine as engine
from pftrack.cli import main
from pftrack.synthetic import make_scene

FAST = ["--particles", "30"]


class _Stream:
    """stdout or stderr, writing into one shared list of (stream, text): their order."""

    def __init__(self, tag: str, said: list[tuple[str, str]]) -> None:
        self.tag, self.said = tag, said

    def write(self, text: str) -> int:
        self.said.append((self.tag, text))
        return len(text)

    def flush(self) -> None:
        pass

    def isatty(self) -> bool:
        return False


def _run(argv: list[str], monkeypatch: pytest.MonkeyPatch) -> list[tuple[str, str]]:
    said: list[tuple[str, str]] = []
    call_task = engine.call_task

    def task(func, args, *rest):  # type: ignore[no-untyped-def]
        said.append(("task", f"{args[0]}"))  # the task's start, among the lines
        return call_task(func, args, *rest)

    monkeypatch.setattr(engine, "call_task", task)
    monkeypatch.setattr(sys, "stdout", _Stream("out", said))
    monkeypatch.setattr(sys, "stderr", _Stream("err", said))
    assert main(argv) == 0
    monkeypatch.undo()
    return said


def test_each_sequences_warning_comes_as_it_ends_and_before_the_table(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    for name in ("a", "b"):  # three frames of one walker: no track, and the tracker warns
        scene = make_scene(n_frames=3, width=64, height=64, n_walkers=1, rng=0)
        scene.write_images(tmp_path / "in" / name)
    argv = ["batch", str(tmp_path / "in"), "--out", str(tmp_path / "out"), "--workers", "0"]
    said = _run([*argv, *FAST], monkeypatch)
    order = [
        "a" if tag == "task" and "/a" in text else
        "b" if tag == "task" and "/b" in text else
        text.split(": warning: ")[0] + " warned" if ": warning: " in text else
        "table" if tag == "out" and text.startswith("name ") else None
        for tag, text in said
    ]  # fmt: skip
    assert [o for o in order if o] == ["a", "a warned", "b", "b warned", "table"], said
    warned = [t for tag, t in said if tag == "err" and "no track over 3" in t]
    assert len(warned) == 2  # each once: not again with the table (b's: "the same as a's")

    # a re-run skips both: their earlier warnings (the summary's) come before the table too,
    # alike ones in one line (test_warnings_said_once.py)
    again = _run([*argv, *FAST], monkeypatch)
    text = "".join(t for _, t in again)
    assert text.count("2 sequences (a, b): warning: no track over 3") == 1, again
    assert text.rindex(": warning: ") < text.index("name "), again


def test_a_say_that_is_not_callable_is_refused_at_once() -> None:
    with pytest.raises(TypeError, match="say is str 'NAME: warning', expected a callable"):
        with engine.warnings_as_they_come("NAME: warning"):  # type: ignore[arg-type]
            pass
