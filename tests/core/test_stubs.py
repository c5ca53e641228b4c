"""The hand-written stubs python/pftrack/_core.pyi match the compiled module (mypy.stubtest)."""

from __future__ import annotations

import importlib.util
import subprocess
import sys
from pathlib import Path

import pftrack
import pytest

ALLOWLIST = Path(__file__).with_name("stubtest_allowlist.txt")


def test_stub_and_marker_ship_with_the_package():
    pkg = Path(pftrack.__file__).parent
    assert (pkg / "_core.pyi").is_file()
    assert (pkg / "py.typed").is_file()


def test_stubtest_reports_no_errors(tmp_path):
    # run outside the repository: no project mypy config, and the cache lands in tmp_path
    if importlib.util.find_spec("mypy") is None:
        pytest.skip("mypy is not installed (it is in the `test` extra)")
    proc = subprocess.run(
        [sys.executable, "-m", "mypy.stubtest", "pftrack._core", "--allowlist", str(ALLOWLIST)],
        capture_output=True, text=True, timeout=300, cwd=tmp_path,
    )  # fmt: skip
    assert proc.returncode == 0, f"stubtest found errors:\n{proc.stdout}\n{proc.stderr}"
