"""``python -m pftrack.cli``: the ``pftrack`` command."""

from __future__ import annotations

import sys

from pftrack._console import main

sys.exit(main())
