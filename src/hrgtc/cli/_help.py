"""``hrgtc --help`` without building the Typer application (issue 27, item 8).

The top-level help lists the commands by name and the first sentence of their help. Typer
builds it from the command functions, which it must import with typer itself (typer's
import alone is ~60 % of ``python -c 'import numpy'``). :func:`top_help` writes the same
text from the entry points (:func:`hrgtc.cli.commands.entry_points`), the command modules'
docstrings read from their source with :mod:`ast` (no import) and the layout rules of
click's ``HelpFormatter`` (typer's vendored click, ``typer/_click/formatting.py``: usage
line, wrapped paragraph, definition lists with a first column of at most 30 characters).

It answers only where it can be sure: ``hrgtc --help`` alone, with hrgtc's own commands
only (a plugin's command, a command module it cannot read, a group with a callback or a
completion request: None, and Typer answers). ``tests/cli/test_help.py`` compares its text
with Typer's, byte for byte, at several terminal widths.
"""

from __future__ import annotations

import os
import re
import sys

#: The application's help (``typer.Typer(help=...)`` in :mod:`hrgtc.cli._app`).
APP_HELP = ("Temperature-drift compensation of hemispherical resonator gyros from the "
            "resonator's natural frequency (Wang et al., Sensors 2012, "
            "doi:10.3390/s120506434).")
#: The root's options and their help, as Typer lists them (``--help`` is click's own).
VERSION_HELP = "Print the version and exit."
ROOT_OPTIONS = (("--version", VERSION_HELP), ("--help", "Show this message and exit."))
#: Where the commands' modules are (an entry point elsewhere: Typer answers).
_PACKAGE = "hrgtc.cli."
#: The opening quotes of the first string after a line that ends in ``:``.
_DOCSTRING = re.compile(r":[ \t]*(?:#[^\n]*)?\n[ \t]+([rRuU]?)(\"\"\"|\'\'\')")


def top_help(argv: list[str]) -> str | None:
    """The text ``hrgtc --help`` prints (without its final newline) if ``argv`` asks for
    the top-level help and every command is hrgtc's own and readable; None otherwise."""
    if argv != ["--help"] or os.environ.get("_HRGTC_COMPLETE"):
        return None
    from hrgtc.cli.commands import OWN_DISTRIBUTION, entry_points

    points = entry_points()
    if not points or any(p.distribution != OWN_DISTRIBUTION for p in points):
        return None
    rows = _command_rows(points)
    if rows is None:
        return None
    return render(program_name(), APP_HELP, ROOT_OPTIONS, rows, help_width())


def _command_rows(points: list) -> list[tuple[str, str]] | None:
    """(name, full help) of each command, functions first and groups after (Typer's
    order), or None if one cannot be read from its source."""
    folder = os.path.dirname(__file__)
    sources: dict[str, str] = {}
    commands, groups = [], []
    for point in points:
        module, _, attribute = point.value.partition(":")
        module, attribute = module.strip(), attribute.strip()
        if not module.startswith(_PACKAGE) or "." in module[len(_PACKAGE):] \
                or not attribute.isidentifier():
            return None
        if module not in sources:
            try:
                with open(os.path.join(folder, module[len(_PACKAGE):] + ".py"),
                          encoding="utf-8") as handle:
                    sources[module] = handle.read()
            except (OSError, ValueError):
                return None
        found = _function_help(sources[module], attribute)
        if found is not None:
            commands.append((point.name, found))
            continue
        found = _group_help(sources[module], attribute)
        if found is None:
            return None
        groups.append((point.name, found))
    return commands + groups


def _parsed(snippet: str) -> object | None:
    """The first statement of ``snippet`` if it parses, else None."""
    import ast

    try:
        body = ast.parse(snippet).body
    except (SyntaxError, ValueError):
        return None
    return body[0] if len(body) == 1 else None


def _function_help(source: str, name: str) -> str | None:
    """The cleaned docstring of the module-level function ``name`` (Typer's help of a
    command: ``inspect.getdoc``), or None.

    Only the function's header and docstring are parsed (the whole module costs ~5x
    more): from ``def name(`` to the end of the first string after a line ending in
    ``:``. What parses there is a function whose first statement is that string, i.e.
    the function's docstring; anything else gives None.
    """
    import ast

    start = source.find(f"\ndef {name}(") + 1
    if start == 0:
        return None
    opening = _DOCSTRING.search(source, start)
    if opening is None:
        return None
    quotes = opening.group(2)
    stop = opening.end()
    while True:
        stop = source.find(quotes, stop)
        if stop == -1:
            return None
        if source[stop - 1] != "\\":
            break
        stop += 1
    node = _parsed(source[start:stop + 3] + "\n")
    if not isinstance(node, ast.FunctionDef) or node.name != name:
        return None
    text = _docstring(node)
    return None if text is None else cleandoc(text)


def _group_help(source: str, name: str) -> str | None:
    """The ``help=`` text of ``name = typer.Typer(..., help="...")`` if the module
    registers no callback on it (Typer's help of a group then), else None."""
    import ast

    if f"{name}.callback" in source:
        return None
    start = source.find(f"\n{name} = typer.Typer(") + 1
    if start == 0:
        return None
    stop = start
    for _ in range(40):  # the assignment's lines, up to the first that closes it
        stop = source.find("\n", stop + 1)
        if stop == -1:
            return None
        node = _parsed(source[start:stop + 1])
        if node is not None:
            break
    else:
        return None
    if not (isinstance(node, ast.Assign) and isinstance(node.value, ast.Call)):
        return None
    for keyword in node.value.keywords:
        if keyword.arg == "help" and isinstance(keyword.value, ast.Constant) \
                and isinstance(keyword.value.value, str):
            return cleandoc(keyword.value.value)
    return None


def _docstring(node: object) -> str | None:
    import ast

    body = node.body  # type: ignore[attr-defined]
    if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant) \
            and isinstance(body[0].value.value, str):
        return body[0].value.value
    return None


def cleandoc(doc: str) -> str:
    """:func:`inspect.cleandoc` (Python 3.11's, without importing :mod:`inspect`)."""
    try:
        lines = doc.expandtabs().split("\n")
    except UnicodeError:  # pragma: no cover - as inspect's
        return doc
    margin = sys.maxsize
    for line in lines[1:]:
        content = len(line.lstrip())
        if content:
            margin = min(margin, len(line) - content)
    if lines:
        lines[0] = lines[0].lstrip()
    if margin < sys.maxsize:
        for i in range(1, len(lines)):
            lines[i] = lines[i][margin:]
    while lines and not lines[-1]:
        lines.pop()
    while lines and not lines[0]:
        lines.pop(0)
    return "\n".join(lines)


def program_name() -> str:
    """The program's name as click shows it (``_detect_program_name``)."""
    main = sys.modules["__main__"]
    path = sys.argv[0]
    package = getattr(main, "__package__", None)
    if package in {None, ""}:
        return os.path.basename(path)
    name = os.path.splitext(os.path.basename(path))[0]
    module = package if name == "__main__" else f"{package}.{name}"
    return f"python -m {module.lstrip('.')}"


def help_width(max_width: int = 80) -> int:
    """click's help width: the terminal's columns (``shutil.get_terminal_size``, whose
    import this avoids) up to ``max_width``, minus 2, at least 50."""
    try:
        columns = int(os.environ["COLUMNS"])
    except (KeyError, ValueError):
        columns = 0
    try:
        lines = int(os.environ["LINES"])
    except (KeyError, ValueError):
        lines = 0
    if columns <= 0 or lines <= 0:
        try:
            size = os.get_terminal_size(sys.__stdout__.fileno())  # type: ignore[union-attr]
        except (AttributeError, ValueError, OSError):
            size = os.terminal_size((80, 24))
        if columns <= 0:
            columns = size.columns or 80
    return max(min(columns, max_width) - 2, 50)


def render(program: str, help_text: str, options: tuple[tuple[str, str], ...],
           commands: list[tuple[str, str]], width: int) -> str:
    """The help page of a group as click writes it (``Command.format_help`` of typer's
    ``TyperGroup`` without rich): usage, help text, options, commands (each with the short
    help of ``make_default_short_help``)."""
    out = [_usage(f"Usage: {program} ", "[OPTIONS] COMMAND [ARGS]...", width)]
    text = cleandoc(help_text).partition("\f")[0]
    if text:
        out += ["\n", wrap_text(text, width, "  ", "  ", paragraphs=True), "\n"]
    out += ["\n", "Options:\n", *_definitions(options, width, indent=2)]
    if commands:
        limit = width - 6 - max(len(name) for name, _ in commands)
        rows = [(name, short_help(text, limit)) for name, text in commands]
        out += ["\n", "Commands:\n", *_definitions(rows, width, indent=2)]
    return "".join(out).rstrip("\n")


def _usage(prefix: str, args: str, width: int) -> str:
    """``HelpFormatter.write_usage`` at indentation 0."""
    if width >= len(prefix) + 20:
        return wrap_text(args, width, prefix, " " * len(prefix)) + "\n"
    indent = " " * (len("Usage: ") + 4)
    return f"{prefix}\n{wrap_text(args, width, indent, indent)}\n"


def _definitions(rows: list[tuple[str, str]] | tuple[tuple[str, str], ...], width: int,
                 indent: int) -> list[str]:
    """``HelpFormatter.write_dl`` (first column at most 30 wide, 2 spaces between)."""
    first_col = min(max(len(first) for first, _ in rows), 30) + 2
    out = []
    for first, second in rows:
        out.append(" " * indent + first)
        if not second:
            out.append("\n")
            continue
        if len(first) <= first_col - 2:
            out.append(" " * (first_col - len(first)))
        else:
            out.append("\n" + " " * (first_col + indent))
        lines = wrap_text(second, max(width - first_col - 2, 10), paragraphs=True).splitlines()
        out.append(f"{lines[0]}\n" if lines else "\n")
        out += [" " * (first_col + indent) + line + "\n" for line in lines[1:]]
    return out


def short_help(text: str, limit: int) -> str:
    """click's ``make_default_short_help``: the first sentence of the first paragraph,
    or its words up to ``limit`` characters and ``...``."""
    end = text.find("\n\n")
    words = (text if end == -1 else text[:end]).split()
    if words and words[0] == "\b":
        words = words[1:]
    if not words:
        return ""
    total = 0
    for i, word in enumerate(words):
        total += len(word) + (i > 0)
        if total > limit:
            break
        if word[-1] == ".":
            return " ".join(words[: i + 1])
        if total == limit and i != len(words) - 1:
            break
    else:
        return " ".join(words).strip()
    total += len("...")
    while i > 0:
        total -= len(words[i]) + (i > 0)
        if total <= limit:
            break
        i -= 1
    return (" ".join(words[:i]) + "...").strip()


def wrap_text(text: str, width: int, initial_indent: str = "", subsequent_indent: str = "",
              paragraphs: bool = False) -> str:
    """click's ``wrap_text``: ``textwrap`` with long words cut at the margin; with
    ``paragraphs``, each paragraph (blank-line separated) wrapped at its own indentation
    and one starting with a ``\\b`` line kept as it is."""
    import textwrap

    class Wrapper(textwrap.TextWrapper):
        def _handle_long_word(self, reversed_chunks: list[str], cur_line: list[str],
                              cur_len: int, width: int) -> None:
            space_left = max(width - cur_len, 1)
            last = reversed_chunks[-1]
            cur_line.append(last[:space_left])
            reversed_chunks[-1] = last[space_left:]

    text = text.expandtabs()
    wrapper = Wrapper(width, initial_indent=initial_indent,
                      subsequent_indent=subsequent_indent, replace_whitespace=False)
    if not paragraphs:
        return wrapper.fill(text)
    out = []
    for extra, raw, body in _paragraphs(text):
        if raw:
            out.append("\n".join((initial_indent if k == 0 else subsequent_indent) + extra
                                 + line for k, line in enumerate(body.splitlines())))
            continue
        wrapper.initial_indent = initial_indent + extra
        wrapper.subsequent_indent = subsequent_indent + extra
        out.append(wrapper.fill(body))
    return "\n\n".join(out)


def _paragraphs(text: str) -> list[tuple[str, bool, str]]:
    """(extra indentation, kept as is, text) of each paragraph, as click splits them."""
    found: list[tuple[str, bool, str]] = []
    lines: list[str] = []
    indent = None

    def flush() -> None:
        if lines:
            raw = lines[0].strip() == "\b"
            found.append((" " * (indent or 0), raw,
                          "\n".join(lines[1:]) if raw else " ".join(lines)))
            lines.clear()

    for line in text.splitlines():
        if not line:
            flush()
            indent = None
            continue
        if indent is None:
            stripped = line.lstrip()
            indent = len(line) - len(stripped)
            line = stripped
        lines.append(line)
    flush()
    return found
