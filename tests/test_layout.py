"""The package's architecture, checked: no import cycles, and each wing imports only downwards.

Imports are read from the source with :mod:`ast` (nothing is executed), so a cycle hidden
inside a function body counts as well: a lazy import is still a dependency.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1] / "python" / "pftrack"


def _module_name(path: Path) -> str:
    parts = path.relative_to(ROOT.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imports() -> dict[str, set[str]]:
    """Every pftrack module -> the pftrack modules it imports (anywhere in its body)."""
    modules = {_module_name(p): p for p in ROOT.rglob("*.py")}
    graph: dict[str, set[str]] = {m: set() for m in modules}
    for name, path in modules.items():
        package = name if path.name == "__init__.py" else name.rpartition(".")[0]
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            targets: list[str] = []
            if isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    up = package.split(".")[: len(package.split(".")) - node.level + 1]
                    base = ".".join(up + ([base] if base else []))
                targets = [base] + [f"{base}.{a.name}" for a in node.names]
            for t in targets:
                if t in modules and t != name:
                    graph[name].add(t)
    return graph


def _wing(module: str) -> str:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else ""


def _is_package_parent(a: str, b: str) -> bool:
    """``pftrack.x`` importing ``pftrack.x.y`` is how a package re-exports; not a cycle."""
    return b.startswith(a + ".")


def test_no_import_cycles() -> None:
    graph = {m: {t for t in ts if not _is_package_parent(m, t)} for m, ts in _imports().items()}
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(m: str) -> None:
        state[m] = 1
        stack.append(m)
        for t in sorted(graph[m]):
            if state.get(t) == 1:
                cycle = stack[stack.index(t) :] + [t]
                pytest.fail("import cycle: " + " -> ".join(cycle))
            if t not in state:
                visit(t)
        stack.pop()
        state[m] = 2

    for m in sorted(graph):
        if m not in state:
            visit(m)


# What each wing may import, besides itself and the shared bottom layer.
BOTTOM = {
    "", "_core", "_typing", "_check", "_limits", "_progress", "_text", "_lazy", "_threads", "_warn",
    "_stand_in", "_interrupt", "_stats", "assignment", "boxes", "kalman", "io",
}  # fmt: skip
ALLOWED = {
    "io": set(),
    "particle_filter": set(),
    "detection": {"particle_filter"},
    "recovery": {"particle_filter"},  # linking's colour term uses the core's HSV histograms
    "tracking": {"particle_filter", "detection", "recovery"},
    "eval": set(),
    # adapters to other libraries' tracker interfaces (the Tracker's options name detection's)
    "integrations": {"tracking", "detection"},
    # the batch layer runs whole commands: it scores (eval) and renders like the CLI does
    "batch": {"particle_filter", "detection", "recovery", "tracking", "eval", "render"},
}


@pytest.mark.parametrize("wing", sorted(ALLOWED))
def test_wing_imports_only_downwards(wing: str) -> None:
    bad = sorted(
        f"{m} imports {t}"
        for m, ts in _imports().items()
        if _wing(m) == wing
        for t in ts
        if _wing(t) not in BOTTOM | ALLOWED[wing] | {wing}
    )
    assert not bad, "\n".join(bad)


def test_graph_sees_the_package() -> None:
    graph = _imports()
    assert "pftrack.cli" in graph and "pftrack.tracking.tracker" in graph
    assert "pftrack.tracking" in graph["pftrack.cli.track"] or any(
        t.startswith("pftrack.tracking") for t in graph["pftrack.cli.track"]
    )


def _direct_warnings(path: Path) -> list[int]:
    """Lines of `path` that call ``warnings.warn`` (or ``warn_explicit``) or import them."""
    lines = []
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if (
            isinstance(node, ast.Attribute)
            and isinstance(node.value, ast.Name)
            and node.value.id == "warnings"
            and node.attr in ("warn", "warn_explicit")
        ) or (
            isinstance(node, ast.ImportFrom)
            and node.module == "warnings"
            and any(a.name in ("warn", "warn_explicit") for a in node.names)
        ):
            lines.append(node.lineno)
    return lines


def test_every_warning_goes_through_pftrack_warn() -> None:
    """``warnings.warn`` called directly escapes :class:`pftrack._warn.Held`: a detector's
    warning raised half-way through ``update`` under ``-W error`` (check_detections'), or
    named a line inside pftrack. Only ``pftrack._warn`` calls it."""
    found = {
        f"{path.relative_to(ROOT.parent)}:{line}"
        for path in ROOT.rglob("*.py")
        if path != ROOT / "_warn.py"
        for line in _direct_warnings(path)
    }
    assert not found, sorted(found)
    assert _direct_warnings(ROOT / "_warn.py")  # the check sees a call
