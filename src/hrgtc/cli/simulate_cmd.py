"""``hrgtc simulate``: simulated chamber runs (soaks, cool-down, warm-up, ...) to files."""

from __future__ import annotations

import json
import shlex
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.table import Table

from hrgtc.cli._app import app, console, library_errors, print_json, progress_bar
from hrgtc.cli.options import ForceOption, JsonOption, OutputFormat
from hrgtc.cli.params import settings_options
from hrgtc.settings.simulation import DEFAULT_SAMPLE_RATE_HZ, DEFAULT_UNIT, SimulationSettings

LOGGER_KINDS = ("continuous", "burst", "pan-cold", "fridge-3day")
LOGGER_RATE_UNITS = ("dph", "dps", "radps", "mradps")

_LOGGER = "Logger (files as a real logger writes them, with ground truth)"


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
@settings_options(SimulationSettings, "settings")
def simulate_command(
    logger: Annotated[
        str | None,
        typer.Option(
            "--logger",
            metavar="|".join(LOGGER_KINDS),
            help="Write the run as a real logger does, with ground truth beside it "
            "(FILE.truth.json, FILE.truth.csv): continuous, burst (--burst-s of every "
            "--period-s), or a preset: pan-cold (the PAN cold test: MEMS, 50 Hz bursts, ms, "
            "rad/s, raw count, hand log), fridge-3day (MEMS at 1 Hz for 3 days in a fridge, "
            "three orientations with handling, mrad/s). Options below override a preset.",
            rich_help_panel=_LOGGER,
        ),
    ] = None,
    burst_s: Annotated[
        float | None, typer.Option("--burst-s", help="Burst length [s] (5).",
                                   rich_help_panel=_LOGGER)
    ] = None,
    period_s: Annotated[
        float | None, typer.Option("--period-s", help="Burst period [s] (300).",
                                   rich_help_panel=_LOGGER)
    ] = None,
    time_unit: Annotated[
        str | None, typer.Option("--time-unit", metavar="s|ms|us|timestamp",
                                 help="Unit of the written time since power-on (s), or "
                                 "timestamp: ISO 8601 wall-clock times from --wall-start.",
                                 rich_help_panel=_LOGGER)
    ] = None,
    wall_start: Annotated[
        str | None, typer.Option("--wall-start", metavar="ISO",
                                 help="Wall-clock time of the run's start (local, e.g. "
                                 "2021-03-28T00:30:00).", rich_help_panel=_LOGGER)
    ] = None,
    tz: Annotated[
        str | None, typer.Option("--tz", metavar="ZONE",
                                 help="Time zone of the wall clock (e.g. Europe/Berlin): a "
                                 "daylight-saving change in the run is a ±1 h step.",
                                 rich_help_panel=_LOGGER)
    ] = None,
    counter_bits: Annotated[
        int | None, typer.Option("--counter-bits",
                                 help="Time as an unsigned counter of this many bits that "
                                 "wraps (32: µs wrap every 71.6 min).", rich_help_panel=_LOGGER)
    ] = None,
    clock_start_s: Annotated[
        float | None, typer.Option("--clock-start-s",
                                   help="Clock reading at the first sample [s] (0); near "
                                   "2^32 µs to see a wrap early.", rich_help_panel=_LOGGER)
    ] = None,
    jitter_ms: Annotated[
        float | None, typer.Option("--jitter-ms", help="Rms time-stamp jitter [ms] (0).",
                                   rich_help_panel=_LOGGER)
    ] = None,
    restarts: Annotated[
        str | None, typer.Option("--restarts", metavar="T1,T2,...",
                                 help="Power cycles at these times [s]: the clock, the bursts "
                                 "and the warm-up start again.", rich_help_panel=_LOGGER)
    ] = None,
    run_offset_dph: Annotated[
        float | None, typer.Option("--run-offset-dph",
                                   help="Rms of a turn-on offset drawn per run [°/h] (0).",
                                   rich_help_panel=_LOGGER)
    ] = None,
    warmup_dph: Annotated[
        float | None, typer.Option("--warmup-dph",
                                   help="A warm-up transient after each power-on: this offset "
                                   "[°/h] decaying with --warmup-tau-s (0).",
                                   rich_help_panel=_LOGGER)
    ] = None,
    warmup_tau_s: Annotated[
        float | None, typer.Option("--warmup-tau-s", help="Time constant of the warm-up [s] "
                                   "(120).", rich_help_panel=_LOGGER)
    ] = None,
    rate_unit: Annotated[
        str | None, typer.Option("--rate-unit", metavar="|".join(LOGGER_RATE_UNITS),
                                 help="Unit of the written rates (dph).", rich_help_panel=_LOGGER)
    ] = None,
    rate_digits: Annotated[
        int | None, typer.Option("--rate-digits",
                                 help="Significant digits of the written rates (all).",
                                 rich_help_panel=_LOGGER)
    ] = None,
    temp_lsb: Annotated[
        float | None, typer.Option("--temp-lsb",
                                   help="Log the sensor temperature as a raw count of this "
                                   "size [°C] (T = count * LSB + --temp-offset); with no "
                                   "--temp-lsb and a MEMS unit, in °C.", rich_help_panel=_LOGGER)
    ] = None,
    temp_offset: Annotated[
        float | None, typer.Option("--temp-offset", help="°C of count 0 (0).",
                                   rich_help_panel=_LOGGER)
    ] = None,
    temp_bits: Annotated[
        int | None, typer.Option("--temp-bits",
                                 help="The signed count stored unsigned in this many bits "
                                 "(16: -300 is written 65236).", rich_help_panel=_LOGGER)
    ] = None,
    temp_rate_hz: Annotated[
        float | None, typer.Option("--temp-rate-hz",
                                   help="A slower temperature channel: a new value at this "
                                   "rate, empty cells between [Hz].", rich_help_panel=_LOGGER)
    ] = None,
    reference_log: Annotated[
        bool | None, typer.Option("--reference-log/--no-reference-log",
                                  help="Write a hand-written reference log FILE_reflog.csv "
                                  "(HH:MM clock times, °F and °C columns, blank cells, BOM).",
                                  rich_help_panel=_LOGGER)
    ] = None,
    reference_lag_s: Annotated[
        float | None, typer.Option("--reference-lag-s",
                                   help="Lag of the reference probe behind the sensor [s].",
                                   rich_help_panel=_LOGGER)
    ] = None,
    duplicates: Annotated[
        int | None, typer.Option("--duplicates", help="Rows written twice (a logger "
                                 "re-sending a line) (0).", rich_help_panel=_LOGGER)
    ] = None,
    spikes: Annotated[
        int | None, typer.Option("--spikes", help="Single-sample spikes to inject (0).",
                                 rich_help_panel=_LOGGER)
    ] = None,
    spike_dph: Annotated[
        float | None, typer.Option("--spike-dph",
                                   help="Size of each spike [°/h] (default: -50 σ).",
                                   rich_help_panel=_LOGGER)
    ] = None,
    orientations: Annotated[
        int | None, typer.Option("--orientations",
                                 help="Orientations visited, with handling between them (1).",
                                 rich_help_panel=_LOGGER)
    ] = None,
    handling_max_dps: Annotated[
        float | None, typer.Option("--handling-max-dps",
                                   help="Peak rotation rate of the handling [°/s] (300).",
                                   rich_help_panel=_LOGGER)
    ] = None,
    hand_warming_c: Annotated[
        float | None, typer.Option("--hand-warming-c",
                                   help="The hands warm the sensor by this much during each "
                                   "handling [°C] (0), cooling back over 10 min.",
                                   rich_help_panel=_LOGGER)
    ] = None,
    accelerometer: Annotated[
        bool | None, typer.Option("--accelerometer/--no-accelerometer",
                                  help="Write accelerometer columns (in g).",
                                  rich_help_panel=_LOGGER)
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
            "--format", help="Output file format (default: from the -o suffix, else parquet; "
            "csv with --logger)."
        ),
    ] = None,
    force: ForceOption = False,
    json_output: JsonOption = False,
    settings: SimulationSettings | None = None,
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

    As a burst logger writes it, truth beside (cold.truth.json, cold.truth.csv):
    hrgtc simulate --logger burst --unit mems-3 --profile cooldown --start 22 --end 5
    --hours 2 --rate-hz 50 --burst-s 5 --period-s 300 --time-unit ms --rate-unit radps -o cold.csv

    The PAN cold test of tests/data/pan-cold-test, with its hand log:
    hrgtc simulate --logger pan-cold -o pan.csv
    """
    from hrgtc.simulate import MultiAxisUnit, simulate_files, standard_profiles, units

    settings = settings or SimulationSettings()
    seed, input_rate_dph = settings.seed, settings.input_rate_dph
    sample_rate_hz = settings.sample_rate_hz
    with library_errors():
        chosen = None
        if logger is not None and logger not in ("continuous", "burst"):
            from hrgtc.simulate.logger_presets import preset

            chosen = preset(logger)
        unit = settings.unit or (chosen.unit if chosen is not None else DEFAULT_UNIT)
        gyro = units.get(unit)
        if chosen is not None and settings.profile is None:
            runs = [chosen.profile]
        else:
            runs = standard_profiles.build(
                settings.profile or "soak", **settings.profile_options(),
                axes=gyro.axis_names if isinstance(gyro, MultiAxisUnit) else None)
        if logger is not None:
            from hrgtc.simulate.logged_files import simulate_logged_files

            spec = _logger_spec(
                chosen.logger if chosen is not None else None, logger, unit,
                sample_rate_hz=sample_rate_hz, burst_s=burst_s, period_s=period_s,
                time_unit=time_unit, start=wall_start, timezone=tz, counter_bits=counter_bits,
                clock_start_s=clock_start_s,
                jitter_s=None if jitter_ms is None else jitter_ms * 1e-3,
                restarts_s=None if restarts is None else tuple(
                    _numbers(restarts, "3600,7200", "times") or ()),
                run_offset_dph=run_offset_dph, warmup_dph=warmup_dph,
                warmup_tau_s=warmup_tau_s, rate_unit=rate_unit, rate_digits=rate_digits,
                duplicates=duplicates, spikes=spikes, spike_dph=spike_dph,
                accelerometer=accelerometer,
                temp_lsb=temp_lsb, temp_offset=temp_offset, temp_bits=temp_bits,
                temp_rate_hz=temp_rate_hz, reference_log=reference_log,
                reference_lag_s=reference_lag_s, orientations=orientations,
                handling_max_dps=handling_max_dps, hand_warming_c=hand_warming_c,
            )
            logged = simulate_logged_files(
                runs, output, spec, unit=gyro, seed=seed,
                file_format=None if file_format is None else file_format.value,
                input_rate_dph=input_rate_dph, force=force,
            )
            if json_output:
                print_json([w.to_dict() for w in logged])
                return
            table = Table(title=f"simulated {unit} through a {logger} logger, "
                          f"{spec.sample_rate_hz:g} Hz, seed {seed}")
            for column in ("file", "rows", "truth"):
                table.add_column(column, justify="right" if column == "rows" else "left")
            for w in logged:
                truth = w.truth_json + (f", {w.reference_log}" if w.reference_log else "")
                table.add_row(w.path, f"{w.rows:,}", truth)
            console.print(table)
            first = json.loads(Path(logged[0].truth_json).read_text())["hrgtc_options"]
            console.print("read it with: hrgtc info " + shlex.quote(logged[0].path) + " "
                          + " ".join(shlex.quote(o) for o in first), markup=False,
                          highlight=False, soft_wrap=True)
            return
        sample_rate_hz = DEFAULT_SAMPLE_RATE_HZ if sample_rate_hz is None else sample_rate_hz
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


def _logger_spec(base: Any, kind: str, unit: str, **given: Any) -> Any:
    """The Logger of ``--logger``: a preset's, or a plain one, with the options given."""
    from dataclasses import replace

    from hrgtc.simulate.handling import Handling
    from hrgtc.simulate.logger import Logger
    from hrgtc.simulate.mems import G_SENSITIVITY_DPH_PER_G, MEMS_UNIT
    from hrgtc.simulate.reflog import ReferenceLog, TemperatureChannel

    mems = unit == MEMS_UNIT
    if base is None:
        base = Logger(kind=kind, sample_rate_hz=DEFAULT_SAMPLE_RATE_HZ, frequency=not mems,
                      temperature=TemperatureChannel(decimals=2) if mems else None)
    temperature = {"lsb_c": given.pop("temp_lsb"), "offset_c": given.pop("temp_offset"),
                   "bits": given.pop("temp_bits"), "rate_hz": given.pop("temp_rate_hz")}
    temperature = {k: v for k, v in temperature.items() if v is not None}
    if temperature:
        # An HRG's temperature sensor sits on the housing; a MEMS die has its own.
        channel = base.temperature or TemperatureChannel(source="die" if mems else "housing")
        base = replace(base, temperature=replace(channel, **temperature))
    reference, lag = given.pop("reference_log"), given.pop("reference_lag_s")
    if reference is False:
        base = replace(base, reference_log=None)
    elif reference or lag is not None:
        log = base.reference_log or ReferenceLog()
        base = replace(base, reference_log=log if lag is None else replace(log, lag_s=lag))
    handling = {"orientations": given.pop("orientations"),
                "max_rate_dps": given.pop("handling_max_dps"),
                "hand_warming_c": given.pop("hand_warming_c")}
    handling = {k: v for k, v in handling.items() if v is not None}
    if handling:
        start = base.handling or Handling(
            orientations=1, g_sensitivity_dph_per_g=G_SENSITIVITY_DPH_PER_G if mems else {})
        base = replace(base, handling=replace(start, **handling))
    return replace(base, **{k: v for k, v in given.items() if v is not None})
