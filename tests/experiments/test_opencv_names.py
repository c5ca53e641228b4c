"""The experiments and benchmarks hand OpenCV no file name that is not valid UTF-8.

OpenCV's binding crashes the process (a segmentation fault) on ``cv2.VideoCapture``,
``cv2.imread``, ``cv2.imwrite`` and ``cv2.VideoWriter`` given such a name; the package goes
through :mod:`pftrack.io.opencv_io`, and so do the scripts beside it (were: raw paths, so a data
folder or ``--out`` under a Latin-1 name crashed them).
"""

from __future__ import annotations

import ast
import os
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
#: The OpenCV calls that take a file name.
FILE_CALLS = ("imread", "imwrite", "VideoCapture", "VideoWriter")


def _raw_calls(path: Path, root: Path = REPO) -> list[str]:
    """The calls of `path` that give OpenCV a file name not made by ``opencv_name``.

    ``cv2.imread`` and ``cv2.imwrite`` are never right (``read_image``, ``write_image``);
    ``cv2.VideoCapture`` and ``cv2.VideoWriter`` take a name bound by
    ``with opencv_name(...) as name``.
    """
    tree = ast.parse(path.read_text(encoding="utf-8"), str(path))
    safe = {
        item.optional_vars.id
        for node in ast.walk(tree)
        if isinstance(node, ast.With)
        for item in node.items
        if isinstance(item.context_expr, ast.Call)
        and isinstance(item.context_expr.func, ast.Name)
        and item.context_expr.func.id == "opencv_name"
        and isinstance(item.optional_vars, ast.Name)
    }
    found: list[tuple[int, str]] = []
    for node in ast.walk(tree):
        if not (
            isinstance(node, ast.Call)
            and isinstance(node.func, ast.Attribute)
            and isinstance(node.func.value, ast.Name)
            and node.func.value.id == "cv2"
            and node.func.attr in FILE_CALLS
        ):
            continue
        first = node.args[0] if node.args else None
        if node.func.attr in ("imread", "imwrite") or not (
            isinstance(first, ast.Name) and first.id in safe
        ):
            found.append(
                (node.lineno, f"{path.relative_to(root)}:{node.lineno}: cv2.{node.func.attr}")
            )
    return [text for _, text in sorted(found)]


def test_no_raw_file_name_reaches_opencv() -> None:
    files = [
        *sorted((REPO / "experiments").rglob("*.py")),
        *sorted((REPO / "bench").rglob("*.py")),
        *(
            p
            for p in sorted((REPO / "python" / "pftrack").rglob("*.py"))
            if p.parent.name != "io"  # pftrack.io owns OpenCV's files (opencv_io)
        ),
    ]
    assert len(files) > 40
    assert [call for p in files for call in _raw_calls(p)] == []


def test_the_check_sees_raw_names(tmp_path: Path) -> None:
    p = tmp_path / "probe.py"
    p.write_text(
        "import cv2\n"
        "def f(path, name2):\n"
        "    cv2.imwrite(str(path), None)\n"
        "    cv2.VideoCapture(str(path))\n"
        "    with opencv_name(path) as name:\n"
        "        cv2.VideoCapture(name)\n"
        "    cv2.VideoWriter(name2, 0, 1.0, (1, 1))\n"
        "    cv2.VideoWriter.fourcc(*'MJPG')\n"
    )
    assert _raw_calls(p, tmp_path) == [
        "probe.py:3: cv2.imwrite",
        "probe.py:4: cv2.VideoCapture",
        "probe.py:7: cv2.VideoWriter",
    ]


_SCRIPT = r"""
import os, shutil, sys
from pathlib import Path

import numpy as np

root = Path(sys.argv[1])
from pftrack.synthetic import make_scene

scene = make_scene(n_frames=4, rng=0)
pets = root / "pets09-s2l1"
pets.mkdir()

from experiments import working_resolution

working_resolution._write(pets / "video.avi", scene.frames)  # cv2.VideoWriter
truth = scene.truth.copy()
np.savetxt(pets / "det.txt", truth, delimiter=",")

from experiments import rjmcmc_speed

binned, masks, cands, source = rjmcmc_speed.pets_sequence(root, first=1, n=2)  # VideoCapture
assert len(binned) == 2, source

from experiments import cost_per_object

keys = ["batched_wall", "batched_cpu", "per_object_wall", "per_object_cpu", "no_refine_wall",
        "no_refine_cpu"]
rows = [{k: float(n) for k in keys} | {"objects": float(n)} for n in (1, 5)]
cost_per_object.plot(rows, root / "cost.png")  # cv2.imwrite

from experiments import eval_detection

eval_detection.figure(scene.frames, truth, 2, root / "figure.jpg")  # cv2.imwrite

from bench import conftest

assert conftest.pets_frame(root, (48, 36))[0].shape == (36, 48, 3)  # cv2.VideoCapture

from bench import test_pipeline

assert test_pipeline._decode(pets / "video.avi") == 4  # cv2.VideoCapture
print(sorted(p.name for p in root.iterdir()))
"""


def test_scripts_read_and_write_under_a_name_that_is_not_utf8(tmp_path: Path) -> None:
    """Was: a segmentation fault (exit status -11) in the first OpenCV call."""
    root = Path(os.fsdecode(os.path.join(os.fsencode(tmp_path), b"d\xe9mo")))
    try:
        root.mkdir()
    except OSError:  # e.g. macOS: names must be UTF-8
        pytest.skip("this file system takes only UTF-8 names")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    run = subprocess.run(
        [sys.executable, "-c", _SCRIPT, os.fsencode(root)],
        cwd=REPO,
        env=env,
        capture_output=True,
        timeout=300,
    )
    err = run.stderr.decode(errors="replace")
    assert run.returncode == 0, err
    assert run.stdout.decode().split("\n")[0] == "['cost.png', 'figure.jpg', 'pets09-s2l1']"
