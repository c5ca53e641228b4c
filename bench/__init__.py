"""pytest-benchmark suites: the C++ core against NumPy references and peers, group by group.

Locally ``pytest bench --benchmark-only``; in CI ``pytest bench --benchmark-disable`` (each case
runs once, untimed). The experiment scripts behind the docs' tables are in ``experiments/``.
"""
