"""Where the real data is (../shared/data or $PFTRACK_DATA); tests skip when it is absent."""

from __future__ import annotations

import os
from pathlib import Path

import pytest


def data_dir() -> Path:
    """../shared/data (or $PFTRACK_DATA); skip the calling test when it is absent."""
    default = Path(__file__).resolve().parents[2] / ".." / "shared" / "data"
    root = Path(os.environ.get("PFTRACK_DATA", default))
    if not root.is_dir():
        pytest.skip(f"real data not found at {root}")
    return root
