"""Every command-line example of the docs and the README runs.

The docs convention (``docs/architecture.md``): a fenced block with the language
``console`` is a session. Each line starting with ``$ `` is a command (a line ending in
``\\`` continues on the next), other lines are output and are not compared. A comment line
``# exit N`` right after a command says it must exit with status N; otherwise it must exit
with 0. Each block runs top to bottom in a fresh empty temporary directory, with ``hrgtc``
of this checkout first on the PATH and ``$DATA`` the absolute path of ``tests/data``, so a
block makes its own inputs (``hrgtc simulate ...``) or reads the repository's test data.
Blocks marked ``text`` or ``python`` are not run.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "tests" / "data"
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
_FENCE = re.compile(r"^(`{3,}|~{3,})\s*([\w+-]*)")
_EXIT = re.compile(r"^#\s*exit\s+(\d+)\s*$")


@dataclass(frozen=True)
class Command:
    line: int
    text: str
    exit_code: int = 0


def console_blocks(text: str) -> list[tuple[int, list[Command]]]:
    """The ``console`` blocks of a Markdown text: (first line, commands) each."""
    blocks: list[tuple[int, list[Command]]] = []
    lines = text.splitlines()
    k = 0
    while k < len(lines):
        fence = _FENCE.match(lines[k].strip())
        if not fence:
            k += 1
            continue
        marker, language = fence.group(1), fence.group(2)
        start = k + 1
        k += 1
        body: list[tuple[int, str]] = []
        while k < len(lines) and not lines[k].strip().startswith(marker):
            body.append((k + 1, lines[k]))
            k += 1
        k += 1
        if language == "console":
            blocks.append((start, _commands(body)))
    return blocks


def _commands(body: list[tuple[int, str]]) -> list[Command]:
    commands: list[Command] = []
    j = 0
    while j < len(body):
        number, line = body[j]
        stripped = line.strip()
        if stripped.startswith("$ "):
            text = stripped[2:]
            while text.endswith("\\") and j + 1 < len(body):
                j += 1
                text = text[:-1].rstrip() + " " + body[j][1].strip()
            commands.append(Command(number, text))
        elif commands and (code := _EXIT.match(stripped)):
            last = commands[-1]
            commands[-1] = Command(last.line, last.text, int(code.group(1)))
        j += 1
    return commands


def _cases() -> list[pytest.param]:
    """One case per distinct block: a block whose commands repeat an earlier block's (the
    README's quick start is the getting-started page's) is the same case, run once, its
    id naming both places."""
    cases: dict[tuple[str, ...], tuple[Path, list[Command], list[str]]] = {}
    for page in PAGES:
        for start, commands in console_blocks(page.read_text(encoding="utf-8")):
            key = tuple(f"{c.text} -> {c.exit_code}" for c in commands)
            cases.setdefault(key, (page, commands, []))[2].append(
                f"{page.relative_to(ROOT)}:{start}")
    return [pytest.param(page, commands, id="+".join(names))
            for page, commands, names in cases.values()]


def _environment() -> dict[str, str]:
    env = dict(os.environ)
    env["PATH"] = os.pathsep.join([str(Path(sys.executable).parent), env.get("PATH", "")])
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT / "src"), env.get("PYTHONPATH", "")])
    env["DATA"] = str(DATA)
    env["COLUMNS"] = "100"
    env.pop("DASK_SCHEDULER_ADDRESS", None)
    return env


@pytest.mark.slow  # about 180 CPU-seconds in all: ~90 s on two idle cores with -n 2
@pytest.mark.parametrize(("page", "commands"), _cases())
def test_console_block_runs(page: Path, commands: list[Command], tmp_path: Path):
    assert commands, f"{page}: a console block without a '$ ' command"
    env = _environment()
    for command in commands:
        done = subprocess.run(["bash", "-c", command.text], cwd=tmp_path, env=env,
                              capture_output=True, text=True, timeout=600)
        assert done.returncode == command.exit_code, (
            f"{page.relative_to(ROOT)} line {command.line}: `{command.text}` exited with "
            f"{done.returncode}, expected {command.exit_code} (add '# exit "
            f"{done.returncode}' after it if that is intended)\n"
            f"stdout:\n{done.stdout[-3000:]}\nstderr:\n{done.stderr[-3000:]}")


def test_the_parser_reads_continuations_and_exit_codes():
    text = "\n".join([
        "```console", "$ hrgtc simulate --profile soak \\", "    -o soaks/", "output line",
        "$ hrgtc info missing.csv", "# exit 2", "```", "```text", "$ not run", "```",
        "````console", "$ echo ok", "````",
    ])
    blocks = console_blocks(text)
    assert [start for start, _ in blocks] == [1, 11]
    assert blocks[0][1] == [Command(2, "hrgtc simulate --profile soak -o soaks/"),
                            Command(5, "hrgtc info missing.csv", 2)]
    assert blocks[1][1] == [Command(12, "echo ok")]


def test_the_docs_have_runnable_examples():
    """Most command examples run: every user-guide page that shows commands has a console block."""
    guide = sorted((ROOT / "docs" / "guide").glob("*.md"))
    assert guide, "docs/guide is missing"
    for page in guide:
        text = page.read_text(encoding="utf-8")
        if "$ hrgtc" in text or "    hrgtc " in text:
            assert console_blocks(text), f"{page.name}: commands shown but none runs"


def test_the_readme_stays_short():
    """The README is what a newcomer reads in five minutes; the rest is on the site."""
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    assert len(readme.encode("utf-8")) <= 15 * 1024
    assert "make test" in readme and "make demo" in readme
    assert console_blocks(readme), "the README's quick start runs as a console block"
