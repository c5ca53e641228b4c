"""Progress bars: tqdm's rate and time left on a terminal, nothing otherwise or when quiet."""

from __future__ import annotations

import io
import os
import select
import struct
import sys
from collections.abc import Callable

import numpy as np
import pytest

from pftrack import _progress
from pftrack._progress import progress, set_quiet


@pytest.fixture(autouse=True)
def loud(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(_progress, "_quiet", False)
    monkeypatch.setattr(_progress, "DELAY", 0.0)


def _run(monkeypatch: pytest.MonkeyPatch, tty: bool, **kwargs: object) -> tuple[list[int], str]:
    err = io.StringIO()
    err.isatty = lambda: tty  # type: ignore[method-assign]
    monkeypatch.setattr(sys, "stderr", err)
    got = list(progress(range(50), desc="work", unit="gap", **kwargs))  # type: ignore[arg-type]
    return got, err.getvalue()


def test_bar_shows_count_rate_and_time_left_on_a_terminal(monkeypatch: pytest.MonkeyPatch) -> None:
    got, text = _run(monkeypatch, tty=True)
    assert got == list(range(50))
    assert "work" in text and "50/50" in text and "gap/s" in text and "<" in text  # ETA


def test_silent_when_not_a_terminal_or_quiet(monkeypatch: pytest.MonkeyPatch) -> None:
    assert _run(monkeypatch, tty=False) == (list(range(50)), "")
    set_quiet(True)
    assert _run(monkeypatch, tty=True) == (list(range(50)), "")
    assert _run(monkeypatch, tty=True, enable=True)[1] == ""  # quiet wins over enable
    set_quiet(False)
    assert "50/50" in _run(monkeypatch, tty=False, enable=True)[1]


def test_a_quick_loop_draws_nothing(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(_progress, "DELAY", 10.0)
    assert _run(monkeypatch, tty=True)[1] == ""


def test_total_defaults_to_the_length(monkeypatch: pytest.MonkeyPatch) -> None:
    err = io.StringIO()
    monkeypatch.setattr(sys, "stderr", err)
    assert list(progress([1, 2, 3], enable=True)) == [1, 2, 3]
    assert "3/3" in err.getvalue()
    err.truncate(0)
    assert list(progress(iter([1, 2, 3]), enable=True)) == [1, 2, 3]
    assert "3it" in err.getvalue()  # unknown total: the count alone


def test_no_stderr_draws_nothing(monkeypatch: pytest.MonkeyPatch) -> None:
    # a process started with stderr closed (2>&-) has sys.stderr None: was AttributeError on
    # its isatty, so `pftrack track ... 2>&-` exited 1 without writing its tracks
    monkeypatch.setattr(sys, "stderr", None)
    assert not _progress.enabled()
    assert list(progress(range(5), desc="work")) == list(range(5))


def test_bar_moved_by_hand(monkeypatch: pytest.MonkeyPatch) -> None:
    err = io.StringIO()
    monkeypatch.setattr(sys, "stderr", err)
    with _progress.Bar(120, desc="0/2 sequences", enable=True, unit="frame") as bar:
        assert bar.enabled
        bar.set(50)
        bar.set(120)
        bar.describe("2/2 sequences")
    assert "2/2 sequences" in err.getvalue() and "120/120" in err.getvalue()
    set_quiet(True)
    with _progress.Bar(10, enable=True) as bar:
        assert not bar.enabled
        bar.set(5)  # nothing drawn, no error
    set_quiet(False)


def _on_a_terminal(
    monkeypatch: pytest.MonkeyPatch, rows: int, cols: int, draw: Callable[[], None]
) -> str:
    """What `draw` writes on stderr when it is a pseudo-terminal of `rows` x `cols` (0: unset)."""
    pty = pytest.importorskip("pty")
    fcntl = pytest.importorskip("fcntl")
    termios = pytest.importorskip("termios")
    master, slave = pty.openpty()
    try:
        fcntl.ioctl(slave, termios.TIOCSWINSZ, struct.pack("HHHH", rows, cols, 0, 0))
        err = open(slave, "w", encoding="utf-8", closefd=False)  # noqa: SIM115
        monkeypatch.setattr(sys, "stderr", err)
        assert err.isatty()
        draw()
        err.flush()
        out = b""
        while select.select([master], [], [], 0.2)[0]:
            out += os.read(master, 65536)
        return out.decode("utf-8", "replace")
    finally:
        os.close(master)
        os.close(slave)


@pytest.mark.parametrize(("rows", "cols"), [(0, 0), (0, 120), (30, 0), (30, 120)])
def test_bar_is_drawn_on_a_terminal_of_any_size(
    monkeypatch: pytest.MonkeyPatch, rows: int, cols: int
) -> None:
    """A terminal whose size is unset (``script``'s, CI runners') hid every bar: -1 lines."""

    def draw() -> None:
        with _progress.Bar(795, desc="0/1 sequences", unit="frame") as bar:
            for n in [*range(0, 795, 100), 795]:
                bar.set(n)
        assert list(progress(range(5), desc="work", unit="gap")) == list(range(5))

    text = _on_a_terminal(monkeypatch, rows, cols, draw)
    assert "0/1 sequences" in text and "795/795" in text and "frame/s" in text
    assert "5/5" in text and "gap/s" in text and "more hidden" not in text


def test_screen_shape_of_an_unset_terminal_is_unknown() -> None:
    assert _progress.screen_shape(io.StringIO()) == (None, None)  # not a terminal


def test_a_warning_during_a_bar_is_written_above_it(monkeypatch: pytest.MonkeyPatch) -> None:
    """The commands print warnings as they are raised (``pftrack track`` too, since it no
    longer holds them to the end of the run): with a bar drawn, on a line of their own above
    it, not inside the bar's line."""
    import warnings

    from pftrack.cli import _one_line_warning

    err = io.StringIO()
    err.isatty = lambda: True  # type: ignore[method-assign]
    monkeypatch.setattr(sys, "stderr", err)
    monkeypatch.setattr(_progress, "DELAY", 0.0)
    with warnings.catch_warnings():
        warnings.simplefilter("always")
        warnings.showwarning = _one_line_warning("pftrack track")
        for i in progress(range(3), desc="work"):
            if i == 1:
                warnings.warn("odd frame", UserWarning, stacklevel=1)
    lines = err.getvalue().replace("\r", "\n").splitlines()
    assert "pftrack track: warning: odd frame" in lines  # a whole line of its own


def test_bars_sets_the_default_of_the_bars_within(monkeypatch: pytest.MonkeyPatch) -> None:
    with _progress.bars(False):
        assert _run(monkeypatch, tty=True)[1] == ""
        assert "50/50" in _run(monkeypatch, tty=True, enable=True)[1]  # a bar's own word wins
        with _progress.bars(None):  # None changes nothing
            assert _run(monkeypatch, tty=True)[1] == ""
    with _progress.bars(True):
        assert "50/50" in _run(monkeypatch, tty=False)[1]
    assert "50/50" in _run(monkeypatch, tty=True)[1]  # and after: as before


def test_track_frames_without_progress_draws_no_bar_of_its_offline_pass(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # trial61: track_frames(show_progress=False) on a terminal still drew "smoothing", the
    # tracker's offline pass, which took no word of it
    from pftrack.synthetic import make_scene
    from pftrack.tracking.run import track_frames

    scene = make_scene(n_frames=30, width=160, height=120, n_walkers=2, rng=0)
    err = io.StringIO()
    err.isatty = lambda: True  # type: ignore[method-assign]
    monkeypatch.setattr(sys, "stderr", err)
    quiet = track_frames(scene.frames, rng=0, show_progress=False)
    assert err.getvalue() == ""
    loud = track_frames(scene.frames, rng=0)  # a terminal, the default: the bars are drawn
    assert "smoothing" in err.getvalue() and "tracking" in err.getvalue()
    assert np.array_equal(quiet.rows, loud.rows)
