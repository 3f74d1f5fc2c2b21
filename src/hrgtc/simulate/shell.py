"""Natural frequency of a thin hemispherical shell and its temperature coefficient.

The n-th flexural (wine-glass) mode of a thin hemispherical shell clamped at the
pole and free at the rim, by Rayleigh's energy method with inextensional mode
shapes, Eq. (1)-(15) of [1]:

    omega_n = n (n^2 - 1) h / r^2 * sqrt( E I(n) / (3 (1 + mu) rho J(n)) )

with the shape integrals I(n) and J(n) of Eq. (12). Every material and geometric
quantity depends on temperature, Eq. (15), which makes the frequency a
thermometer.

Note that the paper's "f" in Eq. (13)-(15) is the angular frequency omega
[rad/s]; every function here returns the frequency in Hz, omega / (2 pi).

[1] X. Wang, W. Wu, Z. Fang, B. Luo, Y. Li, Q. Jiang, "Temperature Drift
    Compensation for Hemispherical Resonator Gyro Based on Natural Frequency",
    Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434

"""

from __future__ import annotations

import dataclasses
import math
import numbers
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np
from numpy.typing import ArrayLike
from scipy.integrate import quad

from hrgtc.core import records
from hrgtc.core.errors import InputError

__all__ = [
    "DEFAULT_RADIUS_M",
    "DEFAULT_SHELL",
    "DEFAULT_THICKNESS_M",
    "FUSED_QUARTZ",
    "I",
    "J",
    "Material",
    "Shell",
    "frequency_temperature_coefficient",
    "natural_frequency",
    "shape_integral_i",
    "shape_integral_j",
]

_QUAD_EPSREL = 1e-13
_QUAD_LIMIT = 200
_ABSOLUTE_ZERO_C = -273.15


def _check_mode(n: Any) -> int:
    """Return the mode number as int, or raise InputError if it is not an integer >= 2."""
    if isinstance(n, bool) or not isinstance(n, numbers.Integral):
        raise InputError(
            f"n must be an integer mode number >= 2, got {n!r} ({type(n).__name__}); "
            "pass n=2 for the wine-glass mode of [1]"
        )
    if n < 2:
        raise InputError(
            f"n must be >= 2, got n={n}: n = 0 and n = 1 are rigid-body modes with no "
            "flexural frequency; pass n=2 for the wine-glass mode of [1]"
        )
    return int(n)


def _check_array(name: str, value: ArrayLike, unit: str, poisson: bool = False) -> np.ndarray:
    """Return ``value`` as float64 array; InputError unless all finite and > 0 (or a valid mu)."""
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InputError(
            f"{name} must be a number or array of numbers [{unit}], got {value!r}"
        ) from exc
    with np.errstate(invalid="ignore"):
        ok = (arr >= 0.0) & (arr < 0.5) if poisson else np.isfinite(arr) & (arr > 0.0)
    if not ok.all():
        first = float(arr.reshape(-1)[np.flatnonzero(~ok.reshape(-1))[0]])
        if poisson:
            raise InputError(
                f"{name} must satisfy 0 <= {name} < 0.5 for an isotropic solid, got {first!r} "
                "(fused quartz: 0.17)"
            )
        raise InputError(f"{name} must be finite and > 0 [{unit}], got {first!r}; pass SI units")
    return arr


def _check_finite_scalar(name: str, value: Any, unit: str) -> float:
    """Return ``value`` as float, raising InputError unless it is a finite real number."""
    try:
        out = float(value)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{name} must be a finite number [{unit}], got {value!r}") from exc
    if not math.isfinite(out):
        raise InputError(f"{name} must be a finite number [{unit}], got {value!r}")
    return out


def _as_output(arr: np.ndarray) -> float | np.ndarray:
    """Return a Python float for 0-d results and the array otherwise."""
    return float(arr) if arr.ndim == 0 else arr


@lru_cache(maxsize=64)
def _shape_integrals(n: int) -> tuple[float, float]:
    """I(n) and J(n) by adaptive quadrature (cached: they depend on n only)."""

    # tan(phi/2) = sin(phi) / (1 + cos(phi)), so sin^-3(phi) tan^2n(phi/2)
    # = sin^(2n-3)(phi) / (1 + cos(phi))^(2n): no 0/0 at phi -> 0 (the integrand
    # behaves like phi^(2n-3) / 2^(2n) and vanishes there for n >= 2).
    def integrand_i(phi: float) -> float:
        s, c = math.sin(phi), math.cos(phi)
        return s ** (2 * n - 3) / (1.0 + c) ** (2 * n)

    def integrand_j(phi: float) -> float:
        s, c = math.sin(phi), math.cos(phi)
        return ((n + c) ** 2 + 2.0 * s * s) * s * math.tan(0.5 * phi) ** (2 * n)

    opts = {"epsabs": 0.0, "epsrel": _QUAD_EPSREL, "limit": _QUAD_LIMIT}
    value_i, _ = quad(integrand_i, 0.0, 0.5 * math.pi, **opts)
    value_j, _ = quad(integrand_j, 0.0, 0.5 * math.pi, **opts)
    return value_i, value_j


def shape_integral_i(n: int = 2) -> float:
    """Shape integral I(n) of the strain energy, Eq. (12)-(14) of [1].

    .. math:: I(n) = \\int_0^{\\pi/2} \\sin^{-3}\\varphi \\, \\tan^{2n}(\\varphi/2) \\, d\\varphi

    Parameters
    ----------
    n
        Circumferential mode number, an integer >= 2. [-]

    Returns
    -------
    float
        I(n), dimensionless. I(2) = 7/24 exactly.

    Raises
    ------
    InputError
        If ``n`` is not an integer >= 2 (n = 0, 1 are rigid-body modes).

    Examples
    --------
    >>> abs(shape_integral_i(2) - 7 / 24) < 1e-14
    True
    """
    return _shape_integrals(_check_mode(n))[0]


def shape_integral_j(n: int = 2) -> float:
    """Shape integral J(n) of the kinetic energy, Eq. (12)-(14) of [1].

    .. math:: J(n) = \\int_0^{\\pi/2} \\{(n + \\cos\\varphi)^2 + 2\\sin^2\\varphi\\}
              \\sin\\varphi \\, \\tan^{2n}(\\varphi/2) \\, d\\varphi

    Eq. (14) of [1] prints ``(2 + cos phi)``: that is this integral at n = 2.

    Parameters
    ----------
    n
        Circumferential mode number, an integer >= 2. [-]

    Returns
    -------
    float
        J(n), dimensionless. J(2) = 1.5296102...

    Raises
    ------
    InputError
        If ``n`` is not an integer >= 2.

    Examples
    --------
    >>> round(shape_integral_j(2), 6)
    1.52961
    """
    return _shape_integrals(_check_mode(n))[1]


#: The issue's names for the shape integrals, I(n) and J(n).
I = shape_integral_i  # noqa: E741
J = shape_integral_j


def _frequency_hz_unchecked(radius_m, thickness_m, youngs_modulus_pa, poisson, density_kg_m3, n):
    """Eq. (13) of [1] divided by 2 pi, on validated float64 arrays (broadcasting)."""
    value_i, value_j = _shape_integrals(n)
    factor = n * (n * n - 1) * math.sqrt(value_i / (3.0 * value_j)) / (2.0 * math.pi)
    return (
        factor
        * thickness_m
        / (radius_m * radius_m)
        * np.sqrt(youngs_modulus_pa / ((1.0 + poisson) * density_kg_m3))
    )


def natural_frequency(
    radius_m: ArrayLike,
    thickness_m: ArrayLike,
    youngs_modulus_pa: ArrayLike,
    poisson: ArrayLike,
    density_kg_m3: ArrayLike,
    n: int = 2,
) -> float | np.ndarray:
    """Natural frequency of the n-th flexural mode of a hemispherical shell, Eq. (13) of [1].

    ``omega_n = n (n^2 - 1) h / r^2 * sqrt(E I(n) / (3 (1 + mu) rho J(n)))``; for n = 2
    this is Eq. (14). The paper's ``f`` in Eq. (13)-(14) is this angular frequency
    omega [rad/s]; the value returned here is omega / (2 pi) in Hz.

    All array arguments broadcast against each other (numpy rules).

    Parameters
    ----------
    radius_m
        Mean radius of the hemisphere, r. [m]
    thickness_m
        Wall thickness, h (thin shell: h << r). [m]
    youngs_modulus_pa
        Young's modulus, E. [Pa]
    poisson
        Poisson's ratio, mu, with 0 <= mu < 0.5. [-]
    density_kg_m3
        Density, rho. [kg/m³]
    n
        Circumferential mode number, integer >= 2 (2 is the gyro's wine-glass mode). [-]

    Returns
    -------
    float or numpy.ndarray
        Natural frequency. [Hz] A float when every input is a scalar.

    Raises
    ------
    InputError
        If a length, E or rho is not finite and positive, mu is outside [0, 0.5),
        or n is not an integer >= 2.

    Examples
    --------
    >>> round(natural_frequency(15e-3, 0.78e-3, 73.1e9, 0.17, 2203.0), 1)
    4444.6
    >>> natural_frequency(15e-3, [0.39e-3, 0.78e-3], 73.1e9, 0.17, 2203.0).round(1)
    array([2222.3, 4444.6])
    """
    n = _check_mode(n)
    r = _check_array("radius_m", radius_m, "m")
    h = _check_array("thickness_m", thickness_m, "m")
    e = _check_array("youngs_modulus_pa", youngs_modulus_pa, "Pa")
    mu = _check_array("poisson", poisson, "-", poisson=True)
    rho = _check_array("density_kg_m3", density_kg_m3, "kg/m³")
    return _as_output(np.asarray(_frequency_hz_unchecked(r, h, e, mu, rho, n)))


@dataclass(frozen=True)
class Material(records.Written):
    """An isotropic resonator material with linear temperature laws.

    Parameters
    ----------
    youngs_modulus_pa
        Young's modulus E0 at the reference temperature. [Pa]
    poisson
        Poisson's ratio mu0 at the reference temperature, 0 <= mu0 < 0.5. [-]
    density_kg_m3
        Density rho0 at the reference temperature. [kg/m³]
    youngs_tc_per_c
        Temperature coefficient of Young's modulus, (1/E) dE/dT. [1/°C]
    poisson_tc_per_c
        Temperature coefficient of Poisson's ratio, (1/mu) dmu/dT. [1/°C]
    expansion_per_c
        Linear thermal expansion coefficient alpha, (1/L) dL/dT. [1/°C]
    reference_temperature_c
        Temperature at which E0, mu0 and rho0 hold. [°C]
    name
        Free-text name of the material.
    """

    #: Its record (:data:`MaterialRecord`): a key it does not know is refused.
    forbid_unknown_fields = True

    youngs_modulus_pa: float
    poisson: float
    density_kg_m3: float
    youngs_tc_per_c: float = 0.0
    poisson_tc_per_c: float = 0.0
    expansion_per_c: float = 0.0
    reference_temperature_c: float = 20.0
    name: str = "custom"

    def __post_init__(self) -> None:
        units = {"youngs_modulus_pa": "Pa", "poisson": "-", "density_kg_m3": "kg/m³"}
        for field, unit in units.items():
            value = _check_array(field, getattr(self, field), unit, poisson=field == "poisson")
            if value.ndim:
                raise InputError(f"Material.{field} must be a scalar, got shape {value.shape}")
            object.__setattr__(self, field, float(value))
        for field in ("youngs_tc_per_c", "poisson_tc_per_c", "expansion_per_c"):
            object.__setattr__(
                self, field, _check_finite_scalar(field, getattr(self, field), "1/°C")
            )
        t_ref = _check_finite_scalar("reference_temperature_c", self.reference_temperature_c, "°C")
        if t_ref <= _ABSOLUTE_ZERO_C:
            raise InputError(f"reference_temperature_c must be above -273.15 °C, got {t_ref!r}")
        object.__setattr__(self, "reference_temperature_c", t_ref)
        object.__setattr__(self, "name", str(self.name))


#: The record of :class:`Material`, generated from its fields.
MaterialRecord = records.record_of(
    Material, doc="A :class:`Material` in the simulator's ground truth (its bounds are the "
    "material's\nown checks).")


#: Fused quartz (vitreous silica) near room temperature.
#: E, mu, rho and alpha: Crystran Ltd., "Handbook of infra-red and ultra-violet
#: optical materials", 5th ed. 2023, fused silica data sheet (E = 73.1 GPa,
#: mu = 0.17, rho = 2203 kg/m³, alpha = 0.55e-6 /K at 300 K); Corning 7980 lists
#: 72.7 GPa, 0.16, 2201 kg/m³, 0.52e-6 /K.
#: Temperature coefficients: E of vitreous silica rises with temperature from
#: about -190 °C to 1175 °C (Spinner & Cleek, J. Appl. Phys. 31, 1407, 1960).
#: Spinner (J. Am. Ceram. Soc. 45, 394, 1962, doi:10.1111/j.1151-2916.1962.tb11177.x)
#: finds roughly parabolic curves peaking near 1050-1200 °C, E about 11 % and the
#: shear modulus G about 9 % above their room-temperature values, and mu rising
#: from about 1/6 to about 1/5. Our estimate, reading those curves as parabolas
#: with the peak ~1105 K above 20 °C: (1/E) dE/dT = 2 * 0.11 / 1105 K = 2.0e-4 /K,
#: (1/G) dG/dT = 2 * 0.09 / 1105 K = 1.63e-4 /K, and, since 1 + mu = E / (2 G),
#: (1/mu) dmu/dT = (2.0e-4 - 1.63e-4) (1 + mu) / mu = 2.5e-4 /K. This is an
#: estimate from published curves, not a measured room-temperature slope; it gives
#: +82 ppm/°C, against +84 ppm/°C of the real unit of [1] (slope of Eq. 18 at 0 °C).
FUSED_QUARTZ = Material(
    youngs_modulus_pa=73.1e9,
    poisson=0.17,
    density_kg_m3=2203.0,
    youngs_tc_per_c=2.0e-4,
    poisson_tc_per_c=2.5e-4,
    expansion_per_c=0.55e-6,
    reference_temperature_c=20.0,
    name="fused quartz",
)


def frequency_temperature_coefficient(
    material: Material = FUSED_QUARTZ,
    temperature_c: ArrayLike | None = None,
    **overrides: float,
) -> float | np.ndarray:
    """Temperature coefficient of the natural frequency, (1/f) df/dT from Eq. (15) of [1].

    The logarithmic derivative of Eq. (15) under the linear temperature laws of
    :class:`Shell` (h and r grow with alpha, rho falls as (1 + alpha dT)^-3):

        (1/f) df/dT = (1/h) dh/dT - 2 (1/r) dr/dT
                      + 1/2 [ (1/E) dE/dT - (1/(1 + mu)) dmu/dT - (1/rho) drho/dT ]

    which at the reference temperature is ``alpha - 2 alpha + (tcE - mu tcmu / (1 + mu)
    + 3 alpha) / 2``. It does not depend on the geometry (r, h) nor on n.

    Parameters
    ----------
    material
        The resonator material. [-]
    temperature_c
        Temperature at which to evaluate the coefficient; None means the
        material's reference temperature. Arrays are accepted. [°C]
    **overrides
        Replace fields of ``material`` for this call, e.g. ``youngs_tc_per_c=1.5e-4``,
        ``poisson_tc_per_c``, ``expansion_per_c``, ``poisson``,
        ``reference_temperature_c`` (see :class:`Material`).

    Returns
    -------
    float or numpy.ndarray
        Frequency temperature coefficient. [ppm/°C]

    Raises
    ------
    InputError
        On an unknown override, an invalid material value, or a temperature at
        which the linear laws leave their physical range.

    Examples
    --------
    >>> round(frequency_temperature_coefficient(), 2)
    82.11
    >>> round(frequency_temperature_coefficient(youngs_tc_per_c=1.7e-4, poisson_tc_per_c=0.0), 3)
    85.275
    """
    if overrides:
        known = {f.name for f in dataclasses.fields(Material)}
        unknown = sorted(set(overrides) - known)
        if unknown:
            raise InputError(f"unknown material override(s) {unknown}; allowed: {sorted(known)}")
        material = dataclasses.replace(material, **overrides)
    m = material
    if temperature_c is None:
        temperature_c = m.reference_temperature_c
    dt = _temperature_offset(m, temperature_c)
    alpha, tce, tcmu = m.expansion_per_c, m.youngs_tc_per_c, m.poisson_tc_per_c
    length_scale = 1.0 + alpha * dt
    dlog_length = alpha / length_scale  # (1/h) dh/dT = (1/r) dr/dT
    dlog_e = tce / (1.0 + tce * dt)
    mu = m.poisson * (1.0 + tcmu * dt)
    dlog_one_plus_mu = m.poisson * tcmu / (1.0 + mu)
    dlog_rho = -3.0 * dlog_length
    tcf = dlog_length - 2.0 * dlog_length + 0.5 * (dlog_e - dlog_one_plus_mu - dlog_rho)
    return _as_output(np.asarray(tcf * 1e6))


def _temperature_offset(material: Material, temperature_c: ArrayLike) -> np.ndarray:
    """T - T_ref as float64 array, checking the linear laws stay physical there."""
    try:
        t = np.asarray(temperature_c, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InputError(
            f"temperature_c must be a number or array of numbers [°C], got {temperature_c!r}"
        ) from exc
    if t.size == 0:
        return t - material.reference_temperature_c
    t_min, t_max = float(np.min(t)), float(np.max(t))
    if not (math.isfinite(t_min) and math.isfinite(t_max)):
        raise InputError("temperature_c contains NaN or inf; pass finite temperatures [°C]")
    if t_min <= _ABSOLUTE_ZERO_C:
        raise InputError(f"temperature_c must be above -273.15 °C, got {t_min!r} °C")
    m = material
    for dt in (t_min - m.reference_temperature_c, t_max - m.reference_temperature_c):
        mu = m.poisson * (1.0 + m.poisson_tc_per_c * dt)
        if (
            1.0 + m.expansion_per_c * dt <= 0.0
            or 1.0 + m.youngs_tc_per_c * dt <= 0.0
            or not (0.0 <= mu < 0.5)
        ):
            raise InputError(
                f"temperature_c = {dt + m.reference_temperature_c!r} °C is outside the range "
                f"where the linear temperature laws of material {m.name!r} are physical "
                f"(mu(T) = {mu:.4g}); use temperatures nearer {m.reference_temperature_c} °C"
            )
    return t - m.reference_temperature_c


@dataclass(frozen=True)
class Shell(records.Written):
    """A hemispherical resonator shell: geometry, material and mode number.

    Parameters
    ----------
    radius_m
        Mean radius r0 at the material's reference temperature. [m]
    thickness_m
        Wall thickness h0 at the material's reference temperature. [m]
    material
        Resonator material with its temperature laws. [-]
    n
        Circumferential mode number, integer >= 2. [-]
    """

    #: Its record (:data:`ShellRecord`): a file names the material.
    required = ("material",)

    radius_m: float
    thickness_m: float
    material: Material = FUSED_QUARTZ
    n: int = 2

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        set_(self, "radius_m", float(_check_array("radius_m", self.radius_m, "m")))
        set_(self, "thickness_m", float(_check_array("thickness_m", self.thickness_m, "m")))
        if not isinstance(self.material, Material):
            raise InputError(
                f"material must be a hrgtc.simulate.shell.Material, "
                f"got {type(self.material).__name__}; "
                "build one with Material(youngs_modulus_pa=..., poisson=..., density_kg_m3=...)"
            )
        set_(self, "n", _check_mode(self.n))

    def frequency_hz(self, temperature_c: ArrayLike | None = None) -> float | np.ndarray:
        """Natural frequency at a resonator temperature, Eq. (15) of [1], in Hz.

        Eq. (15) with linear laws about the reference temperature T0
        (dT = T - T0, alpha the linear expansion coefficient):
        h(T) = h0 (1 + alpha dT), r(T) = r0 (1 + alpha dT),
        E(T) = E0 (1 + tcE dT), mu(T) = mu0 (1 + tcmu dT),
        rho(T) = rho0 / (1 + alpha dT)^3 (mass conserved). The paper's f is
        angular; this returns omega / (2 pi).

        Parameters
        ----------
        temperature_c
            Resonator temperature, scalar or array; None means the material's
            reference temperature. [°C]

        Returns
        -------
        float or numpy.ndarray
            Natural frequency, same shape as ``temperature_c``. [Hz]

        Raises
        ------
        InputError
            If a temperature is not finite or is where the linear laws leave
            their physical range.

        Examples
        --------
        >>> shell = Shell(15e-3, 0.78e-3, FUSED_QUARTZ)
        >>> shell.frequency_hz([-20.0, 20.0, 40.0]).round(2)
        array([4429.97, 4444.62, 4451.91])
        """
        m = self.material
        if temperature_c is None:
            temperature_c = m.reference_temperature_c
        dt = _temperature_offset(m, temperature_c)
        length_scale = 1.0 + m.expansion_per_c * dt
        freq = _frequency_hz_unchecked(
            self.radius_m * length_scale,
            self.thickness_m * length_scale,
            m.youngs_modulus_pa * (1.0 + m.youngs_tc_per_c * dt),
            m.poisson * (1.0 + m.poisson_tc_per_c * dt),
            m.density_kg_m3 / length_scale**3,
            self.n,
        )
        return _as_output(np.asarray(freq))


#: The record of :class:`Shell`, generated from its fields.
ShellRecord = records.record_of(
    Shell, doc="A :class:`Shell` in the simulator's ground truth (a ``shell`` frequency law).")


#: Geometry of the documented example (DESIGN.md): r = 15 mm, h = 0.78 mm. With
#: FUSED_QUARTZ it rings at 4444.6 Hz at 20 °C (the unit of [1]: 4432.07 Hz, Table 1).
DEFAULT_RADIUS_M = 15e-3
DEFAULT_THICKNESS_M = 0.78e-3
DEFAULT_SHELL = Shell(DEFAULT_RADIUS_M, DEFAULT_THICKNESS_M, FUSED_QUARTZ, n=2)
