"""The ``hrgtc`` command: thin commands over the library.

The commands are the entry points of the group ``hrgtc.commands`` (hrgtc's own are
declared in ``pyproject.toml``, one function of a ``*_cmd`` module each, ``fleet`` a
``typer.Typer``), added to :data:`hrgtc.cli._app.app` when this package is imported
(:mod:`hrgtc.cli.commands`). Each command imports the library inside its function, so
``hrgtc --help`` loads no stage.
"""

from __future__ import annotations

from hrgtc.cli._app import app
from hrgtc.cli.commands import register_commands

__all__ = ["app", "main"]

register_commands(app)


def main() -> None:
    """Entry point of the ``hrgtc`` console script."""
    app()
