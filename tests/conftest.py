from __future__ import annotations

import os
import re
from collections.abc import Iterable, Iterator
from pathlib import Path

import numpy as np
import pytest

DATA = Path(
    os.environ.get("PFTRACK_DATA", Path(__file__).resolve().parents[1].parent / "shared" / "data")
)


def dataset(name: str) -> Path:
    """Folder of a real sequence in ../shared/data, or skip the test."""
    folder = DATA / name
    if not folder.is_dir():
        pytest.skip(f"dataset {name} not found at {folder}")
    return folder


# An id naming an object by its address (``<object object at 0x7f...>``, from ``ids=repr``)
_ADDRESS = re.compile(r" at 0x[0-9a-fA-F]+")


def ids_with_addresses(nodeids: Iterable[str]) -> list[str]:
    """The test ids that hold a memory address: each process collects another name for them."""
    return [n for n in nodeids if _ADDRESS.search(n)]


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """Refuse test ids that differ from process to process.

    .ci/run runs the suite on two pytest-xdist processes, which must collect the same ids: one
    id holding an address (``ids=repr`` of an ``object()``) failed the whole run at collection.
    """
    bad = ids_with_addresses(item.nodeid for item in items)
    if bad:
        raise pytest.UsageError(
            f"{len(bad)} test ids hold a memory address, another in each process (give the "
            f"parameter an id): {bad[0]}"
        )


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(12345)


@pytest.fixture
def textured_frame(rng: np.random.Generator) -> np.ndarray:
    frame = rng.integers(0, 256, (72, 96, 3), dtype=np.uint8)
    frame[10:40, 20:40] = (30, 40, 200)  # a red block (BGR)
    frame[40:70, 50:80] = (200, 120, 20)  # a blue block
    return frame


@pytest.fixture(autouse=True)
def _not_quiet() -> Iterator[None]:
    """``main(["-q", ...])`` silences the process's bars (``set_quiet``); not the next test's.

    Was: a test that reads what is said when no bar is drawn failed after any ``-q`` run in
    the same process (``test_experiment_gaps_one_sequence_writes_json`` after
    ``tests/test_cli_outputs.py``).
    """
    from pftrack._progress import quiet, set_quiet

    before = quiet()
    yield
    set_quiet(before)


#: The device files tests write through (``--out /dev/stdout``, ``/dev/null``) or read.
_DEVICES = ("/dev/stdout", "/dev/stderr", "/dev/stdin", "/dev/null", "/dev/fd")


def _device_files() -> dict[str, tuple[int, int] | None]:
    """Each of :data:`_DEVICES`' type and inode, not followed (None where there is none)."""
    found: dict[str, tuple[int, int] | None] = {}
    for name in _DEVICES:
        try:
            st = os.lstat(name)
        except OSError:
            found[name] = None
        else:
            found[name] = (st.st_mode, st.st_ino)
    return found


@pytest.fixture(autouse=True, scope="session")
def _devices_kept() -> Iterator[None]:
    """No test may replace a device file it writes through (pftrack's outputs run as root).

    Was: on stop 74's machine ``/dev/stdout`` turned out a regular file (put there by a command
    outside the suite; the suite itself, run then, left the link as it was), and every write
    through it replaced it again, so three tests of ``--out /dev/stdout`` failed for a reason
    no message said. A replacement made by the tests fails here, at the session's end.
    """
    before = _device_files()
    yield
    changed = sorted(k for k, v in _device_files().items() if v != before[k])
    assert not changed, f"replaced while the tests ran: {', '.join(changed)}"
