"""C text of the end of ``step()``, shared by the double and the float32 exports.

The compensated rate, the range flags and their counts, the scale factor (when the
model has one) and the output record: the same statements in either precision.
"""

from __future__ import annotations

from collections.abc import Mapping

__all__ = ["step_tail"]


def step_tail(*, up: str, level_test: str, rate_test: str, h: Mapping[str, str],
              k: Mapping[str, str]) -> str:
    """The statements of ``step()`` from the compensated rate to ``return``.

    Parameters
    ----------
    up
        Upper-case prefix of the exported names.
    level_test, rate_test
        C expressions: the sample is inside the calibrated temperature and trained
        levels, and inside the trained rates.
    h, k
        Pieces of the housing variables (``h['out']``) and of the scale factor
        (``k['apply']``, ``k['out']``).
    """
    return f"""    compensated = rate_dph - bias;
    level_in_range = {level_test};
    rate_in_range = {rate_test};
    /* in_range: calibrated temperature, trained df/dt, and the filter settled */
    /* settled: SETTLE_S seconds since init/reset, the sum of the steps' dt_s */
    if (state->samples > 0UL && state->elapsed_s < {up}_SETTLE_S) state->elapsed_s += dt_s;
    settled = state->elapsed_s >= {up}_SETTLE_S;
    in_range = level_in_range && rate_in_range && settled;
    state->samples += 1UL;
    /* counted once settled (a settling sample is flagged as such, not out of range) */
    state->out_of_range += (level_in_range || !settled) ? 0UL : 1UL;
    state->rate_out_of_range += (rate_in_range || !settled) ? 0UL : 1UL;
{k['apply']}    if (out) {{
        out->rate_comp_dph = compensated;
        out->bias_model_dph = bias;
        out->resonator_c_est = temperature;
        out->f_hz = f_value;
        out->df_hz_per_s = df_value;
{h['out']}{k['out']}        out->in_range = in_range;
        out->rate_in_range = rate_in_range;
    }}
    return compensated;
}}
"""
