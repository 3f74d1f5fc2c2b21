"""Tests of hrgtc.cli.commands: the commands are the entry points of ``hrgtc.commands``.

hrgtc's own are declared in pyproject.toml and listed by ``hrgtc --help`` in HELP_ORDER;
another package's command appears beside them, given as importlib.metadata's own
EntryPoint objects (in-process) or installed as a ``*.dist-info`` folder on the path (a
fresh process); a broken one is left out with a warning. The group is read from the
``entry_points.txt`` files directly (hrgtc --help does not import importlib.metadata), and
what it finds is compared with importlib.metadata's answer.
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
import tomllib
from importlib import metadata
from pathlib import Path

import pytest
import typer
from typer.testing import CliRunner

from hrgtc.cli import app
from hrgtc.cli.commands import (
    ENTRY_POINT_GROUP,
    HELP_ORDER,
    EntryPoint,
    entry_points,
    register_commands,
)
from hrgtc.core.errors import CommandPluginWarning

ROOT = Path(__file__).resolve().parents[2]
DECLARED = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))[
    "project"]["entry-points"][ENTRY_POINT_GROUP]
PLUGIN = '''
"""mylab_cmd.py: a lab's own command."""


def check(name: str, loud: bool = False) -> None:
    """Say hello to a unit of the lab."""
    print(("HELLO " if loud else "hello ") + name)
'''


#: ``hrgtc --help`` with the lab's command: after hrgtc's commands, before the groups (typer
#: lists a group, such as ``fleet``, after the commands).
SHOWN = [*HELP_ORDER[:-1], "mylab-check", "fleet"]


def own() -> list[EntryPoint]:
    """hrgtc's own entry points (not those of a plugin put on the path)."""
    return [p for p in entry_points() if p.distribution == "hrgtc"]


def listed(help_text: str) -> list[str]:
    """The command names of a ``--help`` text, in order."""
    lines = help_text.split("Commands:")[1].splitlines()
    return [line.split()[0] for line in lines if line.startswith("  ") and line.strip()]


def test_help_lists_the_declared_commands_in_order():
    """Every command of pyproject.toml, in HELP_ORDER (the order before the entry points:
    compensate, evaluate, calibrate, ..., fleet last); the installed metadata is
    pyproject's (else: reinstall)."""
    assert sorted(HELP_ORDER) == sorted(DECLARED)
    installed = {p.name: p.value for p in entry_points() if p.distribution == "hrgtc"}
    assert installed == DECLARED, "reinstall hrgtc: pip install -e . (or make)"
    result = CliRunner().invoke(app, ["--help"], terminal_width=100)
    assert result.exit_code == 0
    assert listed(result.output) == list(HELP_ORDER)


def test_the_scan_finds_what_importlib_metadata_finds():
    ours = sorted((p.name, p.value) for p in entry_points())
    theirs = sorted((p.name, p.value) for p in metadata.entry_points(group=ENTRY_POINT_GROUP))
    assert ours == theirs


@pytest.fixture
def plugin_site(tmp_path):
    """A tiny installed distribution: a module and a dist-info with a command."""
    site = tmp_path / "site"
    info = site / "mylab_cmd-1.0.dist-info"
    info.mkdir(parents=True)
    (site / "mylab_cmd.py").write_text(textwrap.dedent(PLUGIN), encoding="utf-8")
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: mylab-cmd\nVersion: 1.0\n",
                                   encoding="utf-8")
    (info / "entry_points.txt").write_text(
        "[console_scripts]\nmylab = mylab_cmd:check\n\n"
        f"[{ENTRY_POINT_GROUP}]\nmylab-check = mylab_cmd:check\n", encoding="utf-8")
    return site


def test_a_third_party_command_appears_beside_the_own(plugin_site, monkeypatch):
    """Given as importlib.metadata EntryPoint objects: listed after hrgtc's own commands
    (before the fleet group), and run with its options."""
    monkeypatch.syspath_prepend(str(plugin_site))
    third = metadata.EntryPoint(name="mylab-check", value="mylab_cmd:check",
                                group=ENTRY_POINT_GROUP)
    fresh = typer.Typer(rich_markup_mode=None)
    try:
        added = register_commands(fresh, [*own(), third])
        assert added == [*HELP_ORDER, "mylab-check"]
        runner = CliRunner()
        result = runner.invoke(fresh, ["--help"], terminal_width=100)
        assert listed(result.output) == SHOWN
        assert "Say hello to a unit of the lab." in result.output
        result = runner.invoke(fresh, ["mylab-check", "gyro7", "--loud"])
        assert result.exit_code == 0 and result.output == "HELLO gyro7\n"
    finally:
        sys.modules.pop("mylab_cmd", None)


def test_a_command_installed_as_a_distribution_runs_in_a_fresh_process(plugin_site):
    """The real path: a ``*.dist-info`` on PYTHONPATH, ``hrgtc --help`` and the command."""
    env = {**os.environ,
           "PYTHONPATH": os.pathsep.join([str(ROOT / "src"), str(plugin_site)])}

    def hrgtc(*args: str) -> subprocess.CompletedProcess[str]:
        return subprocess.run([sys.executable, "-m", "hrgtc.cli", *args], capture_output=True,
                              text=True, env={**env, "COLUMNS": "100"}, timeout=120)

    shown = hrgtc("--help")
    assert shown.returncode == 0, shown.stderr
    assert listed(shown.stdout) == SHOWN
    ran = hrgtc("mylab-check", "gyro7")
    assert ran.returncode == 0, ran.stderr
    assert ran.stdout == "hello gyro7\n"


def test_the_scan_reads_one_group_first_distribution_of_a_name_wins(tmp_path):
    first, second = tmp_path / "a", tmp_path / "b"
    for folder, value in ((first, "one:f"), (second, "two:f")):
        info = folder / "Lab_Cmd-2.0.dist-info"
        info.mkdir(parents=True)
        (info / "entry_points.txt").write_text(
            f"# generated\n[other.group]\nx = no:thing\n\n[{ENTRY_POINT_GROUP}]\n"
            f"lab = {value}\n", encoding="utf-8")
    legacy = second / "old_cmd.egg-info"
    legacy.mkdir()
    (legacy / "entry_points.txt").write_text(f"[{ENTRY_POINT_GROUP}]\nold=old_cmd : main\n",
                                             encoding="utf-8")
    (second / "no_entry_points-1.0.dist-info").mkdir()
    found = entry_points(path=[str(first), str(tmp_path / "missing"), str(second)])
    assert [(p.name, p.value, p.distribution) for p in found] == [
        ("lab", "one:f", "lab-cmd"), ("old", "old_cmd : main", "old-cmd")]


def test_a_broken_or_clashing_command_is_left_out_with_a_warning(plugin_site, monkeypatch):
    monkeypatch.syspath_prepend(str(plugin_site))
    points = [EntryPoint("mylab-check", "mylab_cmd:NO_SUCH_NAME", ENTRY_POINT_GROUP),
              EntryPoint("calibrate", "mylab_cmd:check", ENTRY_POINT_GROUP),
              EntryPoint("constant", "os:sep", ENTRY_POINT_GROUP),
              EntryPoint("fine", "mylab_cmd:check", ENTRY_POINT_GROUP)]
    fresh = typer.Typer()
    try:
        with pytest.warns(CommandPluginWarning) as caught:
            added = register_commands(fresh, [*own(), *points])
        assert added == [*HELP_ORDER, "fine"]
        messages = [str(w.message) for w in caught]
        assert any("'mylab-check' of the entry point 'mylab_cmd:NO_SUCH_NAME' "
                   f"({ENTRY_POINT_GROUP}) was not loaded" in m for m in messages)
        assert any("'calibrate' is already taken" in m for m in messages)
        assert any("str is neither a function nor a typer.Typer" in m for m in messages)
    finally:
        sys.modules.pop("mylab_cmd", None)


def test_a_missing_install_is_said(monkeypatch):
    """hrgtc on the path but not installed (or installed before its commands were entry
    points): no command, and a warning that says to install it."""
    monkeypatch.setattr("hrgtc.cli.commands.entry_points", lambda: [])
    with pytest.warns(CommandPluginWarning, match=r"own commands are not declared.*"
                                                  r"pip install -e \."):
        assert register_commands(typer.Typer()) == []
