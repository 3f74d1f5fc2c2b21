"""The commands of ``hrgtc``, found through the entry point group ``hrgtc.commands``.

hrgtc declares its own commands there (``pyproject.toml``; ``hrgtc --help`` lists them in
the order of :data:`HELP_ORDER`, as setuptools writes them sorted by name), and another
package adds its own the same way, without touching hrgtc::

    [project.entry-points."hrgtc.commands"]
    mylab-check = "mylab_hrgtc.cli:check"

An entry point names a function, which becomes the command of the entry point's name
(its docstring the help, its parameters the options, as ``@app.command`` makes them), or
a ``typer.Typer``, which becomes a group of commands of that name (``hrgtc fleet ...``).
hrgtc's own commands come first, then the others in the order of the path. A command
that fails to load, or takes a name already taken, is left out with a
:class:`~hrgtc.core.errors.CommandPluginWarning`; the other commands go on.

The group is read from the installed distributions' ``entry_points.txt`` here, not with
:func:`importlib.metadata.entry_points`, whose import (``email``, ``zipfile``, ``csv``)
costs ``hrgtc --help`` a sixth of its start: the same files (``*.dist-info`` and
``*.egg-info`` folders of each folder on ``sys.path``, the first distribution of a name
on the path winning, as importlib.metadata does), parsed for one group.
"""

from __future__ import annotations

import importlib
import os
import re
import sys
import warnings
from collections.abc import Callable, Iterable
from typing import Any, NamedTuple

from hrgtc.core.errors import CommandPluginWarning

__all__ = ["ENTRY_POINT_GROUP", "EntryPoint", "entry_points", "register_commands"]

#: Entry point group of the commands.
ENTRY_POINT_GROUP = "hrgtc.commands"
#: The distribution whose commands come first.
OWN_DISTRIBUTION = "hrgtc"
#: The order of hrgtc's own commands in ``hrgtc --help``: the pipeline's, then the demo, the
#: tools and the fleet (typer lists a group after the commands). One not listed comes after
#: them; ``tests/cli/test_commands.py`` checks the list against ``pyproject.toml``.
HELP_ORDER = ("compensate", "evaluate", "calibrate", "demo", "export-c", "info", "paper",
              "report", "simulate", "test-report", "update",
              "fleet")
_SECTION = re.compile(r"^\[(.+)\]\s*$")


class EntryPoint(NamedTuple):
    """One entry point as ``entry_points.txt`` declares it: ``name = module:attribute``
    (the fields and :meth:`load` of :class:`importlib.metadata.EntryPoint`, which the
    tests may give in its place). A named tuple, not a dataclass: ``hrgtc --help`` reads
    these without importing :mod:`dataclasses` (and :mod:`inspect`, a tenth of its start)."""

    name: str
    value: str
    group: str
    distribution: str = ""

    def load(self) -> Any:
        """The object it names: the module, or the attribute of the module."""
        module, _, attribute = self.value.partition(":")
        found: Any = importlib.import_module(module.strip())
        for part in filter(None, attribute.strip().split(".")):
            found = getattr(found, part)
        return found


def _normalised(name: str) -> str:
    return re.sub(r"[-_.]+", "-", name).lower()


def _distribution_name(folder: str) -> str:
    """``hrgtc-0.1.0.dist-info`` -> ``hrgtc``."""
    stem = folder.rsplit(".", 1)[0]
    return _normalised(stem.split("-", 1)[0])


def _parse(text: str, group: str, distribution: str) -> list[EntryPoint]:
    found, inside = [], False
    for line in text.splitlines():
        line = line.strip()
        if not line or line.startswith(("#", ";")):
            continue
        section = _SECTION.match(line)
        if section:
            inside = section.group(1).strip() == group
        elif inside and "=" in line:
            name, value = line.split("=", 1)
            found.append(EntryPoint(name.strip(), value.strip(), group, distribution))
    return found


def entry_points(group: str = ENTRY_POINT_GROUP,
                 path: Iterable[str] | None = None) -> list[EntryPoint]:
    """The entry points of ``group`` of the distributions on ``path`` (``sys.path``):
    ``hrgtc``'s first, in :data:`HELP_ORDER`, then each other distribution's in the order
    of its file."""
    seen: set[str] = set()
    own: list[EntryPoint] = []
    others: list[EntryPoint] = []
    for folder in sys.path if path is None else path:
        try:
            names = sorted(os.listdir(folder or "."))
        except OSError:
            continue
        for name in names:
            if not name.endswith((".dist-info", ".egg-info")):
                continue
            distribution = _distribution_name(name)
            if distribution in seen:
                continue
            seen.add(distribution)
            try:
                with open(os.path.join(folder or ".", name, "entry_points.txt"),
                          encoding="utf-8") as handle:
                    text = handle.read()
            except OSError:
                continue
            points = _parse(text, group, distribution)
            (own if distribution == OWN_DISTRIBUTION else others).extend(points)
    order = {name: k for k, name in enumerate(HELP_ORDER)}
    own.sort(key=lambda p: (order.get(p.name, len(order)), p.name))
    return own + others


def register_commands(app: Any, points: Iterable[Any] | None = None,
                      add: Callable[[Any, str, Any], None] | None = None) -> list[str]:
    """Add the commands of ``points`` (default: :func:`entry_points`) to the Typer ``app``;
    the names added, in order.

    A function is added with ``app.command(name)``, a ``typer.Typer`` with
    ``app.add_typer(..., name=name)``. Without ``points``, warns when hrgtc's own commands
    are not among them (hrgtc on the path but not installed, or installed before its
    commands were entry points).
    """
    import typer

    if points is None:
        points = entry_points()
        if not any(getattr(p, "distribution", "") == OWN_DISTRIBUTION for p in points):
            warnings.warn(f"hrgtc's own commands are not declared on this path (no entry "
                          f"points {ENTRY_POINT_GROUP} of an installed hrgtc): install it, "
                          "pip install -e . in the checkout", CommandPluginWarning, stacklevel=2)
    taken: set[str] = set()
    added = []
    for point in points:
        try:
            if point.name in taken:
                raise ValueError(f"the command name {point.name!r} is already taken")
            found = point.load()
            if isinstance(found, typer.Typer):
                app.add_typer(found, name=point.name)
            elif callable(found):
                app.command(point.name)(found)
            else:
                raise TypeError(f"{type(found).__name__} is neither a function nor a "
                                "typer.Typer")
        except Exception as exc:  # a broken plugin must not stop the other commands
            warnings.warn(f"command {point.name!r} of the entry point {point.value!r} "
                          f"({ENTRY_POINT_GROUP}) was not loaded: {exc}", CommandPluginWarning,
                          stacklevel=2)
            continue
        taken.add(point.name)
        added.append(point.name)
    return added
