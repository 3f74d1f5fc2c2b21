"""The mark of a compensated recording, so that no run is compensated twice.

``hrgtc compensate`` writes its output with ``extra["compensated_by"]`` in the
metadata (Parquet schema metadata, CSV header, HDF5 attributes)::

    {"model_sha256": "...", "model_unit": "SN 12", "hrgtc_version": "0.1.0",
     "drift": "frequency"}

and with the columns ``rate_comp_dph`` and ``bias_model_dph`` beside the raw
``rate_dph``. ``drift`` says what drove the model: ``"frequency"``, ``"sensor
temperature"`` (a model of the gyro's temperature sensor) or ``"housing"``.
:func:`compensation_mark` finds either: the metadata survive a renaming of the
columns (``--col rate_dph=rate_comp_dph``), the column names
survive a tool that drops the metadata (e.g. a spreadsheet's CSV export). A file
stripped of both cannot be told from a raw run.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

from hrgtc.core.errors import RecordingError

#: Metadata key of the mark.
COMPENSATED_KEY = "compensated_by"
#: Columns only a compensated output has.
COMPENSATED_COLUMNS = ("rate_comp_dph", "bias_model_dph")


def mark(model_sha256: str, model_unit: str, drift: str = "frequency") -> dict[str, Any]:
    """The ``compensated_by`` record of an output compensated by one model."""
    from hrgtc.core.meta import __version__

    return {"model_sha256": model_sha256, "model_unit": model_unit,
            "hrgtc_version": __version__, "drift": drift}


def compensation_mark(metadata: Mapping[str, Any],
                      names: list[str] | tuple[str, ...]) -> dict[str, Any] | None:
    """The mark found in a file's raw metadata or column names, None if there is none."""
    extra = metadata.get("extra") if isinstance(metadata.get("extra"), Mapping) else {}
    found = extra.get(COMPENSATED_KEY, metadata.get(COMPENSATED_KEY))
    if found is not None:
        return dict(found) if isinstance(found, Mapping) else {"model_sha256": str(found)}
    columns = [c for c in COMPENSATED_COLUMNS if c in names]
    if columns:
        return {"columns": columns}
    return None


def describe_mark(found: Mapping[str, Any]) -> str:
    """The model named by a mark, e.g. ``model 3f2a9c01b7e4 (unit SN 12, hrgtc 0.1.0)``."""
    if "columns" in found and "model_sha256" not in found:
        return f"an unknown model (it has the columns {', '.join(found['columns'])})"
    sha = str(found.get("model_sha256", "?"))[:12]
    unit = found.get("model_unit", "?")
    version = found.get("hrgtc_version", "?")
    return f"model {sha} (unit {unit}, hrgtc {version})"


#: What compensating twice would do, by what the file was given for.
_CONSEQUENCE = {
    False: "compensating or evaluating it again would subtract the drift twice: use the "
           "original recording",
    True: "a model trained on it would fit what that compensation left, not the gyro's "
          "drift: calibrate on the original (raw) recording",
}


def refuse_compensated(path: str | Path, training: bool = False) -> None:
    """Raise RecordingError if the file at ``path`` is the output of a compensation.

    Opens the file for its metadata and column names only. ``training``: the file was
    given to train a model (the message says what that would fit); else to be
    compensated or evaluated.
    """
    from hrgtc.recording.io import open_source

    with open_source(path) as source:
        found = compensation_mark(source.metadata, list(source.names))
    if found is not None:
        raise RecordingError(f"{path} is already compensated, by {describe_mark(found)}; "
                             f"{_CONSEQUENCE[training]}")


def refuse_compensated_training(paths: Iterable[str | Path | None]) -> None:
    """Raise RecordingError if a file given to train a model is a compensated output
    (:func:`refuse_compensated` of each, ``training=True``).

    A model trained on a compensated run fits what the first model left (its rate
    column may even be ``rate_comp_dph`` under another name), not the gyro's drift;
    the thermometer of its soaks would be the same as the raw run's, so nothing
    later would show it. A file given twice (a soak that is also a drift run) is opened
    once; call it once per command (:func:`hrgtc.pipeline.calibration.calibrate` does, for
    every axis).
    """
    seen = set()
    for path in paths:
        if path is None or not Path(path).is_file():
            continue  # a missing file is named by the reading that follows
        key = Path(path).resolve()
        if key not in seen:
            seen.add(key)
            refuse_compensated(path, training=True)
