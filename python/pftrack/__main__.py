"""``python -m pftrack``: the ``pftrack`` command (where the console script is not on PATH)."""

from __future__ import annotations

import sys

from pftrack._console import main

sys.exit(main())
