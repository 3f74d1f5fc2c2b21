"""Firmware export: the unit's compensation as a dependency-free C99 header and source.

The generated code runs, sample by sample, exactly the computation of
:class:`hrgtc.compensate.Compensator`: f = freq_hz - f_ref, the causal df/dt
filter of :func:`hrgtc.drift.features.causal_rate` (started at rest on the first
sample, each step exact over the sample's own Δt: ``step()`` takes ``dt_s``, the time
since the previous sample, so jittered clocks and bursts are handled and a gap is
bridged by passing its length; ``reset()`` restarts the filter), the selected
terms of the drift model on scaled variables (Eq. 22 of
[1]), the compensated rate, the resonator temperature by inverting the
thermometer (Eq. 18 of [1], a safeguarded Newton iteration on a bracket taken
from a small embedded table, as in Table 2) and the in-range flags (``in_range``:
calibrated frequency range and training ranges of f and h; ``rate_in_range``:
training ranges of df/dt and dh/dt, with their own counters). Every constant is
printed with ``%.17g`` so it reads back to the same double; the code only
needs ``math.h`` (``pow``, ``fabs``, ``expm1``, ``NAN``), allocates nothing and does no I/O.

Housing-thermistor variables (``h``, ``dh``) are supported: when the selected
terms use them, ``step()`` takes ``housing_c`` as well and the header defines
``<PREFIX>_USES_HOUSING`` as 1. Only the frequency drift model (the paper's) is
exported, not the classical housing baseline.

The variables of issue 12 are supported too: ``d2`` (a second df/dt filter with its own
state ``f2_filter`` and time constant), ``g`` (``housing_c`` minus the C thermometer
inverse's temperature; ``step()`` then takes ``housing_c``) and ``a_NAME`` (one more
``step()`` input ``aux_NAME`` per channel, centred on its training mean;
``<PREFIX>_AUX_INPUTS`` counts them). The heating/cooling switch ``dpos`` is refused.

With ``-ffp-contract=off`` (GCC's default under ``-std=c99``) the filter, the
thermometer polynomial and the terms round exactly as NumPy does; what remains
(the order of the final sum, the Newton iteration's last step) is at the
rounding level: about 1e-14 °/h and 3e-12 °C. The C text is printed by
:mod:`hrgtc.export.c.text` (the header) and :mod:`hrgtc.export.c.source` (the ``.c``
file: one body, in double or in float).

``precision="single"`` writes the float32 build for FPU-only microcontrollers
(centred frequency input; :mod:`hrgtc.export.c.single` writes its header's own sections),
whose worst error against the double model is measured at export by its numpy float32 mirror
(:mod:`hrgtc.export.c.float32`) and stated in the header. ``output_format="params"``
writes the plain parameter file of :mod:`hrgtc.export.parameter_file` instead.

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import hashlib
import json
import os
import re
from pathlib import Path

from hrgtc.core.errors import InputError
from hrgtc.core.files import file_sha256, refuse_existing, refuse_input, write_text_atomic
from hrgtc.export.c import single as c_single
from hrgtc.export.c.float32 import float_accuracy, float_constants
from hrgtc.export.c.plan import PRECISIONS, plan_for
from hrgtc.export.c.source import source
from hrgtc.export.c.text import _comment, header, title
from hrgtc.export.parameter_file import instrument_parameter_text, parameter_text
from hrgtc.model import Model, load_model
from hrgtc.settings.export import EXPORT_FORMATS, ExportSettings

#: What the export writes: C99 files, or the plain parameter file.
FORMATS = EXPORT_FORMATS
_EXPORT = ExportSettings
_PREFIX = re.compile(r"^[A-Za-z][A-Za-z0-9_]{0,31}$")


# -- public API ---------------------------------------------------------------------------
def export_c(
    model: Model | str | os.PathLike[str],
    outdir: str | os.PathLike[str],
    prefix: str = _EXPORT.prefix,
    force: bool = False,
    precision: str = _EXPORT.precision,
    output_format: str = _EXPORT.output_format,
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
        The unit's or instrument's model (:class:`~hrgtc.model.Model`, one or several
        axes), or the path of its model file (then the header
        records the file's SHA-256; for an in-memory model, the SHA-256 of the
        JSON document :func:`hrgtc.model.save_model` would write).
    outdir
        Folder for the two files (created when missing).
    prefix
        C identifier prefix of every exported name (``<prefix>_step``, ...).
    force
        Overwrite existing files.
    precision
        ``"double"`` (default): C double throughout. ``"single"``: float32 for FPU-only
        microcontrollers, with the frequency entering centred (``f_hz = freq_hz -
        <PREFIX>_CENTRE_HZ``) and the worst error against the double model over the
        calibrated range, measured at export (:mod:`hrgtc.export.c.float32`), stated
        in the header and as ``<PREFIX>_MAX_ERROR_C`` / ``<PREFIX>_MAX_ERROR_DPH``.
    output_format
        ``"c"`` (default): the header and source. ``"params"``: one plain parameter file
        ``<prefix>_params.txt`` of ``key = value`` lines, every number documented
        (:mod:`hrgtc.export.parameter_file`); ``precision`` does not apply (``"single"``
        is refused).

    Returns
    -------
    list of pathlib.Path
        The header and the source written (the parameter file for ``output_format="params"``).
        For an instrument with named axes: ``<prefix>_model.h``, which includes every
        axis's ``<prefix>_<axis>_model.h``, then each axis's header and source (every
        name of axis a prefixed ``<prefix>_<a>``); its parameter file prefixes every key
        with ``<axis>_``.

    Raises
    ------
    InputError
        A prefix that is not a C identifier, an unknown precision, ``"single"`` with the
        parameter file, or non-finite model constants.
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
    if output_format not in FORMATS:
        raise InputError(f"format {output_format!r} is not one of {', '.join(FORMATS)}; use 'c' "
                         "(header and source) or 'params' (a key = value parameter file)")
    if precision not in PRECISIONS:
        raise InputError(f"precision {precision!r} is not one of {', '.join(PRECISIONS)}; "
                         "use 'double' (the default) or 'single' (float32 for FPU-only MCUs)")
    if output_format == "params" and precision != "double":
        raise InputError("--precision applies to --format c only; the parameter file holds "
                         "doubles (%.17g): leave --precision at double")
    axes, origin, sha256 = _axes_of(model)
    folder = Path(outdir)
    if folder.exists() and not folder.is_dir():
        raise InputError(f"output folder {folder} is a file; give a folder for the C files")
    single_axis = list(axes) == [""]
    for name in axes:
        if name and not _PREFIX.match(f"{prefix}_{name}"):
            raise InputError(f"prefix {prefix!r} with axis {name!r} gives {prefix}_{name}, "
                             "longer than 32 characters; use a shorter --prefix")
    if output_format == "params":
        target = folder / f"{prefix}_params.txt"
        refuse_input(target, [model] if isinstance(model, str | os.PathLike) else [])
        refuse_existing((target,), force)
        plans = {name: plan_for(unit) for name, unit in axes.items()}
        text = (parameter_text(axes[""], plans[""], origin, sha256) if single_axis else
                instrument_parameter_text(axes, plans, origin, sha256))
        return [write_text_atomic(target, text, force=force)]
    files: dict[Path, str] = {}
    if single_axis:
        files[folder / f"{prefix}_model.h"] = ""
        files[folder / f"{prefix}_model.c"] = ""
    else:
        files[folder / f"{prefix}_model.h"] = ""
        for name in axes:
            files[folder / f"{prefix}_{name}_model.h"] = ""
            files[folder / f"{prefix}_{name}_model.c"] = ""
    refuse_input(tuple(files), [model] if isinstance(model, str | os.PathLike) else [])
    refuse_existing(tuple(files), force)
    if single_axis:
        texts = _c_texts(axes[""], prefix, origin, sha256, precision)
    else:
        texts = (umbrella_header(axes, prefix, origin, sha256, precision),)
        for name, unit in axes.items():
            texts += _c_texts(unit, f"{prefix}_{name}", f"{origin}, axis {name}", sha256,
                              precision)
    return [write_text_atomic(path, text, force=force)
            for path, text in zip(files, texts, strict=True)]


def _axes_of(model: Model | str | os.PathLike[str]) -> tuple[dict[str, Model], str, str]:
    """Axis name -> its one-axis model ('' for a single gyro), the model's origin and
    SHA-256."""
    if isinstance(model, str | os.PathLike):
        path = Path(model)
        loaded = load_model(path)
        origin, sha256 = path.name, file_sha256(path)
    else:
        document = json.dumps(model.to_dict(), indent=2, allow_nan=True) + "\n"
        sha256 = hashlib.sha256(document.encode("utf-8")).hexdigest()
        origin = "in memory (SHA-256 of its JSON document as hrgtc writes it)"
        loaded = model
    return {axis: loaded.of_axis(axis) for axis in loaded.axes}, origin, sha256


def _c_texts(model: Model, prefix: str, origin: str, sha256: str,
             precision: str) -> tuple[str, str]:
    """Header and source of one gyro (one axis)."""
    plan = plan_for(model, precision)
    if precision == "single":
        constants = float_constants(model, plan)
        accuracy = float_accuracy(model, plan, constants)
        return (c_single.header(model, plan, prefix, origin, sha256, constants, accuracy),
                source(model, plan, prefix, constants))
    return header(model, plan, prefix, origin, sha256), source(model, plan, prefix)


def umbrella_header(axes: dict[str, Model], prefix: str, origin: str, sha256: str,
                    precision: str) -> str:
    """``<prefix>_model.h`` of an instrument: includes every axis's header."""
    up = prefix.upper()
    names = list(axes)
    first = f"{prefix}_{names[0]}"
    includes = "".join(f'#include "{prefix}_{name}_model.h"\n' for name in names)
    argument = f"{first.upper()}_CENTRED_HZ(freq_hz)" if precision == "single" else "freq_hz"
    what = ("HRG compensation" if axes[names[0]].thermometer.source != "sensor"
            else title(axes[names[0]]))
    return f"""/*
 * {prefix}_model.h -- {what} of every axis of instrument {_comment(origin)}
 *
 * Generated by hrgtc (hrgtc export-c); do not edit, regenerate from the model file.
 * One axis, one prefix: axis <a> is compensated by {prefix}_<a>_step() with its own state,
 * constants and files {prefix}_<a>_model.h / .c (each documented there: its model, units,
 * {'float32 accuracy, ' if precision == 'single' else ''}use); this header includes them all.
 * Axes: {", ".join(names)}.
 *
 * USAGE
 *   #include "{prefix}_model.h"
 *   static {first}_state gyro_{names[0]};
 *   {first}_init(&gyro_{names[0]});
 *   rate = {first}_step(&gyro_{names[0]}, dt_s, {argument}, rate_dph, ..., &out);  // each sample
 *   (dt_s: seconds since the previous sample, shared by the axes sampled together)
 *   (and likewise for the other axes, each with its own frequency and rate)
 *   Build: cc -std=c99 -O2 -c {" ".join(f"{prefix}_{n}_model.c" for n in names)}, link -lm.
 *
 * model SHA-256: {sha256}
 */
#ifndef {up}_MODEL_H
#define {up}_MODEL_H

/* Number of axes. */
#define {up}_N_AXES {len(names)}

{includes}
#endif /* {up}_MODEL_H */
"""
