"""The source distribution: an allow-list of the repository's files, with the license.

``pyproject.toml``'s ``sdist.exclude`` keeps the top-level files and folders a build and its
tests need; it was every file git does not ignore, so an untracked scratch folder went in
(a 120 MB sdist). The sdist is built here by scikit-build-core itself, from a small tree laid
out like the repository: no compiler runs.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tarfile
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
#: What the sdist holds at its top level: the build's files, the docs, tests and benchmarks
#: (and the experiments, which tests/experiments and bench/ import).
SHIPPED = {
    "CMakeLists.txt", "LICENSE", "PKG-INFO", "README.md", "pyproject.toml",
    "bench", "cpp", "docs", "experiments", "python", "tests",
}  # fmt: skip


def test_pyproject_names_the_license_file() -> None:
    tomllib = pytest.importorskip("tomllib")  # Python 3.11+
    project = tomllib.loads((REPO / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    assert project["license"] == "MIT" and project["license-files"] == ["LICENSE"]
    text = (REPO / "LICENSE").read_text(encoding="utf-8")
    assert text.startswith("MIT License") and "the pftrack developers" in text


def test_pyproject_classifies_the_package() -> None:
    # was: no classifiers (pip show and an index showed nothing of its language or types)
    tomllib = pytest.importorskip("tomllib")  # Python 3.11+
    project = tomllib.loads((REPO / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    classifiers = project["classifiers"]
    assert "Programming Language :: Python :: 3" in classifiers
    assert "Programming Language :: C++" in classifiers
    # the wheel ships py.typed and _core.pyi
    assert (REPO / "python" / "pftrack" / "py.typed").exists() == ("Typing :: Typed" in classifiers)
    assert not [c for c in classifiers if c.startswith("License ::")]  # PEP 639: the expression


def test_the_sdist_holds_the_allowed_files_only(tmp_path: Path) -> None:
    pytest.importorskip("scikit_build_core")
    tree = tmp_path / "tree"
    for name in ("pyproject.toml", "CMakeLists.txt", "README.md", "LICENSE", ".gitignore"):
        (tree / name).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(REPO / name, tree / name)
    kept = ["cpp/include/a.hpp", "python/pftrack/__init__.py", "tests/test_a.py",
            "bench/b.py", "docs/d.md", "experiments/e.py"]  # fmt: skip
    left_out = [
        "scratch/big.bin", "notes.txt", ".ruff_cache/x", "build/x/y",  # not on the list
        "python/pftrack/_core.so", "python/pftrack/__pycache__/a.pyc",  # git-ignored inside it
    ]  # fmt: skip
    for name in kept + left_out:
        (tree / name).parent.mkdir(parents=True, exist_ok=True)
        (tree / name).write_text("x\n")
    out = tmp_path / "dist"
    out.mkdir()
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    code = "import sys; from scikit_build_core.build import build_sdist; build_sdist(sys.argv[1])"
    run = subprocess.run([sys.executable, "-c", code, str(out)], cwd=tree, env=env,
                         capture_output=True, text=True, timeout=120, check=False)  # fmt: skip
    assert run.returncode == 0, run.stderr
    (sdist,) = out.glob("*.tar.gz")
    with tarfile.open(sdist) as tar:
        members = {m.name.split("/", 1)[1] for m in tar.getmembers() if m.isfile()}
    assert {m.split("/")[0] for m in members} == SHIPPED
    assert set(kept) <= members and not set(left_out) & members
    with tarfile.open(sdist) as tar:
        info = tar.extractfile(f"{sdist.name[: -len('.tar.gz')]}/PKG-INFO")
        assert info is not None
        pkg_info = info.read().decode()
    assert "License-Expression: MIT" in pkg_info and "License-File: LICENSE" in pkg_info


def test_a_wheel_and_an_editable_install_build_in_different_folders() -> None:
    # was "build/{wheel_tag}" for both: `pip install .` after the README's editable install
    # (-Ceditable.rebuild=true) reconfigured the editable's folder with the isolated build's
    # pybind11, gone after it, and the editable's rebuild on import failed from then on
    tomllib = pytest.importorskip("tomllib")  # Python 3.11+
    text = (REPO / "pyproject.toml").read_text(encoding="utf-8")
    build_dir = tomllib.loads(text)["tool"]["scikit-build"]["build-dir"]
    values = {"cache_tag": "cpython-311", "wheel_tag": "cp311-cp311-linux_x86_64"}
    folders = {
        state: build_dir.format(build_type="Release", state=state, **values)
        for state in ("wheel", "editable", "sdist")
    }
    assert folders["wheel"] != folders["editable"], folders
