"""The resonator as a thermometer: a polynomial f(T) fitted to soak plateaus and its inverse.

Eq. (16)-(18) and Tables 1-2 of [1]. The frequency-temperature law is a
Taylor polynomial (Eq. 17) whose coefficients come from chamber soaks by least
squares (Eq. 18); inverting it turns the resonator frequency back into the
resonator temperature (Table 2).

Numerics: the fit is done on a centred and scaled temperature
z = (T - centre) / scale in [-1, 1] with a Householder QR (LAPACK through
:func:`numpy.linalg.qr`), never on a raw Vandermonde matrix; the coefficients
are converted back to powers of T in exact rational arithmetic, so the only
error left is that of the well-conditioned scaled problem. The fitted
polynomial is evaluated in the scaled variable, and the inverse is a
safeguarded Newton iteration on a bracket.

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from fractions import Fraction
from functools import cached_property
from math import comb
from typing import Annotated, Any, Literal

import numpy as np
from msgspec import Meta

from hrgtc.core import records
from hrgtc.core.errors import CalibrationError, ExtrapolationWarning, InputError
from hrgtc.core.student_t import t_sf
from hrgtc.core.summary import Figure, Summary, escape

_GRID_POINTS = 2049
_NEWTON_MAX_ITER = 60
_CHEBYSHEV_DEGREE = 9


@dataclass(frozen=True)
class _InverseTable:
    t_bracket: tuple[float, float]
    f_bracket: tuple[float, float]
    f_calibrated: tuple[float, float]
    grid_t: np.ndarray
    grid_f: np.ndarray
    start_coefficients: np.ndarray  # Chebyshev series of T in u = offset + scale * f
    start_map: tuple[float, float]
    tolerance: float
    one_step_limit: float  # a Newton step smaller than this leaves an error below tolerance


def _scaled_to_raw_matrix(order: int, centre: float, scale: float) -> list[list[Fraction]]:
    """Exact matrix M with raw = M @ scaled for p(T) = sum_k a_k ((T - centre)/scale)^k.

    ((T - m)/s)^k = sum_j C(k, j) T^j (-m)^(k-j) / s^k, in exact rationals.
    """
    m = Fraction(centre)
    s = Fraction(scale)
    matrix = [[Fraction(0)] * (order + 1) for _ in range(order + 1)]
    for k in range(order + 1):
        inv = 1 / s**k
        for j in range(k + 1):
            matrix[j][k] = comb(k, j) * (-m) ** (k - j) * inv
    return matrix


def _clenshaw(coefficients: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Evaluate sum_k c_k T_k(u) (Chebyshev polynomials) by Clenshaw's recurrence."""
    b1 = np.zeros_like(u)
    b2 = np.zeros_like(u)
    two_u = 2.0 * u
    for c in coefficients[:0:-1]:
        b1, b2 = two_u * b1 - b2 + c, b1
    return u * b1 - b2 + coefficients[0]


def _horner(coefficients: np.ndarray, z: np.ndarray) -> np.ndarray:
    """Evaluate sum_k c_k z^k (ascending coefficients) by Horner's rule."""
    result = np.full_like(z, coefficients[-1], dtype=np.float64)
    for c in coefficients[-2::-1]:
        result *= z
        result += c
    return result


@dataclass(frozen=True, kw_only=True)
class Thermometer(records.Written):
    """A fitted frequency-temperature polynomial f(T) and its inverse T(f).

    Build it with :func:`fit`. Eq. (17)-(18) of [1].

    Attributes
    ----------
    coefficients
        c0, c1, ... of f(T) = sum_k c_k T^k, ascending powers as
        :mod:`numpy.polynomial` orders them. [Hz/°C^k]
    standard_errors
        Standard error of each coefficient, same order (NaN when the fit has
        no residual degrees of freedom). [Hz/°C^k]
    residual_std_hz
        Residual standard deviation sqrt(RSS / (n - order - 1)). [Hz]
    rsquared
        Coefficient of determination.
    temperature_range_c
        (min, max) of the calibration temperatures. [°C]
    order
        Polynomial order.
    n_points
        Number of calibration points.
    centre_c, scale_c
        The internal scaling z = (T - centre_c) / scale_c. [°C]
    scaled_coefficients
        Coefficients of the polynomial in z, ascending; what is evaluated. [Hz]
    scaled_covariance
        Covariance of ``scaled_coefficients`` (None without residual dof). [Hz²]
    source
        ``"resonator"``: f is the resonator's natural frequency (Eq. 18 of [1]);
        ``"sensor"``: a gyro without a frequency output, whose temperature sensor
        is read in place of f (:func:`identity`: f = T, in °C).
    """

    #: Its record (the model file's ``thermometer``) is generated from these fields.
    constants = (("kind", "hrgtc.Thermometer"),)
    omit_when_default = ("source",)  # written only for a sensor: older files hash alike
    renamed = (("residual_std", "residual_std_hz"),)  # before 0.1

    order: Annotated[int, Meta(ge=1, le=12)]
    n_points: Annotated[int, Meta(ge=2)]
    coefficients: Annotated[tuple[float, ...], Meta(min_length=2)]
    standard_errors: tuple[records.Statistic, ...]
    residual_std_hz: records.Statistic = math.nan
    rsquared: records.Statistic
    temperature_range_c: records.Range
    centre_c: float
    scale_c: records.Positive
    scaled_coefficients: Annotated[tuple[float, ...], Meta(min_length=2)]
    scaled_covariance: tuple[tuple[records.Statistic, ...], ...] | None = None
    source: Literal["resonator", "sensor"] = "resonator"

    # -- derived -------------------------------------------------------------------
    @property
    def pvalues(self) -> tuple[float, ...]:
        """Two-sided t-test p-value of each coefficient being zero, ascending powers.

        NaN where the fit has no residual degrees of freedom (as ``standard_errors``).
        """
        dof = self.n_points - self.order - 1
        out = []
        for c, se in zip(self.coefficients, self.standard_errors, strict=True):
            if dof <= 0 or not np.isfinite(se) or se == 0:
                out.append(float("nan"))
            else:
                out.append(float(2 * t_sf(abs(c / se), dof)))
        return tuple(out)

    @property
    def inverse_range_c(self) -> tuple[float, float]:
        """Temperatures over which :meth:`temperature` inverts f(T). [°C]

        The calibrated range extended by at most one span each side, and only as far
        as f(T) stays monotonic; beyond it the inverse returns NaN.
        """
        t_low, t_high = self.temperature_range_c
        return self._monotonic_extension(t_low, t_high, t_high - t_low)

    @property
    def coefficients_high_first(self) -> tuple[float, ...]:
        """Coefficients with the highest power first, as Eq. (18) prints them."""
        return tuple(reversed(self.coefficients))

    @property
    def frequency_range_hz(self) -> tuple[float, float]:
        """(min, max) of f(T) over the calibrated temperature range. [Hz]"""
        return self._inverse.f_calibrated

    @property
    def is_monotonic(self) -> bool:
        """True when f(T) is strictly monotonic over the calibrated range."""
        return self._monotonic_violation() is None

    def slope_hz_per_c(self, temperature_c: Any) -> np.ndarray:
        """df/dT of the fitted polynomial. [Hz/°C]"""
        z = (np.asarray(temperature_c, dtype=np.float64) - self.centre_c) / self.scale_c
        a = np.asarray(self.scaled_coefficients)
        derivative = a[1:] * np.arange(1, a.size)
        if derivative.size == 0:
            return np.zeros_like(z)
        return _horner(derivative, z) / self.scale_c

    # -- evaluation ----------------------------------------------------------------
    def frequency(self, temperature_c: Any) -> np.ndarray:
        """Natural frequency at a resonator temperature, Eq. (17)-(18) of [1].

        Parameters
        ----------
        temperature_c
            Resonator temperature. [°C]

        Returns
        -------
        numpy.ndarray
            Frequency. [Hz]
        """
        t = np.asarray(temperature_c, dtype=np.float64)
        z = (t - self.centre_c) / self.scale_c
        return _horner(np.asarray(self.scaled_coefficients), z)

    def in_range(self, frequency_hz: Any) -> np.ndarray:
        """Boolean mask: frequencies inside the calibrated range."""
        f = np.asarray(frequency_hz, dtype=np.float64)
        low, high = self.frequency_range_hz
        return (f >= low) & (f <= high)

    def temperature(self, frequency_hz: Any, *, warn: bool = True) -> np.ndarray:
        """Resonator temperature from frequency: the exact inverse of the fit (Table 2 of [1]).

        A safeguarded Newton iteration on the bracket of the calibrated range,
        started from interpolation in a dense table of the polynomial.
        Frequencies outside the calibrated range are extrapolated along the
        polynomial as far as it stays monotonic (NaN beyond) and flagged with an
        :class:`~hrgtc.core.errors.ExtrapolationWarning` giving their count and share.

        Parameters
        ----------
        frequency_hz
            Resonator frequency. [Hz]
        warn
            Issue the extrapolation warning (set False when the caller reports
            the out-of-range share itself).

        Returns
        -------
        numpy.ndarray
            Resonator temperature. [°C]

        Raises
        ------
        CalibrationError
            When f(T) is not monotonic over the calibrated range.
        """
        violation = self._monotonic_violation()
        if violation is not None:
            raise CalibrationError(violation)
        f = np.asarray(frequency_hz, dtype=np.float64)
        inverse = self._inverse
        t_low, t_high = self.temperature_range_c
        f_low_cal, f_high_cal = inverse.f_calibrated
        flat = f.ravel()
        beyond = ~((flat >= inverse.f_bracket[0]) & (flat <= inverse.f_bracket[1]))
        if warn:
            n_out = int(np.count_nonzero(((flat < f_low_cal) | (flat > f_high_cal))
                                         & np.isfinite(flat)))
            if n_out:
                warnings.warn(
                    f"{n_out} of {flat.size} frequencies ({n_out / flat.size:.2%}) are outside "
                    f"the calibrated range {f_low_cal:.4f}-{f_high_cal:.4f} Hz "
                    f"({t_low:g} to {t_high:g} °C); their temperatures are extrapolated"
                    if self.source == "resonator" else
                    f"{n_out} of {flat.size} sensor temperatures ({n_out / flat.size:.2%}) are "
                    f"outside the trained range {t_low:g} to {t_high:g} °C",
                    ExtrapolationWarning,
                    stacklevel=2,
                )
        # Start from a Chebyshev approximation of T(f) (~1e-6 °C), polish by Newton.
        clipped = np.clip(flat, *inverse.f_bracket)
        offset, scale = inverse.start_map
        t = _clenshaw(inverse.start_coefficients, offset + scale * clipped)
        np.clip(t, inverse.t_bracket[0], inverse.t_bracket[1], out=t)
        step = np.full_like(t, np.inf)
        limit = inverse.one_step_limit
        for _ in range(4):
            step = (self.frequency(t) - clipped) / self.slope_hz_per_c(t)
            t -= step
            # Newton's error after a step is at most max|f''|/(2 min|f'|) * step^2.
            if not np.max(np.abs(step), initial=0.0) > limit:
                break
            limit = inverse.tolerance
        lost = ~beyond & ~((np.abs(step) <= limit) & (t >= inverse.t_bracket[0])
                           & (t <= inverse.t_bracket[1]))
        if np.any(lost):
            t[lost] = self._bracketed_newton(flat[lost], inverse)
        t = np.where(beyond, np.nan, t)
        return t.reshape(f.shape) if f.ndim else t.reshape(())[()]

    @cached_property
    def _inverse(self) -> _InverseTable:
        """Bracket, dense table, Chebyshev start and tolerance of the inverse (cached)."""
        t_low, t_high = self.temperature_range_c
        lo, hi = self._monotonic_extension(t_low, t_high, t_high - t_low)
        grid_t = np.linspace(lo, hi, _GRID_POINTS)
        grid_f = self.frequency(grid_t)
        if grid_f[-1] < grid_f[0]:
            grid_t, grid_f = grid_t[::-1], grid_f[::-1]
        eps = np.finfo(np.float64).eps
        slope_min = float(np.min(np.abs(np.diff(grid_f) / np.diff(grid_t))))
        f_max = float(np.max(np.abs(grid_f)))
        # Converged iterates still move by the rounding of f (|f| eps) over the slope.
        tolerance = max(4 * eps * max(abs(lo), abs(hi), hi - lo), 16 * eps * f_max / slope_min)
        # The start only needs to be good where the samples are: the calibrated range
        # and a margin; beyond it Newton takes a few more steps.
        margin = 0.1 * (t_high - t_low)
        near = (grid_t >= t_low - margin) & (grid_t <= t_high + margin)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", np.exceptions.RankWarning)
            chebyshev = np.polynomial.Chebyshev.fit(grid_f[near], grid_t[near],
                                                    deg=_CHEBYSHEV_DEGREE)

        calibrated = self.frequency(np.linspace(t_low, t_high, _GRID_POINTS))
        a = np.asarray(self.scaled_coefficients)
        second = a[2:] * np.arange(2, a.size) * np.arange(1, a.size - 1) if a.size > 2 else a[:0]
        curvature = (float(np.max(np.abs(_horner(second, (grid_t - self.centre_c) / self.scale_c))))
                     / self.scale_c**2 if second.size else 0.0)
        one_step_limit = (math.sqrt(tolerance * 2.0 * slope_min / curvature)
                          if curvature > 0 else math.inf)
        return _InverseTable(
            t_bracket=(float(lo), float(hi)),
            f_bracket=(float(grid_f[0]), float(grid_f[-1])),
            f_calibrated=(float(calibrated.min()), float(calibrated.max())),
            grid_t=grid_t,
            grid_f=grid_f,
            start_coefficients=chebyshev.coef,
            start_map=tuple(float(v) for v in chebyshev.mapparms()),
            tolerance=tolerance,
            one_step_limit=min(one_step_limit, 1e-3 * (hi - lo)),
        )

    def _bracketed_newton(self, flat: np.ndarray, inverse: _InverseTable) -> np.ndarray:
        """Safeguarded Newton inside the dense-table bracket of each sample (slow path)."""
        grid_t, grid_f = inverse.grid_t, inverse.grid_f
        increasing = grid_t[-1] > grid_t[0]
        index = np.clip(np.searchsorted(grid_f, flat), 1, grid_f.size - 1)
        f0, f1 = grid_f[index - 1], grid_f[index]
        t0, t1 = grid_t[index - 1], grid_t[index]
        with np.errstate(invalid="ignore", divide="ignore"):
            t = t0 + (flat - f0) * (t1 - t0) / (f1 - f0)
        lower = np.minimum(t0, t1)
        upper = np.maximum(t0, t1)
        t = np.clip(np.nan_to_num(t, nan=0.5 * (t0[0] + t1[0])), lower, upper)
        for _ in range(_NEWTON_MAX_ITER):
            residual = self.frequency(t) - flat
            candidate = t - residual / self.slope_hz_per_c(t)
            # Keep the bracket: the residual's sign tells which side the root is on.
            above = (residual > 0) == increasing
            upper = np.where(above, np.minimum(upper, t), upper)
            lower = np.where(above, lower, np.maximum(lower, t))
            bad = ~((candidate >= lower) & (candidate <= upper))
            candidate = np.where(bad, 0.5 * (lower + upper), candidate)
            change = np.abs(candidate - t)
            t = candidate
            if not np.any(change > inverse.tolerance):
                break
        return t

    # -- monotonicity --------------------------------------------------------------
    def _critical_points(self) -> np.ndarray:
        """Real temperatures where df/dT = 0. [°C]"""
        a = np.asarray(self.scaled_coefficients)
        if a.size < 3:
            return np.empty(0)
        derivative = np.polynomial.Polynomial(a[1:] * np.arange(1, a.size))
        roots = derivative.roots()
        real = roots[np.abs(roots.imag) < 1e-9].real
        return np.sort(self.centre_c + self.scale_c * real)

    def _monotonic_violation(self) -> str | None:
        t_low, t_high = self.temperature_range_c
        if self.order < 1 or np.all(np.asarray(self.scaled_coefficients[1:]) == 0.0):
            return "the fitted f(T) is constant: frequency carries no temperature information"
        inside = [t for t in self._critical_points() if t_low < t < t_high]
        if inside:
            return (
                f"the fitted f(T) is not monotonic over the calibrated range {t_low:g} to "
                f"{t_high:g} °C: df/dT = 0 at {', '.join(f'{t:.3f}' for t in inside)} °C, so one "
                "frequency maps to two temperatures; lower the polynomial order or check the "
                "soak plateaus for a bad point"
            )
        return None

    def _monotonic_extension(self, t_low: float, t_high: float, span: float) -> tuple[float, float]:
        """Bracket beyond the calibrated range (at most one span each side) kept monotonic."""
        lo, hi = t_low - span, t_high + span
        for t in self._critical_points():
            if lo < t <= t_low:
                lo = t
            if t_high <= t < hi:
                hi = t
        return float(lo), float(hi)

    # -- reporting -----------------------------------------------------------------
    def summary(self) -> Summary:
        """The coefficients with standard errors and p-values, the residual and R² (its
        text: the table and the polynomial, Eq. 18's form)."""
        cells: list[Figure] = []
        layout = [escape(f"Thermometer: order-{self.order} polynomial f(T) from "
                         f"{self.n_points} points, {self.temperature_range_c[0]:g} to "
                         f"{self.temperature_range_c[1]:g} °C"),
                  escape(f"{'power':>6} {'coefficient':>18} {'std error':>12} {'p-value':>10}")]
        rows = zip(self.coefficients, self.standard_errors, self.pvalues, strict=True)
        for k, (c, se, pvalue) in enumerate(rows):
            power = "T^" + str(k)
            unit = "Hz" if k == 0 else f"Hz/°C^{k}"
            cells += [Figure(f"coefficients[{k}]", f"coefficient of {power}", float(c), unit,
                             digits=10, row=power, column="coefficient",
                             definition=f"The fitted coefficient of T^{k} in f(T)."),
                      Figure(f"standard_errors[{k}]", f"std error of {power}", float(se), unit,
                             digits=4, row=power, column="std error"),
                      Figure(f"pvalues[{k}]", f"p of {power}", float(pvalue), digits=3,
                             row=power, column="p-value")]
            layout.append(f"{escape(f'{power:>6}')} {{coefficients[{k}]:>18.10g}} "
                          f"{{standard_errors[{k}]:>12.4g}} {{pvalues[{k}]:>10.3g}}")
        fit = (Figure("n_points", "points", self.n_points),
               Figure("residual_std_hz", "residual std", self.residual_std_hz, "Hz", digits=4,
                      definition="Standard deviation of the fit's residuals."),
               Figure("rsquared", "R²", self.rsquared, spec=".10f"))
        layout.append("residual std {residual_std_hz:.4g} Hz, R² {rsquared:.10f}")
        terms = []
        for k in reversed(range(len(self.coefficients))):
            power = "" if k == 0 else ("·T" if k == 1 else f"·T^{k}")
            terms.append(f"{{coefficients[{k}]:+.6g}}{power}")
        layout.append("f = " + " ".join(terms) + " Hz")
        return Summary(f"thermometer: order-{self.order} polynomial f(T)",
                       (("coefficients", tuple(cells)), ("fit", fit)), layout=tuple(layout))


#: :class:`Thermometer` in a file (the model file's ``thermometer``), generated from its
#: fields.
ThermometerRecord = records.record_of(
    Thermometer, doc="A :class:`Thermometer` in a file (the model file's ``thermometer``): "
    "field names and\nbounds, from which its ``to_dict``/``from_dict`` and its JSON Schema "
    "are generated.")


def fit(temperatures_c: Any, frequencies_hz: Any, order: int = 3) -> Thermometer:
    """Least-squares polynomial f(T) through calibration points, Eq. (17)-(18) of [1].

    Parameters
    ----------
    temperatures_c
        Resonator temperature of each plateau (the chamber set-point once
        settled). [°C]
    frequencies_hz
        Settled natural frequency of each plateau. [Hz]
    order
        Polynomial order; the paper uses 3.

    Returns
    -------
    Thermometer

    Raises
    ------
    InputError
        Mismatched or non-finite input, or fewer distinct temperatures than
        ``order + 1``.

    Examples
    --------
    >>> th = fit([-20, -10, 0, 10, 20, 30, 40],
    ...          [4416.97, 4421.05, 4424.90, 4428.56, 4432.07, 4435.56, 4439.20])
    >>> [f"{c:.4g}" for c in th.coefficients_high_first]
    ['1.528e-05', '-0.0009702', '0.3716', '4425']
    >>> round(float(th.temperature(4421.05)), 3)
    -10.058
    """
    t, f, order = _checked_points(temperatures_c, frequencies_hz, order)
    t_low, t_high = float(t.min()), float(t.max())
    centre = 0.5 * (t_low + t_high)
    scale = 0.5 * (t_high - t_low)
    z = (t - centre) / scale
    f_mean = float(np.mean(f))
    y = f - f_mean

    vandermonde = np.vander(z, order + 1, increasing=True)
    a, r = _least_squares(vandermonde, y)
    a[0] += f_mean
    fitted = vandermonde @ a
    residual = f - fitted
    n = t.size
    dof = n - (order + 1)
    rss = float(residual @ residual)
    tss = float(np.sum((f - f_mean) ** 2))
    rsquared = 1.0 - rss / tss if tss > 0 else float("nan")

    matrix = _scaled_to_raw_matrix(order, centre, scale)
    scaled_exact = [Fraction(float(v)) for v in a]
    raw = tuple(
        float(sum((matrix[j][k] * scaled_exact[k] for k in range(order + 1)), Fraction(0)))
        for j in range(order + 1)
    )
    standard_errors, residual_std, covariance = _errors(r, matrix, rss, dof)
    return Thermometer(
        coefficients=raw,
        standard_errors=standard_errors,
        residual_std_hz=residual_std,
        rsquared=rsquared,
        temperature_range_c=(t_low, t_high),
        order=order,
        n_points=n,
        centre_c=centre,
        scale_c=scale,
        scaled_coefficients=tuple(float(v) for v in a),
        scaled_covariance=covariance,
    )


def _checked_points(temperatures_c: Any, frequencies_hz: Any,
                    order: Any) -> tuple[np.ndarray, np.ndarray, int]:
    """The points of :func:`fit` as flat float arrays and the order as an int, refused
    unless they determine a polynomial of that order."""
    t = np.asarray(temperatures_c, dtype=np.float64).ravel()
    f = np.asarray(frequencies_hz, dtype=np.float64).ravel()
    if not isinstance(order, (int, np.integer)) or order < 1:
        raise InputError(f"order must be a positive integer, got {order!r}")
    order = int(order)
    if t.size != f.size:
        raise InputError(
            f"temperatures_c has {t.size} values but frequencies_hz has {f.size}; "
            "give one frequency per temperature"
        )
    for name, values in (("temperatures_c", t), ("frequencies_hz", f)):
        bad = np.flatnonzero(~np.isfinite(values))
        if bad.size:
            raise InputError(f"{name}[{bad[0]}] is {values[bad[0]]}; remove non-finite points")
    distinct = np.unique(t).size
    if distinct < order + 1:
        raise InputError(
            f"{distinct} distinct temperature(s) cannot determine an order-{order} polynomial "
            f"(it needs at least {order + 1}, and {order + 2} or more to estimate its errors); "
            "add soaks or lower the order"
        )
    return t, f, order


def _least_squares(vandermonde: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Coefficients of ``vandermonde @ a = y`` by QR with one step of iterative
    refinement, and the factor ``r``; refused when the design is numerically singular."""
    order = vandermonde.shape[1] - 1
    q, r = np.linalg.qr(vandermonde)
    diag = np.abs(np.diag(r))
    if diag.min() <= diag.max() * 1e-13:
        raise InputError(
            f"the order-{order} design is numerically singular on these temperatures; "
            "lower the order or spread the soaks"
        )
    qty = q.T @ y
    a = np.linalg.solve(r, qty)
    # One step of iterative refinement on the residual.
    residual = y - vandermonde @ a
    a = a + np.linalg.solve(r, q.T @ residual)
    return a, r


def _errors(r: np.ndarray, matrix: list[list[Fraction]], rss: float, dof: int,
            ) -> tuple[tuple[float, ...], float, tuple[tuple[float, ...], ...] | None]:
    """Standard errors of the raw coefficients, residual standard deviation and covariance
    of the scaled ones, from the QR factor ``r`` of the scaled design; NaN (None for the
    covariance) when no degree of freedom is left. [Hz]"""
    order = r.shape[0] - 1
    if dof > 0:
        sigma2 = rss / dof
        r_inv = np.linalg.solve(r, np.eye(order + 1))
        cov_scaled = sigma2 * (r_inv @ r_inv.T)
        m = np.array([[float(v) for v in row] for row in matrix])
        cov_raw = m @ cov_scaled @ m.T
        standard_errors = tuple(float(np.sqrt(max(v, 0.0))) for v in np.diag(cov_raw))
        residual_std = float(np.sqrt(sigma2))
        covariance: tuple[tuple[float, ...], ...] | None = tuple(
            tuple(float(v) for v in row) for row in cov_scaled
        )
    else:
        standard_errors = tuple(float("nan") for _ in range(order + 1))
        residual_std = float("nan")
        covariance = None
    return standard_errors, residual_std, covariance
