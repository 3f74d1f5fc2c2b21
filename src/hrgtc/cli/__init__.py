"""The ``hrgtc`` command: thin commands over the library.

Each command module registers itself on :data:`hrgtc.cli._app.app` when imported.
"""

from __future__ import annotations

from hrgtc.cli import (
    calibrate_cmd,  # noqa: F401
    compensate_cmd,  # noqa: F401
    demo_cmd,  # noqa: F401
    export_cmd,  # noqa: F401
    fleet_cmd,  # noqa: F401
    info_cmd,  # noqa: F401
    paper_cmd,  # noqa: F401  (registers commands)
    report_cmd,  # noqa: F401
    simulate_cmd,  # noqa: F401
)
from hrgtc.cli._app import app

__all__ = ["app", "main"]


def main() -> None:
    """Entry point of the ``hrgtc`` console script."""
    app()
