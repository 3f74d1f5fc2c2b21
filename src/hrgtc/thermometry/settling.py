"""Settling curve of a chamber soak: extrapolating the settled frequency, Section 3 of [1].

A resonator in vacuum takes hours to follow a chamber step (Fig. 3 of [1]: ~15,000 s),
and chamber time is the costliest part of a calibration, so the settled frequency is
estimated from the thermal transient itself. Once the chamber holds its set-point,
chamber -> housing -> resonator is a linear two-node network with constant input, so
``T(t) = T_inf + a e^(-t/tau1) + b e^(-t/tau2)`` exactly, and the frequency is the
smooth f(T) of Eq. (17) of [1] of it. :func:`fit_transient` fits the models

* ``constant``: ``f_inf``
* ``exp1``: ``f_inf + A u`` with ``u = e^(-t/tau)``
* ``exp2``: ``f_inf + A u`` with ``u = e^(-t/tau1) + w e^(-t/tau2)``
* ``exp2-cubic``: ``f_inf + q1 u + q2 u^2 + q3 u^3`` (the cubic Eq. (17) of that ``u``)

by variable projection (for fixed time constants the model is linear and is solved by
least squares inside; only the time constants and ``w`` go to
:func:`scipy.optimize.least_squares`) and keeps the one of least AIC. The cubic
matters: Eq. (18) bends by ~2 Hz over a 40 °C step, and a plain two-exponential fit
of a 2.5 h soak then misses f_inf by ~0.1 °C.

[1] X. Wang, W. Wu, Z. Fang, B. Luo, Y. Li, Q. Jiang, "Temperature Drift
    Compensation for Hemispherical Resonator Gyro Based on Natural Frequency",
    Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from hrgtc.core import records
from hrgtc.core.errors import InputError
from hrgtc.core.summary import Figure, Summary, escape

__all__ = ["MIN_FIT_POINTS", "TransientFit", "fit_transient"]

#: Fewest points (block means) :func:`fit_transient` accepts.
MIN_FIT_POINTS = 12
_MODELS = {"exp1": (1, 1), "exp2": (2, 1), "exp2-cubic": (2, 3)}  # name: (exponentials, degree)
_RATIO_BOUNDS = (1e-2, 0.9)  # tau2 / tau1


@dataclass(frozen=True)
class TransientFit(records.Written):
    """Settling curve ``f = f_inf + sum_k q_k u^k``, ``u = sum_j w_j exp(-(t - start_s)/tau_j)``.

    Attributes
    ----------
    model
        ``"constant"``, ``"exp1"``, ``"exp2"`` or ``"exp2-cubic"`` (module docstring).
    f_inf_hz, f_inf_std_hz
        Settled frequency and its standard error. [Hz]
    tau_s
        Time constants, slowest first. [s]
    weights
        ``w_j`` of each exponential in ``u`` (the first is 1).
    poly_hz
        ``q_1, q_2, ...``; ``q_1`` is the first-order amplitude. [Hz]
    start_s, end_s
        Times of the first and last block fitted. [s]
    n_blocks
        Number of block means fitted.
    rms_hz
        Residual rms of the block means. [Hz]
    aic
        ``n ln(RSS/n) + 2k`` of the chosen model.
    usable
        True when the fit is well determined; otherwise ``reason`` says why.
    """

    model: str
    f_inf_hz: records.Statistic
    f_inf_std_hz: records.Statistic
    tau_s: tuple[records.Statistic, ...]
    weights: tuple[records.Statistic, ...]
    poly_hz: tuple[records.Statistic, ...]
    start_s: float
    end_s: float
    n_blocks: records.Count
    rms_hz: records.Statistic
    aic: records.Statistic
    usable: bool
    reason: str = ""

    @property
    def amplitude_hz(self) -> tuple[float, ...]:
        """First-order amplitude of each exponential, ``q_1 w_j``. [Hz]"""
        return tuple(self.poly_hz[0] * w for w in self.weights) if self.poly_hz else ()

    @property
    def end_offset_hz(self) -> float:
        """``f(end_s) - f_inf``: how far from settled the curve ends. [Hz]"""
        return float(self.evaluate(self.end_s) - self.f_inf_hz)

    def evaluate(self, time_s: Any) -> np.ndarray:
        """The fitted curve at times on the recording's clock. [Hz]"""
        t = np.asarray(time_s, dtype=np.float64) - self.start_s
        u = np.zeros_like(t)
        for w, tau in zip(self.weights, self.tau_s, strict=True):
            u += w * np.exp(-t / tau)
        out = np.full_like(t, self.f_inf_hz)
        for k, q in enumerate(self.poly_hz, start=1):
            out += q * u**k
        return out

    def summary(self) -> Summary:
        """The settled frequency ± its standard error, the time constants, the RMS residual
        and whether it is usable (its text: one line)."""
        taus = ", ".join(f"{t:.0f}" for t in self.tau_s) or "-"
        state = "usable" if self.usable else f"not usable: {self.reason}"
        figures = (Figure("start_h", "from", self.start_s / 3600, "h"),
                   Figure("end_h", "to", self.end_s / 3600, "h"),
                   Figure.with_error("f_inf_hz", "settled frequency", self.f_inf_hz,
                                     self.f_inf_std_hz, "Hz", definition="The frequency the "
                                     "fitted transient settles to (t → ∞)."),
                   Figure("f_inf_std_hz", "its standard error", self.f_inf_std_hz, "Hz"),
                   *(Figure(f"tau_s[{k}]", f"time constant {k + 1}", t, "s")
                     for k, t in enumerate(self.tau_s)),
                   Figure("rms_hz", "RMS residual", self.rms_hz, "Hz"))
        return Summary(f"{self.model} transient fit", (("transient fit", figures),),
                       (state,), (escape(self.model) + " fit over {start_h:.2f}-{end_h:.2f} h: "
                                  "f_inf {f_inf_hz:.5f} ± {f_inf_std_hz:.2g} Hz, "
                                  f"tau {escape(taus)} s, rms {{rms_hz:.2g}} Hz "
                                  f"({escape(state)})",))


def _basis(tt: np.ndarray, params: np.ndarray, exps: int) -> tuple[np.ndarray, np.ndarray]:
    """``u`` and its derivatives by the nonlinear parameters (log tau1, log tau2/tau1, w)."""
    tau1 = math.exp(params[0])
    e1 = np.exp(-tt / tau1)
    if exps == 1:
        return e1, (e1 * tt / tau1)[:, None]
    tau2 = math.exp(params[0] + params[1])
    e2 = np.exp(-tt / tau2)
    d2 = params[2] * e2 * tt / tau2
    return e1 + params[2] * e2, np.column_stack([e1 * tt / tau1 + d2, d2, e2])


class _Projection:
    """Variable projection of ``y`` on ``[1, u, u^2, ...]``: residuals and their Jacobian.

    For fixed nonlinear parameters the linear coefficients are the least-squares
    solution; the Jacobian is Kaufman's, ``P_perp (dX/dp) coef``.
    """

    def __init__(self, tt: np.ndarray, y: np.ndarray, exps: int, degree: int) -> None:
        self.tt, self.y, self.exps, self.degree = tt, y, exps, degree
        self.params: np.ndarray | None = None

    def update(self, params: np.ndarray) -> None:
        if self.params is not None and np.array_equal(params, self.params):
            return
        self.u, self.du = _basis(self.tt, params, self.exps)
        self.design = np.vander(self.u, self.degree + 1, increasing=True)
        self.coef = np.linalg.lstsq(self.design, self.y, rcond=None)[0]
        self.params = np.array(params, dtype=np.float64)

    def residuals(self, params: np.ndarray) -> np.ndarray:
        self.update(params)
        return self.design @ self.coef - self.y

    def model_jacobian(self, params: np.ndarray) -> np.ndarray:
        """d(model)/d(nonlinear parameters) at fixed linear coefficients."""
        self.update(params)
        slope = np.polynomial.polynomial.polyval(
            self.u, self.coef[1:] * np.arange(1, self.degree + 1)
        )
        return slope[:, None] * self.du

    def jacobian(self, params: np.ndarray) -> np.ndarray:
        jac = self.model_jacobian(params)
        return jac - self.design @ np.linalg.lstsq(self.design, jac, rcond=None)[0]

    def constant_std(self, rss: float) -> float:
        """Standard error of f_inf from the Jacobian of the full (unprojected) model."""
        jac = np.hstack([self.design, self.model_jacobian(self.params)])
        n, k = jac.shape
        norms = np.linalg.norm(jac, axis=0)
        if n <= k or not np.all(np.isfinite(jac)) or np.any(norms == 0):
            return math.inf
        _, sv, vt = np.linalg.svd(jac / norms, full_matrices=False)
        if sv[-1] <= sv[0] * 1e-12:
            return math.inf
        return math.sqrt(rss / (n - k) * float(np.sum((vt[:, 0] / sv) ** 2))) / norms[0]


def fit_transient(time_s: Any, freq_hz: Any) -> TransientFit:
    """Fit the settling curve of a soak and extrapolate its settled frequency.

    The thermal transient after a chamber step (Fig. 3 of [1]) is fitted with
    the models of the module docstring by variable projection; the model of
    least AIC is returned. Pass block means (e.g. 10 s) from the time the
    chamber holds its set-point.

    Parameters
    ----------
    time_s
        Times, increasing. [s]
    freq_hz
        Frequency at those times. [Hz]

    Returns
    -------
    TransientFit
        Not ``usable`` when the slowest time constant is not shorter than the
        fitted span (the curve has not shown where it goes) or the standard
        error of f_inf is not finite.

    Examples
    --------
    >>> t = np.arange(0.0, 9000.0, 10.0)
    >>> fit = fit_transient(t, 4417.0 + 3.0 * np.exp(-t / 2400.0))
    >>> round(fit.f_inf_hz, 6), fit.usable
    (4417.0, True)
    """
    tb, fb = _checked(time_s, freq_hz)
    tt, n = tb - tb[0], tb.size
    span = float(tt[-1])
    ref = float(np.median(fb))
    best = _least_aic(tt, fb - ref)
    model, projection, coef, rss, aic = best
    common = {
        "start_s": float(tb[0]), "end_s": float(tb[-1]), "n_blocks": int(n),
        "rms_hz": math.sqrt(rss / n), "aic": float(aic),
    }  # fmt: skip
    if model == "constant":
        std = math.sqrt(rss / (n - 1) / n)
        return TransientFit(model, ref + float(coef[0]), std, (), (), (), usable=True, **common)
    exps, params = _MODELS[model][0], projection.params
    std = projection.constant_std(rss)
    taus, weights = [math.exp(params[0])], [1.0]
    if exps == 2:
        taus.append(math.exp(params[0] + params[1]))
        weights.append(float(params[2]))
    reason = ""
    if taus[0] >= span:
        reason = (
            f"its time constant {taus[0]:.0f} s is not shorter than the {span:.0f} s fitted, "
            "the curve has not shown where it settles"
        )
    elif not math.isfinite(std):
        reason = "its settled frequency is not determined (singular fit)"
    poly = tuple(float(c) for c in coef[1:])
    return TransientFit(
        model, ref + float(coef[0]), std, tuple(taus), tuple(weights), poly,
        usable=not reason, reason=reason, **common,
    )  # fmt: skip


def _checked(time_s: Any, freq_hz: Any) -> tuple[np.ndarray, np.ndarray]:
    """``time_s`` and ``freq_hz`` as flat float arrays, refused unless fit for a transient."""
    tb = np.asarray(time_s, dtype=np.float64).ravel()
    fb = np.asarray(freq_hz, dtype=np.float64).ravel()
    if tb.size != fb.size or tb.size < MIN_FIT_POINTS:
        raise InputError(
            f"fit_transient needs time_s and freq_hz of equal length >= {MIN_FIT_POINTS}, "
            f"got {tb.size} and {fb.size}"
        )
    if not (np.all(np.isfinite(tb)) and np.all(np.isfinite(fb)) and np.all(np.diff(tb) > 0)):
        raise InputError("fit_transient needs finite freq_hz and finite, increasing time_s")
    return tb, fb


def _least_aic(tt: np.ndarray, y: np.ndarray) -> tuple[str, Any, np.ndarray, float, float]:
    """The model of least AIC for ``y`` at times ``tt`` (from 0): its name, projection
    (None for the constant), linear coefficients, residual sum of squares and AIC.

    The models of the module docstring are tried in order, each started from the last;
    one with more parameters than a third of the points is not tried.
    """
    n = tt.size
    span = float(tt[-1])
    rss = float(np.sum((y - y.mean()) ** 2))
    best = ("constant", None, np.array([y.mean()]), rss, n * math.log(rss / n + 1e-300) + 2)
    log_tau = (math.log(2.0 * float(np.median(np.diff(tt)))), math.log(100.0 * span))
    ratio = (math.log(_RATIO_BOUNDS[0]), math.log(_RATIO_BOUNDS[1]))
    bounds = {1: ([log_tau[0]], [log_tau[1]]), 2: ([log_tau[0], ratio[0], -np.inf],
                                                   [log_tau[1], ratio[1], np.inf])}  # fmt: skip
    from scipy.optimize import least_squares  # imported on first use: a faster start

    fitted: dict[str, np.ndarray] = {}
    for name, (exps, degree) in _MODELS.items():
        if n <= 2 * (exps + degree + 1):
            break
        if exps == 1:
            starts = [np.array([math.log(span * s)]) for s in (0.1, 0.3, 1.0)]
        elif name == "exp2":
            starts = [np.array([fitted["exp1"][0], math.log(0.3), w]) for w in (-0.5, 0.5)]
        else:
            starts = [fitted["exp2"]]
        projection = _Projection(tt, y, exps, degree)
        rss = math.inf
        for x0 in starts:
            x0 = np.clip(x0, np.add(bounds[exps][0], 1e-9), np.subtract(bounds[exps][1], 1e-9))
            result = least_squares(
                projection.residuals, x0, jac=projection.jacobian, bounds=bounds[exps]
            )
            if 2.0 * result.cost < rss:
                rss, fitted[name] = 2.0 * result.cost, result.x
        projection.update(fitted[name])
        aic = n * math.log(rss / n + 1e-300) + 2 * (fitted[name].size + degree + 1)
        if aic < best[4]:
            best = (name, projection, projection.coef, rss, aic)
    return best
