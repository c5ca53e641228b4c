"""Lazy re-exports for package ``__init__`` modules (PEP 562).

A package lists where each public name lives; a name's module is imported the first time the
name is used, so importing the package (and ``pftrack --help``) stays cheap.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping, Sequence
from typing import Any


def lazy_exports(
    package: str, home: Mapping[str, Sequence[str]], namespace: dict[str, Any]
) -> tuple[dict[str, str], Callable[[str], Any], Callable[[], list[str]]]:
    """Module-level ``__getattr__`` and ``__dir__`` that load each name from its home module.

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
        if module is None:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(module), name)
        namespace[name] = value
        return value

    def __dir__() -> list[str]:  # noqa: N807
        return sorted(set(namespace) | set(namespace.get("__all__", ())))

    return module_of, __getattr__, __dir__
