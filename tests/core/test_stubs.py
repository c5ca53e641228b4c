"""The hand-written stubs python/pftrack/_core.pyi match the compiled module (mypy.stubtest)."""

from __future__ import annotations

import importlib.util
import subprocess
import sys
from pathlib import Path

import pytest

import pftrack

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


def _top_level_split(text: str) -> list[str]:
    parts, depth, cur = [], 0, ""
    for ch in text:
        depth += ch in "([{"
        depth -= ch in ")]}"
        if ch == "," and depth == 0:
            parts.append(cur)
            cur = ""
        else:
            cur += ch
    return [p.strip() for p in parts + [cur] if p.strip()]


def _binding_arguments(obj: object) -> list[str] | None:
    """The parameters of pybind11's signature line ``name(a: T, b: U = 1) -> R``, as written
    (``a: T``, ``b: U = 1``); None for an overloaded function or no signature."""
    doc = (getattr(obj, "__doc__", None) or "").strip()
    if not doc or doc.startswith("Overloaded function"):
        return None
    line = doc.splitlines()[0]
    start = line.find("(")
    depth = 0
    for end in range(start, len(line)):
        depth += line[end] in "([{"
        depth -= line[end] in ")]}"
        if depth == 0:
            break
    return _top_level_split(line[start + 1 : end])


def _binding_params(obj: object) -> list[str] | None:
    """Parameter names from pybind11's signature line."""
    args = _binding_arguments(obj)
    return None if args is None else [p.split(":")[0].split("=")[0].strip() for p in args]


def test_stub_parameter_names_match_the_bindings():
    """stubtest cannot read pybind11 signatures, so compare parameter names with the docstrings."""
    import ast

    from pftrack import _core

    tree = ast.parse((Path(pftrack.__file__).parent / "_core.pyi").read_text())

    def names(fn: ast.FunctionDef) -> list[str]:
        a = fn.args
        out = [x.arg for x in a.posonlyargs + a.args]
        if a.vararg or a.kwonlyargs:
            out.append("*" if not a.vararg else f"*{a.vararg.arg}")
        return out + [x.arg for x in a.kwonlyargs]

    checked, mismatched = 0, []
    for node in tree.body:
        pairs = []
        if isinstance(node, ast.FunctionDef):
            pairs.append((node, getattr(_core, node.name, None), node.name))
        elif isinstance(node, ast.ClassDef):
            cls = getattr(_core, node.name, None)
            for fn in node.body:
                if isinstance(fn, ast.FunctionDef) and not any(
                    isinstance(d, ast.Name) and d.id == "property" for d in fn.decorator_list
                ):
                    pairs.append((fn, getattr(cls, fn.name, None), f"{node.name}.{fn.name}"))
        for fn, obj, label in pairs:
            got = _binding_params(obj) if obj is not None else None
            if got is None:
                continue
            checked += 1
            marks = ("*", "/")  # keyword-only and positional-only markers, not names
            if [n for n in got if n not in marks] != [n for n in names(fn) if n not in marks]:
                mismatched.append(f"{label}: binding {got}, stub {names(fn)}")
    assert checked >= 15, f"only {checked} signatures compared"
    assert not mismatched, "\n".join(mismatched)


def _binding_defaults(obj: object) -> dict[str, str | None] | None:
    """Each parameter's default as pybind11's signature line prints it (None: no default)."""
    args = _binding_arguments(obj)
    if args is None:
        return None
    out: dict[str, str | None] = {}
    for p in args:
        name, _, rest = p.partition(":")
        if name.strip() in ("*", "/"):
            continue
        _, eq, default = rest.partition(" = ")
        out[name.strip()] = default.strip() if eq else None
    return out


def test_stub_defaults_match_the_bindings():
    """Which parameters have a default, and the default's value where the stub writes one.

    stubtest reads no pybind11 signature, and the test above compares only names: the stub's
    ``RJMCMCTracker.step`` had ``candidate_hists`` without its default None, so a typed
    ``step(image, mask, boxes, seed=1, step=2)``, which runs, was a mypy error.
    """
    import ast

    from pftrack import _core

    tree = ast.parse((Path(pftrack.__file__).parent / "_core.pyi").read_text())
    functions = []
    for node in tree.body:
        if isinstance(node, ast.FunctionDef):
            functions.append((node, getattr(_core, node.name, None), node.name))
        elif isinstance(node, ast.ClassDef):
            cls = getattr(_core, node.name, None)
            functions += [
                (fn, getattr(cls, fn.name, None), f"{node.name}.{fn.name}")
                for fn in node.body
                if isinstance(fn, ast.FunctionDef) and not fn.decorator_list
            ]
    checked, mismatched = 0, []
    for fn, obj, label in functions:
        got = _binding_defaults(obj) if obj is not None else None
        if got is None:
            continue
        a = fn.args
        positional = a.posonlyargs + a.args
        padded = [None] * (len(positional) - len(a.defaults)) + list(a.defaults)
        stub = [
            *zip(positional, padded, strict=True),
            *zip(a.kwonlyargs, a.kw_defaults, strict=True),
        ]
        for arg, default in stub:
            if arg.arg not in got:
                continue  # self, and names the test above compares
            checked += 1
            runtime = got[arg.arg]
            if (default is None) != (runtime is None):
                shown = "no default" if default is None else f"= {ast.unparse(default)}"
                had = "no default" if runtime is None else f"= {runtime}"
                mismatched.append(f"{label}({arg.arg}): binding {had}, stub {shown}")
            elif default is not None and ast.unparse(default) != "...":
                if repr(ast.literal_eval(default)) != runtime:
                    mismatched.append(
                        f"{label}({arg.arg}): binding {runtime}, stub {ast.unparse(default)}"
                    )
    assert checked >= 100, f"only {checked} parameters compared"
    assert not mismatched, "\n".join(mismatched)
