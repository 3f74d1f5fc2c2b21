"""``hrgtc simulate``: simulated chamber runs (soaks, cool-down, warm-up, ...) to files."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer
from rich.table import Table

from hrgtc.cli._app import app, console, library_errors, print_json, progress_bar
from hrgtc.cli.options import ForceOption, JsonOption, OutputFormat

# Written out so that --help needs no import of the simulator (it starts at once); a test
# holds them equal to hrgtc.simulate's KINDS, unit names, DEFAULT_UNIT and input rate.
PROFILE_KINDS = ("soak", "cooldown", "warmup", "constant", "ramp", "ratetable")
UNIT_NAMES = ("paper-unit", "unit-b", "imu-3", "mems-3")
DEFAULT_UNIT = "paper-unit"
DEFAULT_INPUT_RATE_DPH = 10.0

_PROFILE = "Profile"
_RUN = "Run"


def _numbers(value: str | None, example: str = "-20,-10,0,10",
             what: str = "temperatures") -> list[float] | None:
    if value is None:
        return None
    try:
        return [float(item) for item in value.split(",") if item.strip()]
    except ValueError:
        raise typer.BadParameter(
            f"{value!r} is not a comma-separated list of {what}, e.g. {example}"
        ) from None


@app.command("simulate")
def simulate_command(
    profile: Annotated[
        str,
        typer.Option(
            "--profile",
            metavar="|".join(PROFILE_KINDS) + "|FILE.yaml",
            help="Chamber program: soak (one run per set-point), cooldown, warmup, constant, "
            "ramp, ratetable (plateaus from --setpoints, each soaked --hours then the "
            "--rates held --rate-hold-s each, axis after axis), or a JSON/YAML profile file "
            "(list of {setpoint_c, hold_h | ramp_c_per_min[, table_rate_dps, axis]} segments).",
            rich_help_panel=_PROFILE,
        ),
    ] = "soak",
    setpoints: Annotated[
        str | None,
        typer.Option(
            "--setpoints",
            metavar="T1,T2,...",
            help="Soak set-points [°C]; default -20,-10,0,10,20,30,40 (Table 1 of the paper); "
            "rate-table plateaus, default -10,10,30,50. "
            "Write --setpoints=-20,... when the list starts with a minus sign.",
            rich_help_panel=_PROFILE,
        ),
    ] = None,
    hours: Annotated[
        float | None,
        typer.Option(
            help="Hours per soak, or of the cool-down/warm-up/constant run (default 5); "
            "hold after a ramp (default 0); soak at each rate-table plateau (default 3).",
            rich_help_panel=_PROFILE,
        ),
    ] = None,
    start: Annotated[
        float | None,
        typer.Option(
            help="Start temperature of cooldown (20), warmup (-20) or ramp [°C].",
            rich_help_panel=_PROFILE,
        ),
    ] = None,
    end: Annotated[
        float | None,
        typer.Option(
            help="End temperature of cooldown (-20), warmup (20) or ramp [°C].",
            rich_help_panel=_PROFILE,
        ),
    ] = None,
    temperature: Annotated[
        float | None,
        typer.Option(help="Temperature of a constant run [°C] (20).", rich_help_panel=_PROFILE),
    ] = None,
    ramp_rate: Annotated[
        float | None,
        typer.Option(
            "--ramp-rate",
            help="Chamber ramp rate of cooldown, warmup or ramp [°C/min] (1).",
            rich_help_panel=_PROFILE,
        ),
    ] = None,
    rates: Annotated[
        str | None,
        typer.Option(
            "--rates",
            metavar="W1,W2,...",
            help="Rate-table rates [°/s]; default 0,10,-10,50,-50,100,-100,300,-300.",
            rich_help_panel=_PROFILE,
        ),
    ] = None,
    rate_hold_s: Annotated[
        float | None,
        typer.Option(
            "--rate-hold-s",
            help="Rate table: seconds each rate is held (60).",
            rich_help_panel=_PROFILE,
        ),
    ] = None,
    single_file: Annotated[
        bool,
        typer.Option(
            "--single-file",
            help="Soaks: one file visiting all set-points in sequence.",
            rich_help_panel=_PROFILE,
        ),
    ] = False,
    unit: Annotated[
        str,
        typer.Option(
            help=f"Simulated gyro: {', '.join(UNIT_NAMES)}.", rich_help_panel=_RUN
        ),
    ] = DEFAULT_UNIT,
    sample_rate_hz: Annotated[
        float, typer.Option("--sample-rate-hz", "--rate-hz", help="Sample rate [Hz].",
                            rich_help_panel=_RUN)
    ] = 200.0,
    seed: Annotated[
        int, typer.Option(min=0, help="Random seed; the same seed gives the same files.",
                          rich_help_panel=_RUN)
    ] = 0,
    input_rate_dph: Annotated[
        float | None,
        typer.Option(
            "--input-rate-dph",
            help=f"Known constant rate on the sensitive axis (e.g. Earth rate) [°/h]; "
            f"default {DEFAULT_INPUT_RATE_DPH:g}, or each axis's Earth-rate component for a "
            "multi-axis unit (a value given applies to every axis).",
            rich_help_panel=_RUN,
        ),
    ] = None,
    output: Annotated[
        Path,
        typer.Option(
            "-o",
            "--output",
            help="Output directory (created if missing; files named e.g. soak_-20C.parquet), "
            "or a file name for a single run.",
        ),
    ] = Path("."),
    file_format: Annotated[
        OutputFormat | None,
        typer.Option(
            "--format", help="Output file format (default: from the -o suffix, else parquet)."
        ),
    ] = None,
    force: ForceOption = False,
    json_output: JsonOption = False,
) -> None:
    """Simulate chamber runs of a gyro with ground truth (resonator_c, bias_dph) to files.

    A unit with a scale-factor law adds the truth scale_ppm, a rate table the known
    input_rate_dph; imu-3 writes them per axis (rate_dph_x, ...).

    One file per soak: hrgtc simulate --profile soak --setpoints=-20,-10,0,10,20,30,40
    --hours 5 -o soaks/

    A cool-down like Fig. 6 of the paper: hrgtc simulate --profile cooldown --start 20
    --end -20 --hours 5 -o runs/

    A rate table on the three-axis unit: hrgtc simulate --profile ratetable --unit imu-3
    --setpoints=-10,10,30,50 --rates 0,10,-10,100,-100 --rate-hold-s 60 -o runs/
    """
    from hrgtc.simulate import MultiAxisUnit, simulate_files, standard_profiles, units

    with library_errors():
        gyro = units.get(unit)
        runs = standard_profiles.build(
            profile,
            setpoints_c=_numbers(setpoints),
            hours=hours,
            start_c=start,
            end_c=end,
            temperature_c=temperature,
            ramp_c_per_min=ramp_rate,
            single_file=single_file,
            rates_dps=_numbers(rates, "0,10,-10,100,-100", "rates"),
            rate_hold_s=rate_hold_s,
            axes=gyro.axis_names if isinstance(gyro, MultiAxisUnit) else None,
        )
        with progress_bar("simulating") as progress:
            written = simulate_files(
                runs,
                output,
                None if file_format is None else file_format.value,
                unit=gyro,
                sample_rate_hz=sample_rate_hz,
                seed=seed,
                input_rate_dph=input_rate_dph,
                force=force,
                progress=progress,
            )
    if json_output:
        print_json([w.to_dict() for w in written])
        return
    table = Table(title=f"simulated {unit}, {sample_rate_hz:g} Hz, seed {seed}")
    for column in ("file", "rows", "profile"):
        table.add_column(column, justify="right" if column == "rows" else "left")
    for w in written:
        table.add_row(w.path, f"{w.rows:,}", w.profile)
    console.print(table)
