"""pytest-benchmark suites: the C++ core against NumPy references and peers, group by group.

Locally ``pytest bench --benchmark-only``; in CI ``pytest bench --benchmark-disable`` (each case
runs once, untimed; a case whose input only sets the time may take the smallest one that runs
the same path then, saying so in ``extra_info``: test_batch.py's four sequences). The experiment
scripts behind the docs' tables are in ``experiments/``.
"""
