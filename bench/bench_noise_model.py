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

``--coverage`` (not part of ``bench/run.py``; about 1 min per 2048-sample case on two cores)
measures the 90 % intervals' coverage over 200 seeds of allantools' Kasdin noise, the terms
named and chosen by AIC, on records of 2048 and 8192 samples (docs/noise-model.md): one
JSON line per case with the seeds whose interval holds the generator's term.
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


def coverage(n: int, named: bool, seeds: int = 200, bootstrap: int = 100) -> dict:
    """Coverage of the 90 % intervals over ``seeds`` records of allantools' Kasdin noise
    (C_-1 = 1, C_0 = 0.05, C_+1 = 5e-4 at 1 Hz, as the slow test)."""
    import math

    import allantools
    import numpy as np

    from hrgtc.evaluation.allan import allan_deviation
    from hrgtc.evaluation.noise_model import TERMS, fit_noise_model

    kasdin = {-2: ("angle_random_walk", -1, 1.0), -3: ("bias_instability", 0, 0.05),
              -4: ("rate_random_walk", 1, 5e-4)}
    qd = {-2: 1.0, -3: 0.05 * math.pi / (2.0 * math.log(2.0)), -4: 3.0 * 5e-4}
    truth = {name: TERMS[name][2](allantools.Noise(n + 1, qd[b], b).adev(1.0, 10.0) ** 2
                                  / 10.0 ** k) for b, (name, k, _) in kasdin.items()}
    hits, true_model = dict.fromkeys(truth, 0), 0
    start = time.perf_counter()
    for seed in range(seeds):
        np.random.seed(1000 + seed)  # noqa: NPY002 - allantools.Noise draws from it
        phase = np.zeros(n + 1)
        for b, q in qd.items():
            noise = allantools.Noise(n + 1, q, b)
            noise.generateNoise()
            phase += noise.time_series
        model = fit_noise_model(allan_deviation(np.diff(phase), 1.0, confidence=0.683),
                                terms=tuple(truth) if named else None, bootstrap=bootstrap,
                                confidence=0.9, seed=seed)
        true_model += model.fitted == tuple(truth)
        for name, value in truth.items():
            interval = model.intervals[name]
            hits[name] += interval is not None and interval[0] <= value <= interval[1]
    return {"name": f"noise_model_coverage_{'named' if named else 'aic'}_{n}", "n": n,
            "seeds": seeds, "bootstrap": bootstrap, "confidence": 0.9,
            "binomial_99": [int(x) for x in __import__("scipy.stats").stats.binom.interval(
                0.99, seeds, 0.9)],
            "covered": hits, "true_model_selected": true_model,
            "seconds": round(time.perf_counter() - start, 1)}


if __name__ == "__main__":
    if "--coverage" in sys.argv:
        for n, named in ((2048, True), (2048, False), (8192, False)):
            print(json.dumps(coverage(n, named)), flush=True)
    else:
        for line in run(quick="--quick" in sys.argv):
            print(json.dumps(line))
