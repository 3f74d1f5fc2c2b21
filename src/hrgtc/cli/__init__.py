"""The ``hrgtc`` command: thin commands over the library.

Each command module registers itself on :data:`hrgtc.cli._app.app` when imported.
"""

from __future__ import annotations

from hrgtc.cli import paper_cmd  # noqa: F401  (registers commands)
from hrgtc.cli._app import app

__all__ = ["app", "main"]


def main() -> None:
    """Entry point of the ``hrgtc`` console script."""
    app()
