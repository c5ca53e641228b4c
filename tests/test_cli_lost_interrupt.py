"""Ctrl-C that code in C turns into another error, or drops, still ends the command as one.

``pftrack recover`` Ctrl-C'd in its first half second, while NumPy is imported, printed
NumPy's ``ImportError: ... PyCapsule_Import could not import module "datetime"`` with its
"IMPORTANT: PLEASE READ THIS" advice on a broken install (a traceback, exit status 1); about
once in 40 such runs the interrupt was lost and the run wrote its output (exit status 0).
The ``pftrack`` process now remembers each Ctrl-C (:func:`pftrack._console.interrupted`).
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from pftrack.synthetic import make_scene

# Ctrl-C inside the command's work, as in an import of NumPy's: the KeyboardInterrupt is
# turned into an ImportError ("convert") or dropped ("drop") before the work goes on
SCRIPT = """
import os, signal, sys, time
import {module} as where

real = where.{name}

def interrupted(*args, **kwargs):
    try:
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(2)
    except KeyboardInterrupt:
        if {how!r} == "convert":
            raise ImportError('PyCapsule_Import could not import module "datetime"') from None
    return real(*args, **kwargs)

where.{name} = interrupted
from pftrack._console import main
sys.argv = ["pftrack", *{argv!r}]
sys.exit(main())
"""

HOOKS = {
    "recover": ("pftrack.recovery", "fill_gaps"),
    "smooth": ("pftrack.tracking", "smooth_tracks"),
}


def _run(tmp_path: Path, command: str, how: str, **popen: object) -> tuple[int, str, Path]:
    tracks = make_scene(n_frames=20, n_walkers=2, rng=0).write_truth(tmp_path / "gt.txt")
    out = tmp_path / "out.txt"
    out.write_text("an earlier run\n")
    module, name = HOOKS[command]
    argv = [command, str(tracks), "--out", str(out)]
    code = SCRIPT.format(module=module, name=name, how=how, argv=argv)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    proc = subprocess.run(  # noqa: PLW1510 - the status is the test's
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=120,
        **popen,  # type: ignore[call-overload]
    )  # fmt: skip
    return proc.returncode, proc.stderr, out


@pytest.mark.parametrize("command", ["recover", "smooth"])
@pytest.mark.parametrize("how", ["convert", "drop"])
def test_a_lost_ctrl_c_ends_the_command_as_interrupted(tmp_path, command, how):
    status, err, out = _run(tmp_path, command, how)
    assert status == 130, err
    assert err == f"pftrack {command}: interrupted; no output was changed\n"
    assert out.read_text() == "an earlier run\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["gt.txt", "out.txt"]


def test_an_ignored_sigint_stays_ignored(tmp_path):
    """A command started with SIGINT ignored (``nohup``, a shell's ``&``) runs to its end."""
    status, err, out = _run(
        tmp_path, "recover", "drop",
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_IGN),
    )  # fmt: skip
    assert status == 0, err
    assert out.read_text() != "an earlier run\n"
