"""The ``hrgtc`` command: thin commands over the library.

The commands are the entry points of the group ``hrgtc.commands`` (hrgtc's own are
declared in ``pyproject.toml``, one function of a ``*_cmd`` module each, ``fleet`` a
``typer.Typer``), added to :data:`hrgtc.cli._app.app` when :data:`app` is first taken from
this package (:mod:`hrgtc.cli.commands`). Each command imports the library inside its
function, and ``hrgtc --help`` alone is written without Typer (:mod:`hrgtc.cli._help`).
"""

from __future__ import annotations

import os
import sys
from typing import Any

__all__ = ["app", "main"]


def __getattr__(name: str) -> Any:
    """:data:`app`, the Typer application with every command, made on first use."""
    if name != "app":
        raise AttributeError(f"module 'hrgtc.cli' has no attribute {name!r}")
    from hrgtc.cli._app import app
    from hrgtc.cli.commands import register_commands

    register_commands(app)
    globals()["app"] = app
    return app


def main() -> None:
    """Entry point of the ``hrgtc`` console script."""
    from hrgtc.cli._help import top_help

    text = top_help(sys.argv[1:])
    if text is not None:  # what Typer would print, without building the application
        try:
            sys.stdout.write(text + "\n")
            sys.stdout.flush()
        except BrokenPipeError:  # as click: a reader gone (| head) ends it quietly, code 1
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
            sys.exit(1)
        return
    from hrgtc.core.process import keep_freed_memory

    keep_freed_memory()  # chunk buffers reused, not zeroed afresh by the kernel
    application = globals().get("app") or __getattr__("app")
    application()
