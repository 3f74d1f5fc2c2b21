"""``hrgtc --help`` written without Typer (hrgtc/cli/_help.py) is Typer's text, byte for byte.

The fast path reimplements click's help layout; each part is compared with typer's own
vendored click (``typer._click``) on texts that reach its corners, and the whole page with
the page Typer prints, in fresh processes, at several terminal widths.
"""

from __future__ import annotations

import os
import subprocess
import sys

import pytest
from typer._click.formatting import wrap_text as click_wrap_text
from typer._click.utils import make_default_short_help

from hrgtc.cli import _help
from hrgtc.cli.commands import ENTRY_POINT_GROUP, EntryPoint, entry_points

#: Typer's page, the application built and its help printed by click.
TYPER = ("import sys; sys.argv[0] = {name!r}; from hrgtc.cli import app; "
         "app(prog_name={name!r})")
#: The fast path, as the console script calls it, and what it imported.
FAST = ("import atexit, sys; sys.argv[0] = {name!r}; "
        "atexit.register(lambda: print('typer' in sys.modules, file=sys.stderr)); "
        "from hrgtc.cli import main; main()")


def _run(code: str, columns: str | None, *args: str) -> subprocess.CompletedProcess[str]:
    env = {k: v for k, v in os.environ.items() if k not in ("COLUMNS", "LINES")}
    if columns is not None:
        env["COLUMNS"] = columns
    return subprocess.run([sys.executable, "-c", code, *args], capture_output=True, text=True,
                          env=env, timeout=120, stdin=subprocess.DEVNULL)


@pytest.mark.parametrize("columns", [None, "20", "52", "66", "80", "81", "120", "500"])
def test_the_page_is_typers_byte_for_byte(columns):
    fast = _run(FAST.format(name="/usr/bin/hrgtc"), columns, "--help")
    typer = _run(TYPER.format(name="hrgtc"), columns, "--help")
    assert fast.returncode == typer.returncode == 0, (fast.stderr, typer.stderr)
    assert fast.stderr.strip() == "False"  # typer was not imported: the fast path answered
    assert fast.stdout == typer.stdout
    assert "Usage: hrgtc [OPTIONS] COMMAND [ARGS]..." in fast.stdout
    assert [row.split()[0] for row in fast.stdout.split("Commands:\n")[1].splitlines()] == \
        [p.name for p in entry_points()]


def test_other_arguments_go_to_typer():
    """A command's help, an unknown option: Typer answers (and is imported)."""
    fast = _run(FAST.format(name="hrgtc"), "80", "info", "--help")
    assert fast.returncode == 0 and fast.stderr.strip() == "True"
    assert "Usage: hrgtc info [OPTIONS]" in fast.stdout
    assert _help.top_help(["info", "--help"]) is None
    assert _help.top_help(["--help", "--version"]) is None
    assert _help.top_help([]) is None


def test_a_plugin_command_goes_to_typer(monkeypatch):
    """A command of another distribution (its module is not read here): Typer's page."""
    import hrgtc.cli.commands as commands

    own = entry_points()
    plugin = EntryPoint("mylab-check", "mylab_cmd:check", ENTRY_POINT_GROUP, "mylab")
    monkeypatch.setattr(commands, "entry_points", lambda: [*own, plugin])
    assert _help.top_help(["--help"]) is None
    monkeypatch.setattr(commands, "entry_points", lambda: own)
    assert _help.top_help(["--help"]) is not None


def test_a_command_without_readable_help_goes_to_typer(monkeypatch):
    import hrgtc.cli.commands as commands

    own = entry_points()
    for value in ("hrgtc.cli.info_cmd:no_such_function", "hrgtc.cli.no_such_cmd:info",
                  "hrgtc.cli._app:print_json"):  # a function whose docstring Typer would use
        broken = [p._replace(value=value) if p.name == "info" else p for p in own]
        monkeypatch.setattr(commands, "entry_points", lambda broken=broken: broken)
        text = _help.top_help(["--help"])
        if value.endswith("print_json"):  # readable: its first sentence is listed
            assert text is not None and "info         Write ``data`` as strict" in text
        else:
            assert text is None


def test_python_m_names_the_module():
    env = {**os.environ, "COLUMNS": "90"}
    shown = subprocess.run([sys.executable, "-m", "hrgtc.cli", "--help"], capture_output=True,
                           text=True, env=env, timeout=120)
    typer = _run(TYPER.format(name="python -m hrgtc.cli"), "90", "--help")
    assert shown.returncode == 0, shown.stderr
    assert shown.stdout.startswith("Usage: python -m hrgtc.cli [OPTIONS] COMMAND [ARGS]...")
    assert shown.stdout == typer.stdout


TEXTS = [
    "Reproduce Eq. (16) of the paper and more words after it.",
    "A first paragraph that runs on for quite a while without any full stop at all and on\n\n"
    "a second paragraph.",
    "Exactly fits.",
    "word " * 30,
    "averyveryveryveryveryveryverylongwordthatcannotbebrokenanywhereatallreally and more",
    "\b\nkept   as\n   it is\n\nthen wrapped text that goes on and on and on and on and on",
    "  indented paragraph that goes on and on and on and on and on and on\n\n"
    "    more indented one that goes on and on and on and on and on and on and on",
    "tabs\tand\ttabs\tand words " * 5,
    "",
    "ends with a dot.",
    "Short.",
]


@pytest.mark.parametrize("text", TEXTS)
@pytest.mark.parametrize("limit", [5, 13, 20, 45, 61, 200])
def test_short_help_is_clicks(text, limit):
    assert _help.short_help(text, limit) == make_default_short_help(text, limit).strip()


@pytest.mark.parametrize("text", TEXTS)
@pytest.mark.parametrize("width", [10, 24, 50, 78])
def test_wrapping_is_clicks(text, width):
    for indents in (("", ""), ("  ", "  "), ("Usage: x ", "         ")):
        for paragraphs in (False, True):
            assert _help.wrap_text(text, width, *indents, paragraphs=paragraphs) == \
                click_wrap_text(text, width, *indents, preserve_paragraphs=paragraphs)


@pytest.mark.parametrize("doc", ["", "one line", "  first\n    second\n      third\n\n",
                                 "\n\n  a\n\tb\n  c\n", "x\n   \n  y"])
def test_cleandoc_is_inspects(doc):
    import inspect

    assert _help.cleandoc(doc) == inspect.cleandoc(doc)


def test_a_closed_pipe_ends_as_typers_does():
    """The reader gone before the page is written (``hrgtc --help | true``): exit code 1 and
    nothing on standard error, as click's standalone mode does, not a traceback."""
    ended = []
    for code in (FAST.format(name="hrgtc"), TYPER.format(name="hrgtc")):
        read, write = os.pipe()
        os.close(read)
        try:
            done = subprocess.run([sys.executable, "-c", code, "--help"], stdout=write,
                                  stderr=subprocess.PIPE, text=True, timeout=120)
        finally:
            os.close(write)
        ended.append((done.returncode, done.stderr.replace("True", "").replace("False", "")
                      .strip()))
    assert ended[0] == ended[1] == (1, "")
