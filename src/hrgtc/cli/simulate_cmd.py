"""``hrgtc simulate``: simulated chamber runs (soaks, cool-down, warm-up, ...) to files."""

from __future__ import annotations

import json
import shlex
from pathlib import Path
from typing import Annotated

import typer

from hrgtc.cli._app import console, library_errors, print_json, progress_bar
from hrgtc.cli.options import ForceOption, JsonOption, OutputFormat, output_format_callback
from hrgtc.cli.params import settings_options
from hrgtc.settings.simulation import (
    DEFAULT_SAMPLE_RATE_HZ,
    DEFAULT_UNIT,
    PRESET_CHANGES,
    LoggerSettings,
    SimulationSettings,
)


@settings_options(LoggerSettings, "logger_settings")
@settings_options(SimulationSettings, "settings")
def simulate_command(
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
        str | None,
        typer.Option(
            "--format", metavar="[" + "|".join(OutputFormat) + "]",
            callback=output_format_callback,
            help="Output file format (default: from the -o suffix, else parquet; "
            "csv with --logger). ulog and dataflash have no writer."
        ),
    ] = None,
    force: ForceOption = False,
    json_output: JsonOption = False,
    settings: SimulationSettings | None = None,
    logger_settings: LoggerSettings | None = None,
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
    logger_settings = logger_settings or LoggerSettings()
    logger = logger_settings.logger
    seed, input_rate_dph = settings.seed, settings.input_rate_dph
    sample_rate_hz = settings.sample_rate_hz
    with library_errors():
        chosen = None
        if logger in PRESET_CHANGES:
            from hrgtc.simulate.logger_presets import preset

            chosen = preset(logger)
        unit = settings.unit or (chosen.unit if chosen is not None else DEFAULT_UNIT)
        gyro = units.get(unit)
        if chosen is not None and settings.profile is None:
            _no_profile_options_without_profile(logger, settings)
            runs = [chosen.profile]
        else:
            runs = standard_profiles.build(
                settings.profile or "soak", **settings.profile_options(),
                axes=gyro.axis_names if isinstance(gyro, MultiAxisUnit) else None)
        if logger is not None:
            from hrgtc.simulate.logged_files import simulate_logged_files
            from hrgtc.simulate.logger_presets import plain_logger, with_options

            base = chosen.logger if chosen is not None else plain_logger(logger, unit)
            spec = with_options(base, unit, {**logger_settings.given(),
                                             "sample_rate_hz": sample_rate_hz})
            logged = simulate_logged_files(
                runs, output, spec, unit=gyro, seed=seed,
                file_format=file_format,
                input_rate_dph=input_rate_dph, force=force,
            )
            if json_output:
                print_json([w.to_dict() for w in logged])
                return
            from hrgtc.cli.summary_tables import print_summary
            from hrgtc.simulate.logged_files import logged_summary

            print_summary(logged_summary(logged, unit, logger, spec.sample_rate_hz, seed),
                          console)
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
                file_format,
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
    from hrgtc.cli.summary_tables import print_summary
    from hrgtc.simulate.output import written_summary

    print_summary(written_summary(written, unit, sample_rate_hz, seed), console)



def _no_profile_options_without_profile(logger: str, settings: SimulationSettings) -> None:
    """Refuse profile options a preset's own chamber program would silently ignore."""
    from hrgtc.core.errors import InputError

    flags = {"setpoints_c": "--setpoints", "hours": "--hours", "start_c": "--start",
             "end_c": "--end", "temperature_c": "--temperature",
             "ramp_c_per_min": "--ramp-rate", "rates_dps": "--rates",
             "rate_hold_s": "--rate-hold-s", "single_file": "--single-file"}
    options = settings.profile_options()
    given = [flag for name, flag in flags.items() if options.get(name) not in (None, False)]
    if given:
        raise InputError(
            f"--logger {logger} runs its own chamber program, which {', '.join(given)} "
            f"would not change; pass --profile (e.g. --profile cooldown or --profile "
            f"constant) to replace the program, or leave {', '.join(given)} out")
