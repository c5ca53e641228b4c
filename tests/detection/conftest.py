from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # tests/ for reference_detection


def data_dir() -> Path:
    """../shared/data (or $PFTRACK_DATA); skip the test when it is absent."""
    root = Path(
        os.environ.get(
            "PFTRACK_DATA", Path(__file__).resolve().parents[2] / ".." / "shared" / "data"
        )
    )
    if not root.is_dir():
        pytest.skip(f"real data not found at {root}")
    return root
