"""Corrupted copies of a real recording never give an internal error (issue 27 item 5).

The chamber file of the corpus (``tests/real_corpus.py``), its rows dropped, duplicated,
swapped, reversed, truncated, quantised, rescaled, blanked, or a column renamed: ``info``
and ``calibrate`` either work or say what is wrong with the file (exit 2), never "internal
error". The whole set (every file, more mutations) was run by hand while this was written;
these are the ones that found something.
"""

from __future__ import annotations

import random
import warnings

import pytest
from typer.testing import CliRunner

from hrgtc.cli import app

from real_corpus import CORPUS

CHAMBER = next(f for f in CORPUS if f.name == "tofupilot-imu-chamber")


def _mutated(kind: str, header: str, lines: list[str]) -> tuple[str, list[str]]:
    rng = random.Random(1)
    if kind == "quantise":  # two significant digits: a coarse channel everywhere
        def coarse(line: str) -> str:
            cells = line.split("\t")
            return "\t".join([cells[0], *(f"{float(c):.2g}" for c in cells[1:])])
        return header, [coarse(line) for line in lines]
    if kind == "blank_cells":
        return header, ["\t".join("" if rng.random() < 0.02 else c for c in line.split("\t"))
                        for line in lines]
    if kind == "swap_rows":
        a, b = 1000, 6000
        lines = lines[:]
        lines[a], lines[b] = lines[b], lines[a]
        return header, lines
    if kind == "reverse":
        return header, lines[::-1]
    if kind == "first_10":
        return header, lines[:10]
    if kind == "rename_column":
        return header.replace("imu.gyro.x", "IMU.GYRO.X_RAW"), lines
    raise ValueError(kind)


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["quantise", "blank_cells", "swap_rows", "reverse", "first_10",
                                  "rename_column"])
def test_a_corrupted_real_file_gets_a_clear_answer(kind, tmp_path):
    header, *lines = CHAMBER.source.read_text(encoding="utf-8").splitlines()
    header, lines = _mutated(kind, header, lines)
    path = tmp_path / f"{kind}.csv"
    path.write_text("\n".join([header, *lines]) + "\n", encoding="utf-8")
    for command in (["info", str(path), *CHAMBER.args],
                    ["calibrate", "--drift", str(path), *CHAMBER.args,
                     "--holdout-fraction", "0.4", "-o", str(tmp_path / "m.json")]):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            result = CliRunner().invoke(app, command)
        assert "internal error" not in result.output, (kind, command[0], result.output)
        assert result.exit_code in (0, 2), (kind, command[0], result.output)
        if result.exit_code == 2:
            assert ("error" in result.output and str(path.name) in result.output) or (
                "rows" in result.output), (kind, command[0], result.output)
