"""Options shared by the ``hrgtc`` commands, defined once.

Use the ``Annotated`` aliases as parameter types. Commands that read
recordings get the shared reading options (column mapping, units, sample rate,
unit name, input rate, gap policy, and for messy IMU files temperature scale and
offset, spikes and the thermometer) from :func:`reading_options` and receive them as one
:class:`hrgtc.recording.ReadOptions`, the type the library takes::

    @app.command()
    @reading_options
    def compensate(
        run: Path,
        force: ForceOption = False,
        inputs: ReadOptions | None = None,
    ) -> None:
        with library_errors():
            recording = inputs.read(run)

Nothing here imports the library's stages at import time (``hrgtc --help`` must
start at once): the parsers of the reading options are imported when called.
"""

from __future__ import annotations

import functools
import inspect
from collections.abc import Callable
from enum import StrEnum
from typing import TYPE_CHECKING, Annotated, Any

import typer

from hrgtc.errors import InputError

if TYPE_CHECKING:
    from hrgtc.recording import ReadOptions


def _columns_callback(value: list[str] | None) -> list[str] | None:
    from hrgtc.recording.mapping import parse_columns

    try:
        parse_columns(value)
    except InputError as exc:
        raise typer.BadParameter(str(exc)) from None
    return value


def _unit_callback(kind: str) -> Any:
    def callback(value: str | None) -> str | None:
        if value is None:
            return None
        from hrgtc.recording.mapping import parse_unit

        try:
            return parse_unit(kind, value)
        except InputError as exc:
            raise typer.BadParameter(str(exc)) from None

    return callback


class GapPolicy(StrEnum):
    """What to do with gaps longer than 2 sample periods."""

    error = "error"
    split = "split"
    bridge = "bridge"
    ignore = "ignore"


class MotionPolicy(StrEnum):
    """What calibration and evaluation do with samples not at rest."""

    exclude = "exclude"
    keep = "keep"
    error = "error"


class SpikePolicy(StrEnum):
    """What to do with spikes (non-finite or physically impossible samples)."""

    error = "error"
    drop = "drop"


class SpikeFilterMode(StrEnum):
    """What to do with single-sample spikes of plausible value."""

    drop = "drop"
    flag = "flag"
    off = "off"


class SlowChannelPolicy(StrEnum):
    """What to do with a channel logged slower than the file's rows (empty cells)."""

    hold = "hold"
    interpolate = "interpolate"
    error = "error"


class Thermometer(StrEnum):
    """What the thermometer of the gyro is."""

    resonator = "resonator"
    sensor = "sensor"


class OutputFormat(StrEnum):
    """Output file format (suffixes .parquet, .csv, .h5)."""

    parquet = "parquet"
    csv = "csv"
    h5 = "h5"

    @property
    def suffix(self) -> str:
        """File suffix of the format, e.g. ``".parquet"``."""
        from hrgtc.recording.formats import FORMAT_SUFFIXES

        return FORMAT_SUFFIXES[self.value]


_INPUT = "Input recordings"

ColumnsOption = Annotated[
    list[str] | None,
    typer.Option(
        "--col",
        metavar="NAME=THEIRS",
        help="Map a recording column to your file's column, e.g. --col freq_hz=f_res "
        "(repeat, or separate with commas). Names: time_s, freq_hz, rate_dph, chamber_c, "
        "housing_c, resonator_c, bias_dph, input_rate_dph, temperature_c, scale_ppm; per axis "
        "<name>_<axis>, e.g. --col rate_dph_x=gyro_x.",
        callback=_columns_callback,
        rich_help_panel=_INPUT,
    ),
]
#: The conversions of each unit option, written out from
#: :func:`hrgtc.recording.units.unit_help` (``--help`` must not import numpy; a test
#: checks that they agree).
UNIT_HELP = {
    "time": (
        'to s: s (s, ×1); ms (ms, /1000); us (µs, /10^6); ns (ns, /10^9); timestamp '
        '(ISO 8601, seconds since the first sample)'
    ),
    "freq": (
        'to Hz: Hz (Hz, ×1); kHz (kHz, ×1000)'
    ),
    "rate": (
        'to °/h: dph (°/h, ×1); dps (°/s, ×3600); mdps (m°/s, ×3.6); radps (rad/s, '
        '×648000/π); mradps (mrad/s, ×648/π); drad (Δθ rad/sample, ×648000/π ÷ Δt); '
        'ddeg (Δθ °/sample, ×3600 ÷ Δt); lsb (LSB, ×3600/K, K = --rate-scale LSB per '
        '°/s)'
    ),
    "temp": (
        'to °C: C (°C, ×1); F (°F, (F − 32)×5/9); K (K, − 273.15); count (raw count, × '
        '--temp-scale + --temp-offset, or a --temp-ref log)'
    ),
}


TimeUnitOption = Annotated[
    str | None,
    typer.Option(
        "--time-unit",
        metavar="s|ms|us|ns|timestamp",
        help="Unit of the time column, " + UNIT_HELP["time"] + "; default s.",
        callback=_unit_callback("time"),
        rich_help_panel=_INPUT,
    ),
]
FreqUnitOption = Annotated[
    str | None,
    typer.Option(
        "--freq-unit",
        metavar="Hz|kHz",
        help="Unit of the frequency column, " + UNIT_HELP["freq"] + "; default Hz.",
        callback=_unit_callback("freq"),
        rich_help_panel=_INPUT,
    ),
]
RateUnitOption = Annotated[
    str | None,
    typer.Option(
        "--rate-unit",
        metavar="UNIT",
        help="Unit of the gyro rate columns (every rate_dph* and input_rate_dph* column), "
        + UNIT_HELP["rate"] + "; Δt is each sample's time step (the median period after a "
        "gap); default dph.",
        callback=_unit_callback("rate"),
        rich_help_panel=_INPUT,
    ),
]
RateScaleOption = Annotated[
    float | None,
    typer.Option(
        "--rate-scale",
        metavar="K",
        help="With --rate-unit lsb: the datasheet's sensitivity K in LSB per °/s "
        "(rate [°/h] = count × 3600 / K).",
        rich_help_panel=_INPUT,
    ),
]
TempUnitOption = Annotated[
    str | None,
    typer.Option(
        "--temp-unit",
        metavar="C|F|K|count",
        help="Unit of the temperature columns, " + UNIT_HELP["temp"] + "; °F and K convert "
        "every temperature column, a count only temperature_c*; default C.",
        callback=_unit_callback("temp"),
        rich_help_panel=_INPUT,
    ),
]
TempUnwrapOption = Annotated[
    str | None,
    typer.Option(
        "--temp-unwrap",
        metavar="auto|off|16|32",
        help="A raw temperature count that sits just under 2^16 or 2^32 is a signed count "
        "stored unsigned and is unwrapped (65236 -> -300), with a warning (auto, default); "
        "off reads it as it is; 16 or 32 always unwraps that width.",
        rich_help_panel=_INPUT,
    ),
]
SampleRateOption = Annotated[
    float | None,
    typer.Option(
        "--sample-rate-hz",
        "--rate-hz",
        help="Sample rate of the input [Hz], overriding the file's metadata "
        "(inferred from the time steps when the file has none).",
        rich_help_panel=_INPUT,
    ),
]
UnitNameOption = Annotated[
    str | None,
    typer.Option(
        "--unit-name",
        help="Gyro serial / name, overriding the file's metadata.",
        rich_help_panel=_INPUT,
    ),
]
InputRateOption = Annotated[
    float | None,
    typer.Option(
        "--input-rate-dph",
        help="Known rate on the sensitive axis during the test [°/h] (e.g. the Earth-rate "
        "component), overriding the file's metadata.",
        rich_help_panel=_INPUT,
    ),
]
GapsOption = Annotated[
    GapPolicy,
    typer.Option(
        "--gaps",
        help="Gaps longer than 2 sample periods: fail (error), process the segments "
        "separately (split: filters restart), or carry the filters across each gap with its "
        "duration (bridge; ignore is an old name for it). Windows and Allan never cross a gap.",
        rich_help_panel=_INPUT,
    ),
]
TzOption = Annotated[
    str | None,
    typer.Option(
        "--tz",
        metavar="ZONE",
        help="Time zone the clock times (--time-unit timestamp) were written in, an IANA name "
        "(e.g. Europe/Berlin): they are read as UTC, so the daylight-saving step is gone; "
        "--start/--end clock times too. Default: none (a 3600 s step is an error).",
        rich_help_panel=_INPUT,
    ),
]
StartOption = Annotated[
    str | None,
    typer.Option(
        "--start",
        metavar="SECONDS|ISO",
        help="Read from this time on: seconds since the file's first sample (e.g. 600) or, for "
        "a file with clock times, an ISO time (e.g. 2020-03-07T16:30). Rows before are "
        "counted, not used.",
        rich_help_panel=_INPUT,
    ),
]
EndOption = Annotated[
    str | None,
    typer.Option(
        "--end",
        metavar="SECONDS|ISO",
        help="Read up to (not including) this time: seconds since the file's first sample or "
        "an ISO clock time, as for --start.",
        rich_help_panel=_INPUT,
    ),
]
_ReadingGapsOption = Annotated[
    GapPolicy | None,
    typer.Option(
        "--gaps",
        help="Gaps longer than 2 sample periods: fail (error, default), process the segments "
        "separately (split: the df/dt filter restarts after each gap), or carry the filters "
        "across each gap with its duration (bridge, e.g. a burst logger; ignore is an old "
        "name for it). Windows, bias stability and Allan deviation never cross a gap.",
        rich_help_panel=_INPUT,
    ),
]
TempScaleOption = Annotated[
    float | None,
    typer.Option(
        "--temp-scale",
        metavar="K",
        help="Temperature logged as a raw sensor count: temperature_c = raw * K + C for every "
        "temperature_c* column (with --temp-offset C); default 1.",
        rich_help_panel=_INPUT,
    ),
]
TempOffsetOption = Annotated[
    float | None,
    typer.Option(
        "--temp-offset",
        metavar="C",
        help="Offset [°C] of --temp-scale: temperature_c = raw * K + C; default 0.",
        rich_help_panel=_INPUT,
    ),
]
SpikesOption = Annotated[
    SpikePolicy | None,
    typer.Option(
        "--spikes",
        help="Samples no gyro can produce (NaN, beyond 1000 °/s, impossible temperatures or "
        "frequencies): fail naming the row (error, default) or drop those rows (drop: "
        "their number is reported).",
        rich_help_panel=_INPUT,
    ),
]
SpikeFilterOption = Annotated[
    SpikeFilterMode | None,
    typer.Option(
        "--spike-filter",
        help="Single-sample spikes of plausible value in the rate and thermometer columns "
        "(beyond max(k·σ_MAD, m·LSB) from both neighbours, σ_MAD over --spike-window-s "
        "windows that never span a gap): remove their rows (drop; default of calibrate and "
        "evaluate), mark them in a 'spike' column (flag; compensate's default, which never "
        "drops) or leave them (off). Their number is reported.",
        rich_help_panel=_INPUT,
    ),
]
SpikeKOption = Annotated[
    float | None,
    typer.Option("--spike-k", metavar="K", help="Spike threshold in robust σ (MAD); default 8.",
                 rich_help_panel=_INPUT),
]
SpikeLsbOption = Annotated[
    float | None,
    typer.Option("--spike-lsb", metavar="M",
                 help="Spike threshold floor in steps of the channel's resolution (LSB), so a "
                 "quantised stream keeps its pulses; default 4.", rich_help_panel=_INPUT),
]
SpikeWindowOption = Annotated[
    float | None,
    typer.Option("--spike-window-s", metavar="S",
                 help="Window of the spike filter's σ_MAD [s]; default 10.",
                 rich_help_panel=_INPUT),
]
ThermometerOption = Annotated[
    Thermometer | None,
    typer.Option(
        "--thermometer",
        help="The gyro's thermometer: its resonator frequency (resonator, default; freq_hz "
        "columns) or, for gyros without a frequency output, its temperature sensor (sensor: "
        "the temperature_c or temperature_c_<axis> column takes the place of freq_hz).",
        rich_help_panel=_INPUT,
    ),
]
MotionOption = Annotated[
    MotionPolicy | None,
    typer.Option(
        "--motion",
        help="Samples not at rest (handling, turning, shaking, clipping; found against the "
        "local still level, the at-rest noise and any accel_x/y/z columns, with a guard time): "
        "left out of calibration and evaluation and counted (exclude, default), used (keep), "
        "or an error naming the first one (error).",
        rich_help_panel=_INPUT,
    ),
]
SlowChannelsOption = Annotated[
    SlowChannelPolicy | None,
    typer.Option(
        "--slow-channels",
        help="A channel logged slower than the rows (e.g. a 1 Hz temperature in a 10 Hz "
        "file: empty cells): hold its last value (hold, default), interpolate linearly in "
        "time, or refuse the empty cells (error). What was done is reported.",
        rich_help_panel=_INPUT,
    ),
]
HoldMaxOption = Annotated[
    float | None,
    typer.Option(
        "--hold-max-s",
        metavar="S",
        help="Longest time a slow channel's value is used for [s] (default 3 of its "
        "periods); rows farther from a value are dropped as a gap in that channel.",
        rich_help_panel=_INPUT,
    ),
]
ForceOption = Annotated[bool, typer.Option("--force", help="Overwrite existing output files.")]
#: Exit status of --strict when samples went beyond the trained ranges.
STRICT_EXIT = 3
StrictOption = Annotated[bool, typer.Option(
    "--strict", help="Exit with status 3 when samples went beyond the trained temperature or "
    "df/dt ranges (the warnings are printed either way).")]
JsonOption = Annotated[
    bool, typer.Option("--json", help="Print machine-readable JSON on standard output.")
]
FormatOption = Annotated[OutputFormat, typer.Option("--format", help="Output file format.")]
AxesOption = Annotated[str | None, typer.Option(
    "--axes", help="Axes to compensate, comma-separated (x,y): needed when the model and the "
    "recording have different axes (each other axis is left as it is), or to apply a "
    "single-axis model to one axis of a multi-axis recording.")]


def recording_input(
    col: list[str] | None = None,
    time_unit: str | None = None,
    freq_unit: str | None = None,
    rate_unit: str | None = None,
    sample_rate_hz: float | None = None,
    unit_name: str | None = None,
    input_rate_dph: float | None = None,
    gaps: GapPolicy | str | None = None,
    temp_scale: float | None = None,
    temp_offset: float | None = None,
    spikes: SpikePolicy | str | None = None,
    thermometer: Thermometer | str | None = None,
    rate_scale: float | None = None,
    temp_unit: str | None = None,
    temp_unwrap: str | None = None,
    spike_filter: SpikeFilterMode | str | None = None,
    spike_k: float | None = None,
    spike_lsb: float | None = None,
    spike_window_s: float | None = None,
    motion: MotionPolicy | str | None = None,
    start: str | None = None,
    end: str | None = None,
    slow_channels: SlowChannelPolicy | str | None = None,
    hold_max_s: float | None = None,
    tz: str | None = None,
) -> ReadOptions:
    """Gather the values of the shared reading options into a :class:`ReadOptions`."""
    from hrgtc.recording import ReadOptions
    from hrgtc.recording.mapping import parse_columns

    units = {"time": time_unit, "freq": freq_unit, "rate": rate_unit, "temp": temp_unit}
    if temp_unwrap not in (None, "auto", "off", "16", "32"):
        raise typer.BadParameter(f"--temp-unwrap must be auto, off, 16 or 32, got "
                                 f"{temp_unwrap!r}")
    overrides = {"sample_rate_hz": sample_rate_hz, "unit": unit_name,
                 "input_rate_dph": input_rate_dph}
    return ReadOptions(
        columns=parse_columns(col) or None,
        units={k: v for k, v in units.items() if v is not None} or None,
        metadata={k: v for k, v in overrides.items() if v is not None} or None,
        gaps=str(getattr(gaps, "value", gaps) or "error"),
        temp_scale=1.0 if temp_scale is None else float(temp_scale),
        temp_offset_c=0.0 if temp_offset is None else float(temp_offset),
        spikes=str(getattr(spikes, "value", spikes) or "error"),
        thermometer=str(getattr(thermometer, "value", thermometer) or "resonator"),
        rate_scale=None if rate_scale is None else float(rate_scale),
        temp_unwrap=temp_unwrap or "auto",
        spike_filter=None if spike_filter is None else str(getattr(spike_filter, "value",
                                                                   spike_filter)),
        **{name: float(value) for name, value in (("spike_k", spike_k), ("spike_lsb", spike_lsb),
                                                 ("spike_window_s", spike_window_s))
           if value is not None},
        motion=str(getattr(motion, "value", motion) or "exclude"),
        start=start,
        end=end,
        slow_channels=str(getattr(slow_channels, "value", slow_channels) or "hold"),
        hold_max_s=None if hold_max_s is None else float(hold_max_s),
        tz=tz,
    )


#: The shared reading options, in the order they appear in ``--help``.
_READING_OPTIONS: tuple[tuple[str, Any], ...] = (
    ("col", ColumnsOption),
    ("time_unit", TimeUnitOption),
    ("tz", TzOption),
    ("freq_unit", FreqUnitOption),
    ("rate_unit", RateUnitOption),
    ("rate_scale", RateScaleOption),
    ("sample_rate_hz", SampleRateOption),
    ("unit_name", UnitNameOption),
    ("input_rate_dph", InputRateOption),
    ("gaps", _ReadingGapsOption),
    ("temp_scale", TempScaleOption),
    ("temp_offset", TempOffsetOption),
    ("temp_unit", TempUnitOption),
    ("temp_unwrap", TempUnwrapOption),
    ("spikes", SpikesOption),
    ("spike_filter", SpikeFilterOption),
    ("spike_k", SpikeKOption),
    ("spike_lsb", SpikeLsbOption),
    ("spike_window_s", SpikeWindowOption),
    ("thermometer", ThermometerOption),
    ("motion", MotionOption),
    ("start", StartOption),
    ("end", EndOption),
    ("slow_channels", SlowChannelsOption),
    ("hold_max_s", HoldMaxOption),
)


def reading_options(command: Callable[..., Any]) -> Callable[..., Any]:
    """Give a command the shared reading options, defined once here.

    The decorated function takes ``inputs: ReadOptions`` (as its last
    parameter) instead of the separate options; the command line still shows
    ``--col``, ``--time-unit``, ``--freq-unit``, ``--rate-unit``, ``--sample-rate-hz``,
    ``--unit-name``, ``--input-rate-dph``, ``--gaps``, ``--temp-scale``,
    ``--temp-offset``, ``--spikes``, ``--thermometer``, ``--motion``, ``--start`` and
    ``--end``.
    """
    signature = inspect.signature(command)
    namespace = command.__globals__
    own = [p.replace(annotation=eval(p.annotation, namespace))
           if isinstance(p.annotation, str) else p
           for name, p in signature.parameters.items() if name != "inputs"]
    added = [
        inspect.Parameter(name, inspect.Parameter.KEYWORD_ONLY, default=None, annotation=kind)
        for name, kind in _READING_OPTIONS
    ]

    @functools.wraps(command)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        values = {name: kwargs.pop(name, None) for name, _ in _READING_OPTIONS}
        return command(*args, inputs=recording_input(**values), **kwargs)

    parameters = [
        p.replace(kind=inspect.Parameter.KEYWORD_ONLY) for p in own
    ] + added
    wrapper.__signature__ = signature.replace(parameters=parameters)  # type: ignore[attr-defined]
    wrapper.__annotations__ = {p.name: p.annotation for p in parameters}
    del wrapper.__wrapped__  # Typer must see the new signature, not the wrapped one
    return wrapper
