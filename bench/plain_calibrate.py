"""The paper's calibration as a plain numpy + pyarrow script: the baseline of ``hrgtc calibrate``.

    python bench/plain_calibrate.py MODEL.json --soak SOAK... --drift RUN...

What a user would write from [1] without hrgtc, on the same files, each read once with
the columns it needs:

1. each soak: the plateau is the mean frequency and chamber temperature of its last
   hour (Section 3 of [1]: 4-5 h soaks); the plateaus' cubic f(T) and its inverse T(f)
   (Eq. 16-18, Table 1);
2. every run (the drift runs and the soaks, whose warming and cooling transients are the
   training data hrgtc uses by default): 10 s window means of the rate, the frequency
   and the housing temperature; T = T(f); the candidate terms in f = T − 20 °C and the
   housing-resonator gradient g = housing_c − T (the terms hrgtc chooses when every run
   logs housing_c: ``GRADIENT_TERMS``); ordinary least squares with a constant
   (Eq. 21-22 with the gradient in place of df/dt).

No validation, no spike filter, no motion detection, no term selection: the floor that
the reading path of ``hrgtc calibrate`` is measured against. Writes the coefficients
as JSON.

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import argparse
import json
import sys

import numpy as np
import pyarrow.parquet as pq

WINDOW_S = 10.0
PLATEAU_S = 3600.0
REFERENCE_C = 20.0


def plateau(path: str) -> tuple[float, float]:
    """Mean chamber temperature and frequency of the soak's last hour. [°C], [Hz]"""
    table = pq.read_table(path, columns=["time_s", "freq_hz", "chamber_c"])
    time_s = table.column("time_s").to_numpy()
    last = time_s >= time_s[-1] - PLATEAU_S
    return (float(np.mean(table.column("chamber_c").to_numpy()[last])),
            float(np.mean(table.column("freq_hz").to_numpy()[last])))


def window_means(path: str) -> np.ndarray:
    """10 s window means of rate, frequency and housing temperature, one row per window."""
    table = pq.read_table(path, columns=["time_s", "freq_hz", "rate_dph", "housing_c"])
    time_s = table.column("time_s").to_numpy()
    per = max(round(WINDOW_S / float(np.median(np.diff(time_s[:1000])))), 1)
    windows = time_s.size // per
    out = np.empty((windows, 3))
    for k, name in enumerate(("rate_dph", "freq_hz", "housing_c")):
        column = table.column(name).to_numpy()[: windows * per]
        out[:, k] = column.reshape(windows, per).mean(axis=1)
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("output")
    parser.add_argument("--soak", nargs="+", required=True)
    parser.add_argument("--drift", nargs="+", required=True)
    args = parser.parse_args(argv)
    plateaus = np.array([plateau(p) for p in args.soak])
    temperature_c, freq_hz = plateaus[:, 0], plateaus[:, 1]
    f_of_t = np.polynomial.Polynomial.fit(temperature_c, freq_hz, 3)  # Eq. 18
    t_of_f = np.polynomial.Polynomial.fit(freq_hz, temperature_c, 3)  # its inverse
    means = np.concatenate([window_means(p) for p in [*args.drift, *args.soak]])
    rate, temperature = means[:, 0], t_of_f(means[:, 1])
    f = temperature - REFERENCE_C
    g = means[:, 2] - temperature
    design = np.column_stack([np.ones_like(f), f, f**2, f**3, g, f * g, f**2 * g])
    coefficients, *_ = np.linalg.lstsq(design, rate, rcond=None)
    residual = rate - design @ coefficients
    with open(args.output, "w", encoding="utf-8") as out:
        json.dump({"f_of_t": f_of_t.convert().coef.tolist(),
                   "terms": ["1", "f", "f^2", "f^3", "g", "f*g", "f^2*g"],
                   "coefficients": coefficients.tolist(),
                   "windows": int(rate.size), "residual_std_dph": float(np.std(residual))},
                  out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
