"""Firmware export: the unit's compensation as a dependency-free C99 header and source.

The generated code runs, sample by sample, exactly the computation of
:class:`hrgtc.compensate.Compensator`: f = freq_hz - f_ref, the causal df/dt
filter of :func:`hrgtc.drift.features.causal_rate` (started at rest on the first
sample), the selected terms of the drift model on scaled variables (Eq. 22 of
[1]), the compensated rate, the resonator temperature by inverting the
thermometer (Eq. 18 of [1], a safeguarded Newton iteration on a bracket taken
from a small embedded table, as in Table 2) and the in-range flags (``in_range``:
calibrated frequency range and training ranges of f and h; ``rate_in_range``:
training ranges of df/dt and dh/dt, with their own counters). Every constant is
printed with ``%.17g`` so it reads back to the same double; the code only
needs ``math.h`` (``pow``, ``fabs``, ``NAN``), allocates nothing and does no I/O.

Housing-thermistor variables (``h``, ``dh``) are supported: when the selected
terms use them, ``step()`` takes ``housing_c`` as well and the header defines
``<PREFIX>_USES_HOUSING`` as 1. Only the frequency drift model (the paper's) is
exported, not the classical housing baseline.

The variables of issue 12 are supported too: ``d2`` (a second df/dt filter with its own
state ``f2_y1``/``f2_y2`` and time constant), ``g`` (``housing_c`` minus the C thermometer
inverse's temperature; ``step()`` then takes ``housing_c``) and ``a_NAME`` (one more
``step()`` input ``aux_NAME`` per channel, centred on its training mean;
``<PREFIX>_AUX_INPUTS`` counts them). The heating/cooling switch ``dpos`` is refused.

With ``-ffp-contract=off`` (GCC's default under ``-std=c99``) the filter, the
thermometer polynomial and the terms round exactly as NumPy does; what remains
(the order of the final sum, the Newton iteration's last step) is at the
rounding level: about 1e-14 °/h and 3e-12 °C. The C text is printed by
:mod:`hrgtc.compensate.c_text`.

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import hashlib
import json
import os
import re
from pathlib import Path

from hrgtc.compensate.c_plan import plan_for
from hrgtc.compensate.c_text import header, source
from hrgtc.errors import InputError
from hrgtc.files import file_sha256, refuse_existing, write_text_atomic
from hrgtc.model import UnitModel, load_model

_PREFIX = re.compile(r"^[A-Za-z][A-Za-z0-9_]{0,31}$")


# -- public API ---------------------------------------------------------------------------
def export_c(
    model: UnitModel | str | os.PathLike[str],
    outdir: str | os.PathLike[str],
    prefix: str = "hrgtc",
    force: bool = False,
) -> list[Path]:
    """Write the unit's compensation as C99 files ``<prefix>_model.h`` and ``<prefix>_model.c``.

    The code implements, per sample, what :class:`hrgtc.compensate.Compensator`
    does: the causal df/dt filter, the drift model of Eq. (22) of [1], the
    compensated rate, the inverse of the thermometer of Eq. (18) (Table 2) and
    the in-range flag. Both files are written atomically; neither is written
    when either exists and ``force`` is False.

    Parameters
    ----------
    model
        The unit's model, or the path of its model file (then the header
        records the file's SHA-256; for an in-memory model, the SHA-256 of the
        JSON document :func:`hrgtc.model.save_model` would write).
    outdir
        Folder for the two files (created when missing).
    prefix
        C identifier prefix of every exported name (``<prefix>_step``, ...).
    force
        Overwrite existing files.

    Returns
    -------
    list of pathlib.Path
        The header and the source written.

    Raises
    ------
    InputError
        A prefix that is not a C identifier, or non-finite model constants.
    CalibrationError
        A thermometer that is not monotonic over its calibrated range.
    OutputExistsError
        A file exists and ``force`` is False.
    ModelFileError
        An unreadable or foreign model file.
    """
    if not isinstance(prefix, str) or not _PREFIX.match(prefix):
        raise InputError(
            f"prefix {prefix!r} is not usable as a C identifier prefix; use a letter followed by "
            "up to 31 letters, digits or underscores, e.g. 'hrgtc' or 'gyro_x'"
        )
    if isinstance(model, UnitModel):
        document = json.dumps(model.to_dict(), indent=2, allow_nan=True) + "\n"
        sha256 = hashlib.sha256(document.encode("utf-8")).hexdigest()
        origin = "in memory (SHA-256 of its JSON document as hrgtc writes it)"
    else:
        path = Path(model)
        model = load_model(path)
        sha256 = file_sha256(path)
        origin = path.name
    folder = Path(outdir)
    if folder.exists() and not folder.is_dir():
        raise InputError(f"output folder {folder} is a file; give a folder for the C files")
    header_path = folder / f"{prefix}_model.h"
    source_path = folder / f"{prefix}_model.c"
    refuse_existing((header_path, source_path), force)
    plan = plan_for(model)
    header_text = header(model, plan, prefix, origin, sha256)
    code = source(model, plan, prefix)
    return [
        write_text_atomic(header_path, header_text, force=force),
        write_text_atomic(source_path, code, force=force),
    ]
