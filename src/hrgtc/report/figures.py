"""Figures of the HTML report and the decimated data they draw, after Figs. 3-6 of [1].

:func:`trace_soak` and :func:`trace_run` stream a recording chunk by chunk and
reduce it to plotting blocks (block means of at least 10 s); a run is also
compensated (Eq. 22 of [1]) and its bias stability and Allan deviation computed
at the full rate. One function per figure turns that data (or the model) into a
:class:`matplotlib.figure.Figure`; :func:`plot` makes it a :class:`Plot`, the
``<img>`` source (:func:`svg_data_uri`) and its alternative text. Figures are built on
``Figure`` objects directly with the Agg backend, never through ``pyplot``, so no global
figure state is shared between them.

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import base64
import io
import os
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

from hrgtc.evaluation import BlockMeans, Evaluation, block_rows
from hrgtc.evaluation.allan import FLICKER_FLOOR_FACTOR
from hrgtc.recording import ReadOptions, count_rows
from hrgtc.settings.compensation import ReportSettings
from hrgtc.thermometry import Thermometer, paper
from hrgtc.thermometry.plateaus import Plateau

PathLike = str | os.PathLike[str]
#: Colours: the paper's Fig. 6 draws the output blue and the model red.
RAW, MODEL, COMPENSATED, HOUSING, TRUTH, CHAMBER = (
    "#1f5fa8", "#d62728", "#2b8a3e", "#e8890c", "#222222", "#8c8c8c")
_STYLE = {
    "svg.fonttype": "path",
    "svg.hashsalt": "hrgtc",  # deterministic element ids
    "font.size": 9.0,
    "axes.grid": True,
    "grid.color": "#dddddd",
    "grid.linewidth": 0.6,
    "axes.spines.top": False,
    "axes.spines.right": False,
    "legend.fontsize": 8.0,
    "legend.frameon": False,
    "lines.linewidth": 1.1,
}
_PANEL_WIDTH_IN = 3.3
#: Decorator: build (and save) a figure under the report's style, restoring rcParams after.
_styled = matplotlib.rc_context(_STYLE)


@_styled
def svg_data_uri(figure: Figure) -> str:
    """The figure as an SVG ``data:`` URI (self-contained: glyphs as paths)."""
    buffer = io.BytesIO()
    figure.savefig(buffer, format="svg", metadata={"Date": None})
    return "data:image/svg+xml;base64," + base64.b64encode(buffer.getvalue()).decode("ascii")


@dataclass(frozen=True)
class Plot:
    """A drawn figure as a report embeds it: its SVG ``data:`` URI and its alternative text."""

    uri: str
    alt: str


def plot(figure: Figure, alt: str) -> Plot:
    """``figure`` drawn for the page (:func:`svg_data_uri`), with its alternative text."""
    return Plot(svg_data_uri(figure), alt)


def _figure(width_in: float, height_in: float) -> Figure:
    return Figure(figsize=(width_in, height_in), layout="constrained")


def _grid(count: int, height_in: float = 2.4, columns: int = 3) -> tuple[Figure, list[Axes]]:
    columns = max(1, min(columns, count))
    rows = -(-count // columns)
    figure = _figure(_PANEL_WIDTH_IN * columns, height_in * rows)
    axes = figure.subplots(rows, columns, squeeze=False).ravel()
    for extra in axes[count:]:
        extra.set_visible(False)
    return figure, list(axes[:count])


def _plain(ax: Axes) -> None:
    """No offset notation on the y axis (frequencies read in Hz)."""
    ax.ticklabel_format(axis="y", useOffset=False, style="plain")


def _legend_below(figure: Figure, axes: Sequence[Axes]) -> None:
    """One legend under a grid of panels, each label once."""
    entries: dict[str, Any] = {}
    for ax in axes:
        for handle, label in zip(*ax.get_legend_handles_labels(), strict=True):
            entries.setdefault(label, handle)
    if entries:
        figure.legend(list(entries.values()), list(entries), loc="outside lower center",
                      ncols=min(len(entries), 5))


def _hours(time_s: Any) -> np.ndarray:
    return np.asarray(time_s, dtype=np.float64) / 3600.0


# -- data passes --------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class SoakTrace:
    """Block means of one soak recording, for Fig. 3 and Fig. 5 of [1].

    Attributes
    ----------
    source, name
        The file and its name.
    block_s
        Length of the plotting blocks. [s]
    time_s, freq_hz
        Block-mean time [s] and frequency [Hz].
    temperature_c
        Resonator temperature from the block-mean frequency (inverse of Eq. 18). [°C]
    chamber_c, resonator_c
        Block means of the chamber and (simulator) true resonator temperature, if recorded. [°C]
    """

    source: str
    name: str
    block_s: float
    time_s: np.ndarray
    freq_hz: np.ndarray
    temperature_c: np.ndarray
    chamber_c: np.ndarray | None
    resonator_c: np.ndarray | None


def trace_soak(
    path: PathLike, thermometer: Thermometer, *, max_points: int = ReportSettings.max_points,
    read_options: ReadOptions | None = None, on_chunk: Callable[[int], None] | None = None,
) -> SoakTrace:
    """Block means of a soak recording, streamed (blocks of >= 10 s, at most ``max_points``)."""
    return trace_soak_axes(path, {"": thermometer}, max_points=max_points,
                           read_options=read_options, on_chunk=on_chunk)[""]


def trace_soak_axes(
    path: PathLike, thermometers: Mapping[str, Thermometer], *,
    max_points: int = ReportSettings.max_points, read_options: ReadOptions | None = None,
    on_chunk: Callable[[int], None] | None = None,
) -> dict[str, SoakTrace]:
    """:func:`trace_soak` of every axis of a soak from one reading of the file.

    ``thermometers`` maps each axis (``""``: the file as ``read_options`` read it) to its
    thermometer; each axis is traced on its single-axis view of the chunks.
    """
    from hrgtc.recording import axis_view

    means: dict[str, BlockMeans] = {}
    rows = count_rows(path)
    block_s = 0.0
    for chunk in (read_options or ReadOptions()).chunks(path):
        if not means:
            size = block_rows(rows, chunk.sample_rate_hz, max_points)
            means = {axis: BlockMeans(size) for axis in thermometers}
            block_s = size / chunk.sample_rate_hz
        for axis, state in means.items():
            view = axis_view(chunk, axis) if axis else chunk
            state.partial_fit({k: view[k] for k in ("time_s", "freq_hz", "chamber_c",
                                                    "resonator_c") if k in view})
        if on_chunk is not None:
            on_chunk(len(chunk))
    assert means  # iter_chunks raises on an empty file
    traces = {}
    for axis, state in means.items():
        b = state.finish()
        traces[axis] = SoakTrace(str(path), Path(path).name, block_s, b["time_s"],
                                 b["freq_hz"],
                                 thermometers[axis].temperature(b["freq_hz"], warn=False),
                                 b.get("chamber_c"), b.get("resonator_c"))
    return traces


# -- Fig. 3: settling of the soaks -----------------------------------------------------
def _draw_plateau(ax: Axes, plateau: Plateau, data_end_s: float) -> None:
    ax.axvspan(plateau.start_s / 3600, plateau.end_s / 3600, color="#f3e3b5", alpha=0.6, lw=0,
               label="final stretch")
    fit = plateau.fit
    if fit is not None:  # a "constant" fit (no transient) draws as a flat line
        end = max(data_end_s, fit.end_s, fit.start_s + 4.0 * max(fit.tau_s, default=0.0))
        inside = np.linspace(fit.start_s, fit.end_s, 300)
        ax.plot(_hours(inside), fit.evaluate(inside), color=MODEL, lw=0.9,
                label="settling-curve fit")
        if end > fit.end_s and fit.tau_s:
            beyond = np.linspace(fit.end_s, end, 100)
            ax.plot(_hours(beyond), fit.evaluate(beyond), color=MODEL, lw=0.9, ls="--",
                    label="extrapolation")
    ax.axhline(plateau.settled_freq_hz, color=TRUTH, lw=0.8, ls=":",
               label="settled frequency (Table 1)")


@_styled
def settling_figure(
    traces: Sequence[SoakTrace], plateaus: Sequence[Sequence[Plateau]]
) -> Figure:
    """Frequency of each soak against time, its settled value and the settling-curve fit.

    Mirrors Fig. 3 of [1] (frequency from room temperature to the set-point; the
    resonator in vacuum settles after ~15,000 s). ``plateaus[k]`` are the plateaus
    found in ``traces[k]``; a trace may be None to draw the stored fit alone.
    """
    figure, axes = _grid(len(plateaus))
    for ax, trace, found in zip(axes, traces, plateaus, strict=True):
        end = 0.0
        if trace is not None:
            ax.plot(_hours(trace.time_s), trace.freq_hz, color=RAW, label="frequency")
            end = float(trace.time_s[-1])
        for plateau in found:
            _draw_plateau(ax, plateau, end)
        low, high = ax.dataLim.intervaly
        if high - low < 0.01:  # a flat stored fit: show ±10 mHz, not ±0.1 % of 4.4 kHz
            ax.set_ylim(0.5 * (low + high) - 0.01, 0.5 * (low + high) + 0.01)
        setpoints = ", ".join(f"{p.chamber_c:.0f}" for p in found)
        name = trace.name if trace is not None else "stored fit"
        ax.set_title(f"{name} — chamber {setpoints or '?'} °C", fontsize=8.5)
        ax.set_xlabel("time [h]")
        ax.set_ylabel("frequency [Hz]")
        _plain(ax)
    _legend_below(figure, axes)
    return figure


# -- Fig. 4: frequency-temperature fit ---------------------------------------------------
@_styled
def thermometer_figure(
    thermometer: Thermometer, chamber_c: Sequence[float], freq_hz: Sequence[float],
    freq_std_hz: Sequence[float],
) -> Figure:
    """The unit's plateau points, the fitted polynomial and its residuals.

    Mirrors Fig. 4 of [1] (the cubic of Eq. 18 through Table 1); the residual
    panel gives f − f_fit in mHz and, on the right axis, the equivalent
    temperature error through the linear coefficient.
    """
    t = np.asarray(chamber_c, dtype=np.float64)
    f = np.asarray(freq_hz, dtype=np.float64)
    figure = _figure(3 * _PANEL_WIDTH_IN, 3.3)
    fit_ax, res_ax = figure.subplots(1, 2)
    low, high = thermometer.temperature_range_c
    grid = np.linspace(low - 0.05 * (high - low), high + 0.05 * (high - low), 300)
    fit_ax.plot(grid, thermometer.frequency(grid), color=MODEL,
                label=f"order-{thermometer.order} fit (Eq. 18 form)")
    fit_ax.plot(t, f, "o", color=RAW, ms=4, label="plateaus (Table 1)")
    fit_ax.set_xlabel("temperature [°C]")
    fit_ax.set_ylabel("frequency [Hz]")
    fit_ax.legend(loc="upper left")
    _plain(fit_ax)
    residual_mhz = 1e3 * (f - thermometer.frequency(t))
    res_ax.axhline(0.0, color=CHAMBER, lw=0.8)
    res_ax.errorbar(t, residual_mhz, yerr=1e3 * np.asarray(freq_std_hz, dtype=np.float64),
                    fmt="o", color=RAW, ms=4, capsize=2)
    res_ax.set_xlabel("temperature [°C]")
    res_ax.set_ylabel("residual f − f_fit [mHz]")
    slope = float(thermometer.coefficients[1]) if thermometer.order >= 1 else 0.0
    if slope:  # mHz -> °C, or m°C when the residuals are that small
        milli = np.max(np.abs(residual_mhz), initial=0.0) / (1e3 * abs(slope)) < 0.05
        per_mhz = (1.0 if milli else 1e-3) / slope
        second = res_ax.secondary_yaxis(
            "right", functions=(lambda m: m * per_mhz, lambda c: c / per_mhz))
        second.yaxis.set_major_formatter(FuncFormatter(lambda value, _: f"{value:g}"))
        unit = "m°C" if milli else "°C"
        second.set_ylabel(f"≈ temperature error [{unit}] (÷ {slope:.4g} Hz/°C)")
    return figure


# -- Fig. 5: temperature from frequency ---------------------------------------------------
@_styled
def temperature_error_figure(table: Sequence[Mapping[str, float]]) -> Figure:
    """Error of the temperature from frequency at each plateau; mirrors Fig. 5(a) of [1]."""
    t = np.array([row["chamber_c"] for row in table])
    error = np.array([row["error_c"] for row in table])
    figure = _figure(2 * _PANEL_WIDTH_IN, 2.9)
    ax = figure.subplots()
    width = 0.6 * float(np.min(np.diff(np.sort(t)))) if t.size > 1 else 1.0
    ax.bar(t, error, width=width, color=RAW, label="this unit")
    ax.plot(paper.TABLE2_ACTUAL_C, paper.TABLE2_ERROR_C, "o", mfc="none", color=CHAMBER,
            label="paper's unit (Table 2 of [1])")
    ax.axhspan(-0.1, 0.1, color="#e9f3e9", zorder=0, label="±0.1 °C (paper's tolerance)")
    ax.axhline(0.0, color=CHAMBER, lw=0.8)
    ax.set_xlabel("chamber temperature [°C]")
    ax.set_ylabel("T from frequency − chamber [°C]")
    ax.legend(loc="best")
    return figure


@_styled
def soak_temperature_figure(traces: Sequence[SoakTrace]) -> Figure:
    """Temperature from frequency against time for each soak; mirrors Fig. 5(b) of [1].

    The chamber temperature and, for simulated soaks, the true resonator
    temperature are drawn beside it.
    """
    figure, axes = _grid(len(traces))
    for ax, trace in zip(axes, traces, strict=True):
        if trace.chamber_c is not None:
            ax.plot(_hours(trace.time_s), trace.chamber_c, color=CHAMBER, lw=0.9, label="chamber")
        ax.plot(_hours(trace.time_s), trace.temperature_c, color=RAW,
                label="resonator, from frequency")
        if trace.resonator_c is not None:
            ax.plot(_hours(trace.time_s), trace.resonator_c, color=TRUTH, lw=0.9, ls="--",
                    label="resonator, true (simulator)")
        ax.set_title(trace.name, fontsize=8.5)
        ax.set_xlabel("time [h]")
        ax.set_ylabel("temperature [°C]")
        _plain(ax)
    _legend_below(figure, axes)
    return figure


# -- Fig. 6: raw and compensated output ---------------------------------------------------
def _spans(mask: np.ndarray) -> list[tuple[int, int]]:
    """(start, stop) index pairs of the True runs of ``mask``."""
    edges = np.diff(np.concatenate([[0], mask.astype(np.int8), [0]]))
    return list(zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1), strict=True))


@_styled
def run_figure(run: Evaluation, sensor: bool = False) -> Figure:
    """Raw output with the model, compensated output and temperatures of one run.

    Mirrors Fig. 6(a) (output, blue, and model, red) and Fig. 6(b) (compensated
    output) of [1]; a third panel shows the resonator temperature from frequency
    (``sensor``: the thermometer is the gyro's temperature sensor, and the legends
    say so). Stretches with samples outside the calibrated range are shaded.
    """
    b = run.blocks
    hours = _hours(b["time_s"])
    figure = _figure(3 * _PANEL_WIDTH_IN, 7.2)
    raw_ax, comp_ax, temp_ax = figure.subplots(3, 1, sharex=True, height_ratios=(1.2, 1.2, 0.8))
    raw_ax.plot(hours, b["raw_dph"], color=RAW,
                label=f"output − input rate ({_at10(run, 'raw')})")
    raw_ax.plot(hours, b["model_dph"], color=MODEL,
                label="drift model" if sensor else "drift model (Eq. 22 form)")
    if "model_std_dph" in b:  # 1σ of the fitted line from the coefficients' covariance
        raw_ax.fill_between(hours, b["model_dph"] - b["model_std_dph"],
                            b["model_dph"] + b["model_std_dph"], color=MODEL, alpha=0.25, lw=0,
                            label="model ±1σ (coefficient covariance, Newey-West)")
    if "true_dph" in b:
        raw_ax.plot(hours, b["true_dph"], color=TRUTH, lw=0.8, ls="--",
                    label="true bias (simulator)")
    raw_ax.set_ylabel("bias [°/h]")
    raw_ax.set_title(f"(a) raw output and model, {run.block_s:g} s means", fontsize=9)
    comp_ax.plot(hours, b["comp_dph"], color=COMPENSATED,
                 label=f"compensated, {'temperature-sensor' if sensor else 'frequency'} model "
                 f"({_at10(run, 'compensated')})")
    if "comp_housing_dph" in b:
        comp_ax.plot(hours, b["comp_housing_dph"], color=HOUSING, lw=0.9,
                     label=f"compensated, housing thermistor ({_at10(run, 'housing')})")
    comp_ax.set_ylabel("bias [°/h]")
    comp_ax.set_title("(b) compensated output", fontsize=9)
    temp_ax.plot(hours, b["temperature_c"], color=RAW,
                 label="temperature sensor" if sensor else "resonator, from frequency")
    for key, label, colour, style in (
        ("resonator_c", "resonator, true", TRUTH, "--"),
        ("housing_c", "housing thermistor", HOUSING, "-"),
        ("chamber_c", "chamber", CHAMBER, "-"),
    ):
        if key in b:
            temp_ax.plot(hours, b[key], color=colour, lw=0.9, ls=style, label=label)
    temp_ax.set_ylabel("temperature [°C]")
    temp_ax.set_xlabel("time [h]")
    out = b["in_range"] < 1.0
    if np.any(out):
        edges = np.concatenate([hours, [hours[-1] + run.block_s / 3600]])
        for ax in (raw_ax, comp_ax, temp_ax):
            for start, stop in _spans(out):
                ax.axvspan(edges[start], edges[stop], color="#f6d5d5", lw=0, zorder=0)
        temp_ax.plot([], [], color="#f6d5d5", lw=6, label="outside calibrated range")
    for ax in (raw_ax, comp_ax, temp_ax):
        ax.legend(loc="best")
    return figure


def _at10(run: Evaluation, series: str) -> str:
    value = run.stability(series, 10.0)
    return "10 s stability n/a" if value is None else f"10 s stability {value:.4g} °/h"


@_styled
def allan_figure(run: Evaluation) -> Figure:
    """Allan deviation of the raw and compensated output (log-log), minima marked.

    Where the curve carries a confidence interval (overlapping Allan deviation,
    chi-squared with the simple edf of SP 1065) it is drawn as error bars.
    """
    figure = _figure(2 * _PANEL_WIDTH_IN, 3.6)
    ax = figure.subplots()
    colours = {"raw": RAW, "compensated": COMPENSATED, "housing": HOUSING}
    labels = {"raw": "raw", "compensated": "compensated (frequency)",
              "housing": "compensated (housing thermistor)"}
    for key, allan in run.allan.items():
        ax.loglog(allan.taus_s, allan.deviation, "-o", ms=2.5, color=colours[key],
                  label=labels[key])
        if allan.lower is not None and allan.upper is not None:
            ax.errorbar(allan.taus_s, allan.deviation,
                        yerr=(allan.deviation - allan.lower, allan.upper - allan.deviation),
                        fmt="none", ecolor=colours[key], elinewidth=0.8, capsize=1.5)
            ax.fill_between(allan.taus_s, allan.lower, allan.upper, color=colours[key],
                            alpha=0.12, lw=0)
        terms = run.noise.get(key)
        if terms is not None and terms.bias_instability_dph is not None:
            tau = terms.bias_instability_tau_s
            minimum = terms.bias_instability_dph * FLICKER_FLOOR_FACTOR
            ax.plot([tau], [minimum], "s", mfc="none", ms=7, color=colours[key])
    ax.set_xlabel("averaging time τ [s]")
    names = {"adev": "Allan deviation (non-overlapping)", "oadev": "Allan deviation",
             "mdev": "modified Allan deviation", "hdev": "Hadamard deviation",
             "tdev": "time deviation"}
    unit = "[°/h·s]" if run.deviation == "tdev" else "[°/h]"
    ax.set_ylabel(f"{names.get(run.deviation, run.deviation)} {unit}")
    plain = FuncFormatter(lambda value, _: f"{value:g}")
    ax.xaxis.set_major_formatter(plain)
    ax.yaxis.set_major_formatter(plain)
    low, high = ax.get_ylim()
    if high / low < 100.0:  # under two decades: label 2 and 5 between the powers of ten
        ax.yaxis.set_minor_locator(LogLocator(subs=(2.0, 5.0)))
        ax.yaxis.set_minor_formatter(plain)
    else:
        ax.yaxis.set_minor_formatter(NullFormatter())
    ax.legend(loc="best")
    ax.grid(True, which="minor", color="#f0f0f0", lw=0.4)
    return figure
