"""hrgtc's compiled modules: loaded by name, with one error saying how to build them.

The C kernels (docs/architecture.md, "The native Allan module", "The native at-rest
detector" and "The native kernels") are CPython extensions that ``setup.py`` builds in
place at ``pip install -e .`` (``make .venv/.installed``). A source checkout not built
lacks them: that is an ``ImportError`` naming the module, its C source and the command
that builds it, never a silent fallback to slower code.
"""

from __future__ import annotations

import importlib
from types import ModuleType

__all__ = ["native_module"]


def native_module(name: str, what: str) -> ModuleType:
    """The compiled module ``name`` (``"hrgtc.recording._spike_native"``), built from
    ``src/<its path>.c``; ``what`` says in the error what it computes ("spike filter").

    Raises
    ------
    ImportError
        The module is not built (or does not load): naming it, its source and the build.
    """
    try:
        return importlib.import_module(name)
    except ImportError as error:
        source = "src/" + name.replace(".", "/") + ".c"
        raise ImportError(
            f"hrgtc's compiled {what} ({name}, from {source}) could not be loaded ({error}); "
            "build it with `make .venv/.installed` or `pip install -e .` (a C compiler is "
            "needed)") from error
