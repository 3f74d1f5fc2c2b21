"""The noise model's fit time beside a plain ``scipy.optimize.nnls`` fit of the same curve.

A gyro-like rate (ARW 0.1 °/√h, bias instability 2 °/h, RRW 20 °/h/√h) of 2^16 samples at
10 Hz (``--quick``: 2^14): its overlapping Allan deviation, then

- ``plain_nnls``: one ``scipy.optimize.nnls`` of the five-term design on the relative
  residuals, each τ weighted by √(edf/2) (the usual fit, no interval on the terms);
- ``noise_model``: :func:`hrgtc.evaluation.noise_model.fit_noise_model` with 200 bootstrap
  records (pilot, bootstrap covariance, AIC selection over 31 subsets, 200 refits).

One JSON line each: seconds (best of 3), the terms found, how far each fit's ARW, bias
instability and RRW are from the generator's, and the noise model's 90 % intervals (None:
unbounded above, more than 5 % of the refits leave the term out).
"""

from __future__ import annotations

import json
import sys
import time


def run(quick: bool = False) -> list[dict]:
    import numpy as np
    from scipy.optimize import nnls

    from hrgtc.evaluation.allan import allan_deviation
    from hrgtc.evaluation.noise_model import TERMS, fit_noise_model, unit_noises

    n, fs, bootstrap = (1 << 14 if quick else 1 << 16), 10.0, 200
    truth = {"angle_random_walk": 0.1, "bias_instability": 2.0, "rate_random_walk": 20.0}
    coefficients = {"angle_random_walk": (60.0 * 0.1) ** 2,  # docs/noise-model.md
                    "bias_instability": 2.0 * np.log(2.0) / np.pi * 2.0 ** 2,
                    "rate_random_walk": (20.0 / 60.0) ** 2 / 3}
    units = unit_noises(1, n, fs, np.random.default_rng(20261129))
    rate = sum(np.sqrt(c) * units[k][0] for k, c in coefficients.items())
    allan = allan_deviation(rate, fs, confidence=0.683)
    keep = allan.blocks >= 8
    taus, avar, edf = allan.taus_s[keep], allan.deviation[keep] ** 2, allan.edf[keep]

    def plain() -> np.ndarray:
        design = np.column_stack([taus ** power for power, *_ in TERMS.values()])
        weight = np.sqrt(edf / 2.0) / avar
        a = design * weight[:, None]
        scale = 1.0 / np.abs(a).max(axis=0)
        c, _ = nnls(a * scale, avar * weight)
        return c * scale

    def best_of(function, repeats: int = 3) -> tuple[float, object]:
        times, out = [], None
        for _ in range(repeats):
            start = time.perf_counter()
            out = function()
            times.append(time.perf_counter() - start)
        return min(times), out

    plain_s, c = best_of(plain)
    plain_terms = {k: float(TERMS[k][2](v)) for k, v in zip(TERMS, c, strict=True)}
    model_s, model = best_of(lambda: fit_noise_model(allan, bootstrap=bootstrap))
    common = {"n": n, "sample_rate_hz": fs, "taus": int(taus.size)}

    def errors(terms: dict) -> dict:
        return {f"{k}_rel_error": round(terms[k] / v - 1.0, 4) for k, v in truth.items()}

    return [
        {"name": "noise_model_plain_nnls", **common, "seconds": round(plain_s, 6),
         "terms": {k: round(v, 5) for k, v in plain_terms.items()}, **errors(plain_terms)},
        {"name": "noise_model_fit", **common, "bootstrap": bootstrap,
         "seconds": round(model_s, 3), "fitted": list(model.fitted),
         "ratio_to_plain": round(model_s / plain_s, 1),
         "terms": {k: round(v, 5) for k, v in model.terms.items()}, **errors(model.terms),
         "intervals_90": {k: [round(x, 5) if np.isfinite(x) else None for x in v]
                          for k, v in model.intervals.items() if v is not None}},
    ]


if __name__ == "__main__":
    for line in run(quick="--quick" in sys.argv):
        print(json.dumps(line))
