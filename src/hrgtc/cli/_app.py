"""The Typer application object and the helpers every command shares.

Commands live in their own modules of this package, as plain functions that
:mod:`hrgtc.cli.commands` adds to :data:`app` (the entry points ``hrgtc.commands``);
library errors are turned into a one-line message and exit code 2.
"""

from __future__ import annotations

import json
import os
import re
import sys
import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from typing import TYPE_CHECKING, Any

import typer

from hrgtc.cli._help import APP_HELP, VERSION_HELP
from hrgtc.core.errors import HrgtcError

if TYPE_CHECKING:
    from rich.console import Console

    from hrgtc.core.progress import Progress as ProgressCallback

app = typer.Typer(
    name="hrgtc",
    help=APP_HELP,  # hrgtc --help writes it without Typer (_help.py)
    no_args_is_help=True,
    add_completion=False,
    # Help texts are plain text: with Rich markup, units like "[s]" and "[°C]" vanish.
    rich_markup_mode=None,
    pretty_exceptions_enable=False,
)



class LazyConsole:
    """A rich ``Console`` made on first use, every attribute its console's.

    rich's import is a sixth of ``hrgtc --help``'s start, which prints no rich output
    (the help is plain text); a command's first print makes the console, as the module
    did at import before. Pass :meth:`real` where rich itself needs a ``Console``.
    """

    def __init__(self, **options: Any) -> None:
        object.__setattr__(self, "_options", options)
        object.__setattr__(self, "_console", None)
        object.__setattr__(self, "_replaced", {})

    def real(self) -> Console:
        """The console itself (made now if not yet)."""
        made = object.__getattribute__(self, "_console")
        if made is None:
            from rich.console import Console

            made = Console(**object.__getattribute__(self, "_options"))
            object.__setattr__(self, "_console", made)
        return made

    def __getattr__(self, name: str) -> Any:
        return getattr(self.real(), name)

    def __setattr__(self, name: str, value: Any) -> None:
        console = self.real()
        object.__getattribute__(self, "_replaced").setdefault(name, getattr(console, name))
        setattr(console, name, value)

    def __delattr__(self, name: str) -> None:
        """Give back the value ``name`` had before it was first set (as pytest's
        ``monkeypatch`` undoes an attribute that is not in the instance's ``__dict__``)."""
        replaced = object.__getattribute__(self, "_replaced")
        if name not in replaced:
            raise AttributeError(f"{name!r} was never set on the console")
        setattr(self.real(), name, replaced.pop(name))


console: Console = LazyConsole(highlight=False)  # type: ignore[assignment]
error_console: Console = LazyConsole(  # type: ignore[assignment]
    stderr=True, highlight=False, soft_wrap=True)


def print_json(data: Any) -> None:
    """Write ``data`` as strict JSON to standard output (machine readable, nothing else).

    A figure that is not finite (an overflow, a statistic of too few samples) is written
    ``null``, as in the model file: the output stays valid JSON, never a traceback.
    """
    sys.stdout.write(json.dumps(_strict(data), indent=2, allow_nan=False) + "\n")


def _strict(value: Any) -> Any:
    """``value`` with numpy scalars as Python numbers and non-finite floats as None."""
    import math

    if isinstance(value, dict):
        return {k: _strict(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_strict(v) for v in value]
    if type(value).__module__ == "numpy" and getattr(value, "ndim", None) == 0:
        value = value.item()  # numpy scalar -> Python
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def fail(message: str, code: int = 2) -> typer.Exit:
    """Print ``message`` as an error and return the Exit to raise."""
    from rich.markup import escape

    # the message is text (a column named "gyro_x [deg/h]" is not markup)
    error_console.print(f"[bold red]error:[/] {escape(message)}")
    return typer.Exit(code)


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip()
    return text.splitlines()[0] if text else type(exc).__name__


@contextmanager
def library_errors() -> Iterator[None]:
    """Turn every error into a clear message and exit code 2, never a traceback.

    hrgtc's own errors carry the file, column, row and fix; missing files, full disks
    and refused permissions are named with their file; corrupt files that a reader
    library rejects (pyarrow, h5py) are named by that library's message; anything
    else is reported as an internal error (a bug to report) on one line.
    """
    try:
        yield
    except typer.Exit:
        raise
    except HrgtcError as exc:
        raise fail(str(exc)) from exc
    except FileNotFoundError as exc:
        raise fail(f"{exc.filename or exc}: no such file") from exc
    except OSError as exc:
        from hrgtc.core.files import describe_os_error

        raise fail(describe_os_error(exc)) from exc
    except UnicodeError as exc:
        raise fail(f"a file is not valid UTF-8 text ({_first_line(exc)}); save it as UTF-8") \
            from exc
    except MemoryError as exc:
        raise fail("out of memory; process the file in smaller chunks (--chunk-rows)") from exc
    except KeyboardInterrupt:
        raise fail("interrupted; nothing was written", 130) from None
    except Exception as exc:
        if os.environ.get("HRGTC_TRACEBACK"):  # for a bug report: the whole traceback
            raise
        module = type(exc).__module__.split(".")[0]
        if module in ("pyarrow", "h5py"):
            raise fail(f"{module} cannot read or write a file: {_first_line(exc)}") from exc
        raise fail(f"internal error {type(exc).__name__}: {_first_line(exc)} "
                   "(a bug in hrgtc; please report it with the command line; "
                   "HRGTC_TRACEBACK=1 shows where)") from exc


@contextmanager
def progress_bar(
    description: str, enabled: bool = True
) -> Iterator[ProgressCallback]:
    """A rich progress bar as a ``callback(done, total)`` for library functions.

    The bar is drawn on standard error so ``--json`` output stays clean.
    """
    if not enabled:
        yield lambda done, total: None
        return
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )

    progress = Progress(
        TextColumn("{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TimeElapsedColumn(),
        TimeRemainingColumn(),
        console=getattr(error_console, "real", lambda: error_console)(),
        transient=True,
    )
    with progress:
        task = progress.add_task(description, total=None)

        def callback(done: float, total: float) -> None:
            progress.update(task, completed=done, total=total)

        yield callback


_AXIS_TOKENS = (
    (re.compile(r"_(?:x|y|z)\b"), "_*"),
    (re.compile(r"\baxis \w+"), "axis *"),
    (re.compile(r"[-+]?\d[\d.]*(?:e[-+]?\d+)?", re.IGNORECASE), "#"),
)


def warning_cause(text: str) -> str:
    """A warning's text without its axis names and numbers: one cause, one key."""
    for pattern, replacement in _AXIS_TOKENS:
        text = pattern.sub(replacement, text)
    return text


def _format_warning(message: Warning | str, category: type[Warning], filename: str,
                    lineno: int, line: str | None = None) -> str:
    return f"warning: {message}\n"


def print_warnings_once(context: typer.Context) -> None:
    """Show each warning once per cause for this command, then count the repeats.

    The same warning of every axis (or of every pass over a file) differs only in
    the axis name and its numbers: the first is shown, as ``warning: ...`` without
    Python's source line, and the number of the others at the end.
    """
    previous_show, previous_format = warnings.showwarning, warnings.formatwarning
    seen: dict[tuple[str, str], int] = {}

    def show(message: Warning | str, category: type[Warning], filename: str, lineno: int,
             file: Any = None, line: str | None = None) -> None:
        key = (category.__name__, warning_cause(str(message)))
        seen[key] = seen.get(key, 0) + 1
        if seen[key] == 1:
            previous_show(message, category, filename, lineno, file, line)

    def close() -> None:
        warnings.showwarning, warnings.formatwarning = previous_show, previous_format
        repeats = sum(count - 1 for count in seen.values())
        if repeats:
            error_console.print(f"({repeats} more warning(s) like those above, for other axes "
                                "or passes over the same file, not repeated)", markup=False)

    warnings.showwarning, warnings.formatwarning = show, _format_warning
    context.call_on_close(close)


@app.callback(invoke_without_command=True)
def _root(
    context: typer.Context,
    version: bool = typer.Option(False, "--version", help=VERSION_HELP),
) -> None:
    """Temperature-drift compensation of HRGs from the resonator's natural frequency."""
    if version:
        from hrgtc.core.meta import __version__

        console.print(f"hrgtc {__version__}")
        raise typer.Exit()
    if context.invoked_subcommand is None:
        console.print(context.get_help())
        raise typer.Exit(2)
    print_warnings_once(context)
