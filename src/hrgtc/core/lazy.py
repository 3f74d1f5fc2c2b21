"""Names of a package loaded from their modules on first use (PEP 562).

A package whose ``__init__`` would import heavy modules (numba kernels, scipy, the drift
model) only to re-export their names gives them this way, so ``import hrgtc.x`` stays cheap
and ``hrgtc --help`` imports none of them.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping, MutableMapping
from typing import Any


def lazy_names(package: str, names: Mapping[str, str], namespace: MutableMapping[str, Any],
               ) -> tuple[Callable[[str], Any], Callable[[], list[str]]]:
    """The ``__getattr__`` and ``__dir__`` of ``package``: ``names`` maps each public name to
    its module (relative to the package); a name is imported when first asked for and kept
    in the package's ``namespace`` (its ``globals()``)."""

    def __getattr__(name: str) -> Any:
        module = names.get(name)
        if module is None:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(f"{package}.{module}"), name)
        namespace[name] = value
        return value

    def __dir__() -> list[str]:
        return sorted(set(namespace) | set(names))

    return __getattr__, __dir__
