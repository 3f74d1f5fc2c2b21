"""Build the HTML report of a unit or of a whole instrument (one section per axis).

:func:`build_report` checks its inputs (:func:`hrgtc.report.inputs.report_inputs`), asks the
report kind's data function (:data:`hrgtc.report.kinds.KINDS`, "paper" by default) for the
report's data, which reads the soaks and runs chunk by chunk, each file once for all the axes,
and renders that data with the kind's templates (:func:`hrgtc.report.render.render`) into one
self-contained page, written atomically.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

from hrgtc.core.errors import InputError
from hrgtc.core.files import refuse_existing, write_text_atomic
from hrgtc.core.progress import Progress
from hrgtc.evaluation import Evaluation
from hrgtc.model import Model
from hrgtc.recording import ReadOptions
from hrgtc.report.inputs import ReportInputs, report_inputs
from hrgtc.report.kinds import kind as report_kind
from hrgtc.report.render import render
from hrgtc.settings.compensation import ReportSettings

__all__ = ["build_report"]

PathLike = str | os.PathLike[str]


def build_report(
    model: Model | PathLike,
    runs: Sequence[PathLike | Evaluation],
    output: PathLike,
    settings: ReportSettings | None = None,
    *,
    soaks: Sequence[PathLike] | None = None,
    force: bool = False,
    read_options: ReadOptions | None = None,
    progress: Progress | None = None,
    model_source: str = "",
) -> Path:
    """Write the report: one self-contained HTML file with Figs. 3-6 and Tables 1-2 of [1].

    Parameters
    ----------
    model
        The unit's or instrument's model, or the path of its model file.
    runs
        Recordings to compensate and evaluate (Fig. 6 of [1]), one section each, or
        evaluations already made with plotting blocks (``.axis`` of
        :func:`hrgtc.evaluation.evaluate` with ``max_points``; single-axis models only),
        which are not computed again.
    output
        The HTML file; written atomically, never overwritten without ``force``.
    settings
        The page's settings (:class:`~hrgtc.settings.compensation.ReportSettings`): most
        points per plotted curve (plots use block means of at least 10 s), title (default
        names the unit), the kind of report (:data:`hrgtc.report.kinds.KINDS`: its data
        and its templates; "paper" lays the calibration's evidence out like [1]) and the
        axes to show (None: all; the model's and each run's axes must agree unless
        ``axes`` names those to show, :func:`hrgtc.compensate.multi_axis.match_axes`).
        Default: the defaults.
    soaks
        Soak recordings for Figs. 3 and 5(b); default: the model's soak inputs that
        still exist on disk (read with the column mapping stored in the model).
    read_options
        How to read the runs and the given soaks (column mapping, units, metadata); the
        model's temperature map (``--temp-ref``) applies unless they give their own
        scale and offset.
    progress
        Optional ``callback(rows_done, rows_total)``.
    model_source
        The model's name in messages (default: its path when ``model`` is one).

    Returns
    -------
    pathlib.Path
        The written file.

    Raises
    ------
    OutputExistsError
        ``output`` exists and ``force`` is False (checked before any work).
    InputError
        An evaluation given in ``runs`` kept no plotting blocks, or was given for a
        multi-axis model; the runs are read as the other kind of thermometer than the
        model's; the model's and a run's axes differ (checked before any run is read); no
        such ``kind``.
    """
    settings = settings or ReportSettings()
    target = Path(output)
    refuse_existing(target, force)
    chosen = report_kind(settings.kind)
    if chosen.takes is not ReportInputs:
        raise InputError(f"kind={settings.kind!r} is not made from a model and runs; use "
                         "hrgtc.report.test_report.write_test_report (hrgtc test-report)")
    inputs = report_inputs(model, runs, soaks=soaks, title=settings.title,
                           max_points=settings.max_points, read_options=read_options,
                           progress=progress, axes=settings.axes, model_source=model_source)
    return write_text_atomic(target, render(chosen.template, report=chosen.data(inputs)),
                             force=force)
