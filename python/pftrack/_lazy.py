"""Lazy re-exports for package ``__init__`` modules (PEP 562).

A package lists where each public name lives; a name's module is imported the first time the
name is used, so importing the package (and ``pftrack --help``) stays cheap. Its submodules
load the same way: ``pftrack.batch.track_many`` after a bare ``import pftrack``.
"""

from __future__ import annotations

import importlib
import importlib.util
import pkgutil
from collections.abc import Callable, Mapping, Sequence
from typing import Any


def lazy_exports(
    package: str, home: Mapping[str, Sequence[str]], namespace: dict[str, Any]
) -> tuple[dict[str, str], Callable[[str], Any], Callable[[], list[str]]]:
    """Module-level ``__getattr__`` and ``__dir__`` that load each name from its home module.

    A name that is not listed but is a public submodule of the package (``pftrack.batch``,
    ``pftrack.recovery.linking``) is imported as ``import package.name`` would, on first use.

    Parameters
    ----------
    package : str
        The package's ``__name__`` (for error messages).
    home : mapping of module name to names
        Where each public name is defined.
    namespace : dict
        The package's ``globals()``: a loaded name is cached there, so it is imported once.

    Returns
    -------
    module_of, __getattr__, __dir__
        The name -> module map, and the two functions to bind in the package.
    """
    module_of = {name: module for module, names in home.items() for name in names}

    def __getattr__(name: str) -> Any:  # noqa: N807 - the module hook's own name
        module = module_of.get(name)
        if module is not None:
            value = getattr(importlib.import_module(module), name)
            namespace[name] = value
            return value
        if not name.startswith("_") and importlib.util.find_spec(f"{package}.{name}"):
            # the import system sets it in the namespace too: found there from now on
            return importlib.import_module(f"{package}.{name}")
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    def __dir__() -> list[str]:  # noqa: N807
        subs = {m.name for m in pkgutil.iter_modules(namespace.get("__path__", ()))}
        public = {s for s in subs if not s.startswith("_")}
        return sorted(set(namespace) | set(namespace.get("__all__", ())) | public)

    return module_of, __getattr__, __dir__
