"""A population prior for the thermometer: fewer soaks from what earlier units taught.

The paper calibrates every unit from seven soaks (Table 1 of [1]), about 40 h of
chamber time. Units of one design share their frequency law up to a small spread
(geometry moves f at 20 °C by tens of Hz, the material its relative temperature
coefficient by a few %), so the law of a new unit is known before its first soak
up to that spread. :class:`ThermometerPrior` holds it, :func:`fit_with_prior`
updates it with two or three soaks.

**Basis.** Every thermometer of the population is re-expressed in one scaled
variable z = (T - centre_c) / scale_c over the prior's temperature range,
f(T) = a0 (1 + b1 z + b2 z^2 + b3 z^3): ``a0`` (frequency at the centre) carries
the unit's nominal frequency, the relative coefficients ``b_k = a_k / a0`` its
shape, so units of different f0 share one prior. The prior is the population
mean and covariance of (b1, ..., bK); a0 gets a flat prior.

**Posterior.** With the soak points (T_i, f_i) of standard error s_i and the
prior scaled by the unit's a0 (a_k = a0 b_k; a0 is known from the data to
~1e-7 relative, so it is fixed at its estimate and refined once), the model is
linear in a = (a0, a1, ..., aK) and the Gaussian conjugate update is exact:
precision P = P_prior + X' W X, mean m = P^-1 (P_prior m_prior + X' W f). The
posterior covariance gives, through the inverse T(f) (delta method), the
temperature uncertainty sd_T(T) = sqrt(g(z)' C g(z)) / |f'(T)| over the range,
g(z) = (1, z, ..., z^K).

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path
from typing import Annotated, Any

import numpy as np
from msgspec import Meta

from hrgtc.core import records
from hrgtc.core.errors import CalibrationError, InputError
from hrgtc.core.summary import Figure, Summary
from hrgtc.thermometry.thermometer import Thermometer, _scaled_to_raw_matrix

__all__ = ["PriorFit", "ThermometerPrior", "fit_with_prior", "load_prior", "relative_coefficients"]

SCHEMA_NAME = "hrgtc.thermometer-prior"
SCHEMA_VERSION = 1
#: The basis the prior's coefficients are in (written into the file for its reader).
BASIS = "f(T) = a0 (1 + sum_k b_k z^k), z = (T - centre_c) / scale_c"
#: A unit whose soaks lie this far (in prior standard deviations) from the prior's
#: prediction is not of the prior's kind.
KIND_SIGMAS = 8.0
#: Soaks may lie this far outside the prior's temperature range. [°C]
RANGE_TOLERANCE_C = 1.0
#: Smallest standard error given to a soak point (plateau bias floor). [Hz]
MIN_POINT_STD_HZ = 2.0e-4


def scaled_in_basis(thermometer: Thermometer, centre_c: float, scale_c: float) -> np.ndarray:
    """A thermometer's polynomial in z = (T - centre_c) / scale_c, ascending. [Hz]

    Exact composition of the fitted polynomial in its own scaled variable with the
    affine map between the two variables (no resampling).
    """
    own = np.polynomial.Polynomial(np.asarray(thermometer.scaled_coefficients))
    shift = (centre_c - thermometer.centre_c) / thermometer.scale_c
    stretch = scale_c / thermometer.scale_c
    composed = own(np.polynomial.Polynomial([shift, stretch])).coef
    out = np.zeros(thermometer.order + 1)
    out[: composed.size] = composed
    return out


def relative_coefficients(thermometer: Thermometer, centre_c: float,
                          scale_c: float) -> tuple[float, np.ndarray]:
    """``(a0, b)``: frequency at ``centre_c`` [Hz] and relative scaled coefficients b_k = a_k/a0."""
    a = scaled_in_basis(thermometer, centre_c, scale_c)
    return float(a[0]), a[1:] / a[0]


@dataclass(frozen=True)
class ThermometerPrior(records.Written):
    """Mean and covariance of the relative scaled thermometer coefficients of a population.

    Attributes
    ----------
    order
        Polynomial order of f(T).
    centre_c, scale_c
        The basis z = (T - centre_c) / scale_c. [°C]
    temperature_range_c
        Range the population was calibrated over (where the prior holds). [°C]
    mean, covariance
        Mean (K,) and covariance (K, K) of b_1..b_K. [-]
    nominal_freq_hz, nominal_freq_std_hz
        Mean and standard deviation of a0, the frequency at ``centre_c``. [Hz]
    point_std_hz
        Median residual standard deviation of the population's fits: the error of
        one soak point beyond its own standard error. [Hz]
    units
        Names of the units the prior was built from.
    """

    #: Its record (:data:`ThermometerPriorRecord`, the prior file): ``schema`` first, the
    #: version and basis written for the reader (not read back), ``n_units`` derived.
    constants = (("schema", SCHEMA_NAME),)
    record_order = ("schema", "schema_version", "order", "centre_c", "scale_c",
                    "temperature_range_c", "basis", "mean", "covariance", "nominal_freq_hz",
                    "nominal_freq_std_hz", "point_std_hz", "n_units", "units")

    order: Annotated[int, Meta(ge=1, le=12)]
    centre_c: float
    scale_c: records.Positive
    temperature_range_c: records.Range
    mean: tuple[float, ...]
    covariance: tuple[tuple[float, ...], ...]
    nominal_freq_hz: float
    nominal_freq_std_hz: records.NonNegative
    point_std_hz: records.NonNegative
    units: tuple[str, ...] = field(default=())

    @records.derived(default=SCHEMA_VERSION)
    def schema_version(self) -> Annotated[int, Meta(ge=1, le=SCHEMA_VERSION)]:
        """The prior file's schema version."""
        return SCHEMA_VERSION

    @records.derived(default=BASIS)
    def basis(self) -> str:
        """What ``mean`` and ``covariance`` are coefficients of (text for the reader)."""
        return BASIS

    @records.derived(default=0)
    def n_units(self) -> records.Count:
        """Number of units behind the prior."""
        return len(self.units)

    @classmethod
    def from_thermometers(cls, thermometers: Sequence[Thermometer],
                          units: Sequence[str] | None = None) -> ThermometerPrior:
        """The population prior of calibrated units (at least ``order + 2`` of them).

        Raises
        ------
        InputError
            Too few units, mixed orders, or units whose ranges do not overlap.
        """
        if units is None:
            units = [f"unit-{k}" for k in range(len(thermometers))]
        if len(units) != len(thermometers):
            raise InputError(f"{len(units)} names for {len(thermometers)} thermometers")
        orders = sorted({th.order for th in thermometers})
        if len(orders) > 1:
            raise InputError(f"the units' thermometers have orders {orders}; give units of one "
                             "order (calibrated with the same --order)")
        order = orders[0] if orders else 3
        if len(thermometers) < order + 2:
            raise InputError(
                f"{len(thermometers)} unit(s) cannot estimate a {order}x{order} covariance; "
                f"give at least {order + 2} calibrated units (a few tens is better)")
        low = max(th.temperature_range_c[0] for th in thermometers)
        high = min(th.temperature_range_c[1] for th in thermometers)
        if not high > low:
            raise InputError("the units' calibrated temperature ranges do not overlap; "
                             "build a prior from units calibrated over one range")
        centre, scale = 0.5 * (low + high), 0.5 * (high - low)
        pairs = [relative_coefficients(th, centre, scale) for th in thermometers]
        a0 = np.array([p[0] for p in pairs])
        b = np.array([p[1] for p in pairs])
        residuals = [th.residual_std_hz for th in thermometers
                     if math.isfinite(th.residual_std_hz)]
        return cls(
            order=order, centre_c=centre, scale_c=scale, temperature_range_c=(low, high),
            mean=tuple(float(v) for v in b.mean(axis=0)),
            covariance=tuple(tuple(float(v) for v in row)
                             for row in np.atleast_2d(np.cov(b, rowvar=False))),
            nominal_freq_hz=float(a0.mean()), nominal_freq_std_hz=float(a0.std(ddof=1)),
            point_std_hz=float(np.median(residuals)) if residuals else MIN_POINT_STD_HZ,
            units=tuple(str(u) for u in units),
        )

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], source: str = "prior") -> ThermometerPrior:
        """Inverse of :meth:`to_dict` (checked against :class:`ThermometerPriorRecord`)."""
        if not isinstance(data, Mapping) or data.get("schema") != SCHEMA_NAME:
            raise InputError(f"{source}: not an hrgtc prior file; create one with "
                             "'hrgtc fleet prior MODELS -o prior.json'")
        try:
            return records.load(data, cls)  # type: ignore[no-any-return]
        except InputError as exc:
            raise InputError(f"{source}: prior file is corrupt: {exc}") from None

    def summary(self) -> Summary:
        """The units, order and range, the nominal frequency ± its spread and each
        normalised coefficient's mean ± its relative spread (its text: one line)."""
        sd = np.sqrt(np.diag(np.asarray(self.covariance)))
        figures = [Figure("n_units", "units", self.n_units), Figure("order", "order", self.order),
                   Figure("temperature_range_c", "temperatures",
                          self.temperature_range_c[1] - self.temperature_range_c[0], "°C",
                          tuple(self.temperature_range_c), "range"),
                   Figure("centre_c", "centre", self.centre_c, "°C"),
                   Figure("nominal_freq_hz", "f at the centre", self.nominal_freq_hz, "Hz",
                          definition="Mean over the units of their frequency at the centre."),
                   Figure("nominal_freq_std_hz", "its spread", self.nominal_freq_std_hz, "Hz",
                          definition="Standard deviation over the units of that frequency.")]
        for k, (m, s) in enumerate(zip(self.mean, sd, strict=True)):
            figures += [Figure(f"mean[{k}]", f"b{k + 1}", float(m),
                               definition=f"Mean over the units of the normalised "
                               f"coefficient b{k + 1}."),
                        Figure(f"relative_sd[{k}]", f"b{k + 1} relative spread",
                               float(s / abs(m)), spec=".2%")]
        rel = ", ".join(f"b{k + 1} {{mean[{k}]:.6g}} ± {{relative_sd[{k}]:.2%}}"
                        for k in range(len(self.mean)))
        low, high = self.temperature_range_c
        return Summary(f"prior of {self.n_units} units", (("prior", tuple(figures)),), layout=(
            f"prior of {{n_units}} units, order {{order}}, {low:g} to {high:g} °C: "
            "f({centre_c:g} °C) {nominal_freq_hz:.3f} ± {nominal_freq_std_hz:.3f} Hz; " + rel,))


def save_prior(prior: ThermometerPrior, path: str | os.PathLike[str],
               force: bool = False) -> Path:
    """Write the prior file atomically (refuses to overwrite without ``force``)."""
    from hrgtc.core.files import write_text_atomic

    return write_text_atomic(path, json.dumps(prior.to_dict(), indent=2) + "\n", force=force)


def load_prior(path: str | os.PathLike[str]) -> ThermometerPrior:
    """Read a prior file written by :func:`save_prior` (``hrgtc fleet prior``)."""
    try:
        data = json.loads(Path(path).read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise InputError(f"{path}: no such prior file") from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise InputError(f"{path}: cannot read the prior file: {exc}") from exc
    return ThermometerPrior.from_dict(data, source=str(path))


@dataclass(frozen=True)
class PriorFit(records.Dumped):
    """A thermometer fitted with a population prior (the result of :func:`fit_with_prior`).

    Attributes
    ----------
    thermometer
        The posterior-mean f(T), valid over the prior's range; its
        ``scaled_covariance`` is the posterior covariance. [Hz]
    prior
        The prior used.
    temperatures_c, frequencies_hz, point_std_hz
        The soak points and the standard error given to each. [°C, Hz, Hz]
    max_sigma
        Largest standardised distance of a soak point from the prior's prediction.
    """

    #: Its record (:data:`PriorFitRecord`, in ``calibrate --prior --json``; written only):
    #: the prior's size, the points and the uncertainty they leave, not the two fits.
    not_written = ("thermometer", "prior")
    record_order = ("prior_units", "temperatures_c", "frequencies_hz", "point_std_hz",
                    "max_sigma", "max_temperature_std_c", "temperature_band")

    thermometer: Thermometer
    prior: ThermometerPrior
    temperatures_c: tuple[float, ...]
    frequencies_hz: tuple[float, ...]
    point_std_hz: tuple[float, ...]
    max_sigma: records.Statistic

    @records.derived
    def prior_units(self) -> records.Count:
        """Units behind the prior."""
        return self.prior.n_units

    @records.derived
    def temperature_band(self) -> dict[str, tuple[records.Statistic, ...]]:
        """:meth:`band` at 13 temperatures (what the JSON document shows). [°C]"""
        return self.band(13)

    def temperature_std_c(self, temperature_c: Any) -> np.ndarray:
        """1-sigma uncertainty of the temperature read from frequency (delta method). [°C]"""
        th = self.thermometer
        z = (np.asarray(temperature_c, dtype=np.float64) - th.centre_c) / th.scale_c
        g = np.stack([z**k for k in range(th.order + 1)], axis=-1)
        cov = np.asarray(th.scaled_covariance)
        var_f = np.einsum("...i,ij,...j->...", g, cov, g)
        return np.sqrt(np.maximum(var_f, 0.0)) / np.abs(th.slope_hz_per_c(temperature_c))

    def band(self, points: int = 61) -> dict[str, list[float]]:
        """Temperature uncertainty over the prior's range: ``{"temperature_c", "std_c"}``."""
        t = np.linspace(*self.prior.temperature_range_c, points)
        return {"temperature_c": t.tolist(), "std_c": self.temperature_std_c(t).tolist()}

    @records.derived
    def max_temperature_std_c(self) -> records.Statistic:
        """Largest 1-sigma temperature uncertainty over the prior's range. [°C]"""
        return float(np.max(self.band()["std_c"]))



#: The record of :class:`ThermometerPrior` (its file), generated from its fields.
ThermometerPriorRecord = records.record_of(
    ThermometerPrior, doc="A :class:`ThermometerPrior` in its file (``hrgtc fleet prior``): "
    "field names and\nbounds, from which its ``to_dict``/``from_dict`` and its JSON Schema "
    "are generated.")


#: The record of :class:`PriorFit`, generated from its fields and figures.
PriorFitRecord = records.record_of(
    PriorFit, doc="A :class:`PriorFit` in a JSON document (``calibrate --prior --json``); "
    "written only.")


#: JSON Schema (Draft 2020-12) of the prior file, generated from :class:`ThermometerPriorRecord`.
PRIOR_JSON_SCHEMA: dict[str, Any] = records.json_schema(
    ThermometerPriorRecord, "hrgtc thermometer prior",
    "https://hrgtc.invalid/schema/thermometer-prior.json")


def _design(z: np.ndarray, order: int) -> np.ndarray:
    return np.vander(z, order + 1, increasing=True)


def _check_kind(prior: ThermometerPrior, t: np.ndarray, f: np.ndarray, order: int | None) -> None:
    if order is not None and order != prior.order:
        raise InputError(f"the prior is of order {prior.order} but order {order} was asked; "
                         "drop --order or build a prior of that order")
    low, high = prior.temperature_range_c
    outside = t[(t < low - RANGE_TOLERANCE_C) | (t > high + RANGE_TOLERANCE_C)]
    if outside.size:
        raise InputError(
            f"soak at {outside[0]:g} °C is outside the prior's range {low:g} to {high:g} °C: "
            "the prior says nothing there; soak inside its range or build a prior over it")


def fit_with_prior(temperatures_c: Any, frequencies_hz: Any, prior: ThermometerPrior,
                   frequency_std_hz: Any = None, order: int | None = None) -> PriorFit:
    """Posterior thermometer from a few soak points and a population prior (module docstring).

    Parameters
    ----------
    temperatures_c
        Soak temperatures (two or more distinct ones). [°C]
    frequencies_hz
        Settled frequency of each soak. [Hz]
    prior
        The population prior (:class:`ThermometerPrior`).
    frequency_std_hz
        Standard error of each settled frequency (scalar or one per point); the
        prior's ``point_std_hz`` is added in quadrature. Default: that alone. [Hz]
    order
        Expected order (checked against the prior's); None takes the prior's.

    Returns
    -------
    PriorFit

    Raises
    ------
    InputError
        Fewer than two distinct temperatures, soaks outside the prior's range, or a
        unit of another kind than the prior's (nominal frequency or temperature
        coefficient many standard deviations away): the message says which.
    """
    t = np.asarray(temperatures_c, dtype=np.float64).ravel()
    f = np.asarray(frequencies_hz, dtype=np.float64).ravel()
    if t.size != f.size or not (np.all(np.isfinite(t)) and np.all(np.isfinite(f))):
        raise InputError("give one finite frequency per finite temperature")
    if np.unique(t).size < 2:
        raise InputError(f"{np.unique(t).size} distinct soak temperature(s): a prior fit needs "
                         "at least 2 (a soak near each end of the range is best)")
    _check_kind(prior, t, f, order)
    k = prior.order
    own = np.zeros(t.size) if frequency_std_hz is None else np.broadcast_to(
        np.asarray(frequency_std_hz, dtype=np.float64), t.shape)
    s = np.sqrt(np.nan_to_num(own, nan=0.0) ** 2
                + max(prior.point_std_hz, MIN_POINT_STD_HZ) ** 2)
    z = (t - prior.centre_c) / prior.scale_c
    x = _design(z, k)
    w = 1.0 / s**2
    mean_b = np.asarray(prior.mean)
    cov_b = np.asarray(prior.covariance)
    shape = x @ np.concatenate([[1.0], mean_b])  # prior-mean law per unit a0
    a0 = float(np.sum(w * shape * f) / np.sum(w * shape**2))
    if abs(a0 - prior.nominal_freq_hz) > max(KIND_SIGMAS * prior.nominal_freq_std_hz,
                                             0.01 * prior.nominal_freq_hz):
        raise InputError(
            f"this unit rings at {a0:.2f} Hz at {prior.centre_c:g} °C but the prior's "
            f"{prior.n_units} units at {prior.nominal_freq_hz:.2f} ± "
            f"{prior.nominal_freq_std_hz:.2f} Hz: they differ in kind (another design or "
            "mode), so their prior does not apply; calibrate with 4 or more soaks")
    a, covariance = _posterior(x, w, f, a0, mean_b, cov_b)
    a0 = float(a[0])
    # Distance of each point from the prior's prediction (a0 from the data).
    predicted_var = a0**2 * np.einsum("ij,jk,ik->i", x[:, 1:], cov_b, x[:, 1:]) + s**2
    sigma = np.abs(f - a0 * shape) / np.sqrt(predicted_var)
    worst = int(np.argmax(sigma))
    if sigma[worst] > KIND_SIGMAS:
        raise InputError(
            f"the soak at {t[worst]:g} °C is {sigma[worst]:.0f} standard deviations from the "
            f"prior's law (relative temperature coefficient unlike its {prior.n_units} units): "
            "the unit differs in kind, so the prior does not apply; calibrate with 4 or more "
            "soaks")
    thermometer = _thermometer(a, covariance, prior, t, f)
    if not thermometer.is_monotonic:
        raise CalibrationError("the posterior f(T) is not monotonic over the prior's range; "
                               "check the soaks")
    return PriorFit(thermometer, prior, tuple(map(float, t)), tuple(map(float, f)),
                    tuple(map(float, s)), float(sigma.max()))


def _posterior(x: np.ndarray, w: np.ndarray, f: np.ndarray, a0: float, mean_b: np.ndarray,
               cov_b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Posterior mean and covariance of the scaled coefficients (module docstring).

    The prior on the relative coefficients ``b`` becomes one on ``a = a0 * (1, b)`` with
    ``a0`` fixed at its estimate, refined once from the first posterior.
    """
    k = x.shape[1] - 1
    precision_b = np.linalg.inv(cov_b)
    for _ in range(2):  # a0 fixed at its estimate, refined once
        prior_precision = np.zeros((k + 1, k + 1))
        prior_precision[1:, 1:] = precision_b / a0**2
        prior_mean = np.concatenate([[0.0], a0 * mean_b])
        precision = prior_precision + x.T @ (w[:, None] * x)
        covariance = np.linalg.inv(precision)
        covariance = 0.5 * (covariance + covariance.T)
        a = covariance @ (prior_precision @ prior_mean + x.T @ (w * f))
        a0 = float(a[0])
    return a, covariance


def _thermometer(a: np.ndarray, covariance: np.ndarray, prior: ThermometerPrior,
                 t: np.ndarray, f: np.ndarray) -> Thermometer:
    """The posterior as a :class:`Thermometer` over the prior's range."""
    k = prior.order
    matrix = _scaled_to_raw_matrix(k, prior.centre_c, prior.scale_c)
    exact = [Fraction(float(v)) for v in a]
    raw = tuple(float(sum((matrix[j][i] * exact[i] for i in range(k + 1)), Fraction(0)))
                for j in range(k + 1))
    m = np.array([[float(v) for v in row] for row in matrix])
    cov_raw = m @ covariance @ m.T
    fitted = _design((t - prior.centre_c) / prior.scale_c, k) @ a
    residual = f - fitted
    tss = float(np.sum((f - f.mean()) ** 2))
    return Thermometer(
        coefficients=raw,
        standard_errors=tuple(float(np.sqrt(max(v, 0.0))) for v in np.diag(cov_raw)),
        residual_std_hz=float(np.sqrt(np.mean(residual**2))),
        rsquared=1.0 - float(residual @ residual) / tss if tss > 0 else float("nan"),
        temperature_range_c=prior.temperature_range_c,
        order=k, n_points=int(t.size), centre_c=prior.centre_c, scale_c=prior.scale_c,
        scaled_coefficients=tuple(float(v) for v in a),
        scaled_covariance=tuple(tuple(float(v) for v in row) for row in covariance),
    )
