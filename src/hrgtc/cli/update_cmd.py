"""``hrgtc update``: a model updated from the still periods of a field recording, or rolled
back to its parent (``--rollback``)."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import TYPE_CHECKING

import typer

from hrgtc.cli._app import console, fail, library_errors, print_json
from hrgtc.cli.options import ForceOption, JsonOption, reading_options
from hrgtc.cli.params import settings_options
from hrgtc.cli.summary_tables import print_summary
from hrgtc.settings.update import UpdateSettings

if TYPE_CHECKING:
    from hrgtc.recording import ReadOptions


def parse_still(values: list[str] | None) -> list[tuple[float, float]]:
    """``--still START:END`` values as ``(start, end)`` pairs. [s]"""
    out = []
    for value in values or ():
        start, sep, end = value.partition(":")
        try:
            if not sep:
                raise ValueError(value)
            out.append((float(start), float(end)))
        except ValueError:
            raise fail(f"--still {value!r} is not START:END in seconds (e.g. --still "
                       "600:4200)") from None
    return out


@reading_options
@settings_options(UpdateSettings)
def update_command(
    model: Path = typer.Argument(..., help="Model file (hrgtc calibrate, or an earlier "
                                           "update); with --rollback, the updated file."),
    recordings: list[Path] = typer.Argument(
        None, metavar="[RECORDINGS]...", help="Field recordings of the same unit, with "
        "still periods."),
    output: Path = typer.Option(..., "-o", "--output", help="Model file to write (JSON); "
                                "never the input."),
    still: list[str] = typer.Option(
        None, "--still", metavar="START:END", help="A still interval in the recording's "
        "time [s], instead of the motion detector's still periods (repeat for more)."),
    rollback: bool = typer.Option(
        False, "--rollback", help="Write the parent of MODEL (an updated file), byte for "
        "byte, to --output."),
    force: ForceOption = False,
    json_output: JsonOption = False,
    inputs: ReadOptions | None = None,
    settings: UpdateSettings | None = None,
) -> None:
    """Update a model from the still periods of a field recording: a Kalman filter on the
    drift model's offset (with a known --input-rate-dph; a three-axis model's offsets
    without it, from the Earth rate's magnitude and still periods in several orientations)
    and slope (over --min-span-c), refused with its reason for another unit's file, a jump,
    a ramp, a step too far or no gain on held-out still blocks. The new file records its
    lineage.

    Example: hrgtc update unit.json field.parquet --input-rate-dph 9.67 -o unit-2.json

    Back to the parent: hrgtc update --rollback unit-2.json -o unit-restored.json
    """
    from hrgtc.core.files import refuse_existing, refuse_input, write_bytes_atomic
    from hrgtc.model import load_model, save_model
    from hrgtc.update import rollback_bytes

    with library_errors():
        refuse_input(output, [model, *(recordings or [])])
        refuse_existing(output, force)
        if rollback:
            if recordings:
                raise fail("--rollback takes the updated model file only, no recording")
            child = load_model(model)
            if child.lineage is None:
                raise fail(f"{model}: not an updated model (no lineage): nothing to roll "
                           "back to")
            write_bytes_atomic(output, rollback_bytes(child.lineage, str(model)), force)
            if json_output:
                print_json({"rollback": str(model), "output": str(output),
                            "parent_sha256": child.lineage.parent_sha256})
            else:
                console.print(f"wrote {output} (the parent {child.lineage.parent_path}, "
                              f"SHA-256 {child.lineage.parent_sha256})", soft_wrap=True)
            return
        if not recordings:
            raise fail("no recording given: hrgtc update MODEL RECORDING -o NEW_MODEL")
        known = ((inputs.metadata or {}).get("input_rate_dph") if inputs is not None else None)
        settings = dataclasses.replace(settings or UpdateSettings(), input_rate_dph=known)
        parent = load_model(model)
        result = parent.update(recordings, settings, still_s=parse_still(still) or None,
                               parent=model, read_options=inputs)
        if result.applied:
            save_model(result.model, output, force)
    if json_output:
        print_json({"applied": result.applied, "output": str(output) if result.applied
                    else None, "summary": result.summary().to_dict()})
        return
    print_summary(result.summary(), console)
    console.print(f"wrote {output}" if result.applied else f"{output} not written",
                  soft_wrap=True)
