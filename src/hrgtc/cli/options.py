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

import inspect
from collections.abc import Callable
from enum import StrEnum
from typing import TYPE_CHECKING, Annotated, Any

import typer

from hrgtc.core.errors import InputError

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


class OutputFormat(StrEnum):
    """Output file format (suffixes .parquet, .csv, .h5, .tdms, .mat, .mf4): the formats of
    the registry that have a writer, written out so that ``--help`` loads no format (a test
    checks that they agree with ``output_suffixes()``)."""

    parquet = "parquet"
    csv = "csv"
    h5 = "h5"
    tdms = "tdms"
    mat = "mat"
    mf4 = "mf4"

    @property
    def suffix(self) -> str:
        """File suffix of the format, e.g. ``".parquet"``."""
        from hrgtc.recording.formats.registry import output_suffixes

        return output_suffixes()[self.value]


def output_format_callback(value: str | None) -> str | None:
    """``--format``: the output name of a format with a writer (a lab's own included), or an
    error naming those that write (and, for a format hrgtc only reads, that it has no writer).
    """
    if value is None or value in OutputFormat.__members__:
        return value
    from hrgtc.core.errors import RecordingError
    from hrgtc.recording.formats.registry import get, output_suffixes

    can = ", ".join(output_suffixes())
    try:
        fmt = get(value)
    except RecordingError:
        raise typer.BadParameter(f"unknown format {value!r}; the formats that write are "
                                 f"{can}") from None
    if fmt.sink is not None:
        return fmt.output_name
    raise typer.BadParameter(f"hrgtc has no writer for {fmt.name} files ({fmt.description}; "
                             f"its library reads them only); the formats that write are {can}")


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
    temp_unit: str | None = None,
) -> ReadOptions:
    """A :class:`ReadOptions` of the column mapping, the units and the metadata overrides
    (the other reading options are its fields, generated from
    :class:`~hrgtc.settings.reading.ReadSettings`)."""
    from hrgtc.recording import ReadOptions
    from hrgtc.recording.mapping import parse_columns

    units = {"time": time_unit, "freq": freq_unit, "rate": rate_unit, "temp": temp_unit}
    overrides = {"sample_rate_hz": sample_rate_hz, "unit": unit_name,
                 "input_rate_dph": input_rate_dph}
    return ReadOptions(
        columns=parse_columns(col) or None,
        units={k: v for k, v in units.items() if v is not None} or None,
        metadata={k: v for k, v in overrides.items() if v is not None} or None,
    )


#: The reading options that fill the mapping, units and metadata of a ReadOptions, in the
#: order they appear in ``--help`` (before those generated from ReadSettings' fields).
_READING_OPTIONS: tuple[tuple[str, Any], ...] = (
    ("col", ColumnsOption),
    ("time_unit", TimeUnitOption),
    ("freq_unit", FreqUnitOption),
    ("rate_unit", RateUnitOption),
    ("sample_rate_hz", SampleRateOption),
    ("unit_name", UnitNameOption),
    ("input_rate_dph", InputRateOption),
    ("temp_unit", TempUnitOption),
)


def reading_options(command: Callable[..., Any]) -> Callable[..., Any]:
    """Give a command the shared reading options, defined once.

    The decorated function takes ``inputs: ReadOptions`` instead of the separate
    options; the command line shows ``--col``, the unit options and the metadata
    overrides declared here, then one option per field of
    :class:`~hrgtc.settings.reading.ReadSettings` that names one (``--gaps``,
    ``--spikes``, ``--spike-k``, ``--thermometer``, ``--motion``, ``--start``, ...), with
    its default from the field.
    """
    import dataclasses

    from hrgtc.cli.params import add_parameters, option_parameter, option_settings
    from hrgtc.settings.reading import ReadSettings

    generated = option_settings(ReadSettings)
    added = [inspect.Parameter(name, inspect.Parameter.KEYWORD_ONLY, default=None,
                               annotation=kind) for name, kind in _READING_OPTIONS]
    added += [option_parameter(s) for s in generated]

    def make(values: dict[str, Any]) -> ReadOptions:
        options = recording_input(**{name: values.get(name) for name, _ in _READING_OPTIONS})
        return dataclasses.replace(options, **{s.name: values[s.name] for s in generated
                                              if s.name in values})

    return add_parameters(command, "inputs", added, make)
