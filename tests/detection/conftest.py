from __future__ import annotations

import sys
from pathlib import Path

# tests/ holds reference_detection.py (the NumPy references), tests/detection the data helper
for p in (Path(__file__).resolve().parents[1], Path(__file__).resolve().parent):
    if str(p) not in sys.path:
        sys.path.insert(0, str(p))
