"""Frequency and bias laws of a simulated gyro, in physical variables.

Frequency: the natural frequency as a function of the resonator temperature,
either a polynomial (by default the cubic of Eq. (17)-(18) of [1] fitted to
Table 1 at full precision, :func:`table1_frequency_law`) or the shell model of
Eq. (15) of [1] with material temperature coefficients (:class:`ShellFrequencyLaw`).

Scale factor: the error of the scale factor in ppm as a polynomial in the
resonator temperature (:class:`ScaleFactorLaw`); the output is
``rate = input (1 + k 1e-6) + bias + noise``.

Bias: the simulator's own law in resonator temperature ``T_r`` and the
housing - resonator gradient ``G = T_h - T_r`` (:class:`BiasLaw`), not Eq. (21)
of [1]: since ``f`` is a smooth monotonic function of ``T_r`` (Eq. 18) and
``df/dt = f'(T_r) dT_r/dt = f'(T_r) G / tau_r`` (:mod:`hrgtc.simulate.thermal`),
the paper's polynomial in ``f`` and ``df/dt`` (Eq. 21-22) can fit it closely
but not exactly.

[1] X. Wang, W. Wu, Z. Fang, B. Luo, Y. Li, Q. Jiang, "Temperature Drift
    Compensation for Hemispherical Resonator Gyro Based on Natural Frequency",
    Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Annotated, Any, ClassVar, Protocol

import numpy as np
from msgspec import Meta
from numba import njit
from numpy.polynomial import Polynomial

from hrgtc.core import records
from hrgtc.core.errors import InputError
from hrgtc.simulate.shell import Shell

__all__ = [
    "BiasLaw",
    "FrequencyLaw",
    "PolynomialFrequencyLaw",
    "ScaleFactorLaw",
    "ShellFrequencyLaw",
    "frequency_law_from_dict",
    "play_operator",
    "table1_frequency_law",
]


class FrequencyLaw(Protocol):
    """Natural frequency of the resonator as a function of its temperature."""

    def frequency_hz(self, temperature_c: np.ndarray) -> np.ndarray:
        """Natural frequency. [Hz]"""
        ...

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON types."""
        ...


@dataclass(frozen=True)
class PolynomialFrequencyLaw(records.Written):
    """``f(T) = sum_k c_k T^k``, the Taylor form of Eq. (17) of [1].

    Parameters
    ----------
    coefficients
        Coefficients in ascending powers of T: ``(c0, c1, c2, c3)`` in Hz,
        Hz/°C, Hz/°C², Hz/°C³. [Hz/°C^k]
    source
        Where the coefficients come from.
    """

    #: Its record: a member of :data:`FrequencyLawRecord`, told by ``kind`` (written first).
    tag = ("kind", "polynomial")

    coefficients: Annotated[tuple[float, ...], Meta(min_length=1)]
    source: str = ""

    def __post_init__(self) -> None:
        coefficients = tuple(float(c) for c in self.coefficients)
        if not coefficients or not all(math.isfinite(c) for c in coefficients):
            raise InputError(f"coefficients must be finite numbers, got {self.coefficients!r}")
        object.__setattr__(self, "coefficients", coefficients)

    def frequency_hz(self, temperature_c: np.ndarray) -> np.ndarray:
        """Natural frequency at a resonator temperature (Horner). [Hz]"""
        t = np.asarray(temperature_c, dtype=np.float64)
        out = np.full(t.shape, self.coefficients[-1])
        for c in self.coefficients[-2::-1]:
            out *= t
            out += c
        return out


#: The record of :class:`PolynomialFrequencyLaw`, generated from its fields.
PolynomialFrequencyLawRecord = records.record_of(
    PolynomialFrequencyLaw, doc="A :class:`PolynomialFrequencyLaw` in the simulator's ground "
    "truth (``kind``\n``polynomial``, written first: the tag of :data:`FrequencyLawRecord`).")


def table1_frequency_law() -> PolynomialFrequencyLaw:
    """Eq. (18) of [1] at full precision: the least-squares cubic through Table 1.

    Examples
    --------
    >>> law = table1_frequency_law()
    >>> [round(c, 9) for c in law.coefficients]
    [4424.900952381, 0.371555556, -0.000970238, 1.5278e-05]
    """
    from hrgtc.thermometry.paper import TABLE1_FREQUENCY_HZ, TABLE1_TEMPERATURE_C

    poly = Polynomial.fit(TABLE1_TEMPERATURE_C, TABLE1_FREQUENCY_HZ, 3).convert()
    return PolynomialFrequencyLaw(
        tuple(float(c) for c in poly.coef), source="Eq. (18) of [1]: cubic fit to Table 1"
    )


@dataclass(frozen=True)
class ShellFrequencyLaw(records.Written):
    """Natural frequency from the shell model, Eq. (15) of [1] (:class:`~.shell.Shell`).

    Parameters
    ----------
    shell
        Geometry and material (with its temperature coefficients).
    """

    #: Its record: a member of :data:`FrequencyLawRecord`, told by ``kind``.
    tag = ("kind", "shell")

    shell: Shell

    def frequency_hz(self, temperature_c: np.ndarray) -> np.ndarray:
        """Natural frequency at a resonator temperature, Eq. (15) of [1]. [Hz]"""
        return np.asarray(self.shell.frequency_hz(np.asarray(temperature_c, dtype=np.float64)))


#: The record of :class:`ShellFrequencyLaw`, generated from its fields.
ShellFrequencyLawRecord = records.record_of(
    ShellFrequencyLaw, doc="A :class:`ShellFrequencyLaw` in the simulator's ground truth "
    "(``kind`` ``shell``).")


#: A frequency law in a unit's ground truth: one of the two kinds, told by its ``kind``
#: (a msgspec tagged union; its JSON Schema has a ``discriminator``).
FrequencyLawRecord = PolynomialFrequencyLawRecord | ShellFrequencyLawRecord


def frequency_law_from_dict(data: Mapping[str, Any]) -> FrequencyLaw:
    """A frequency law from its :meth:`to_dict` form (``kind`` polynomial or shell)."""
    kinds: dict[str, Any] = {
        record.__struct_config__.tag: law
        for record, law in ((PolynomialFrequencyLawRecord, PolynomialFrequencyLaw),
                            (ShellFrequencyLawRecord, ShellFrequencyLaw))
    }
    kind = data.get("kind") if isinstance(data, Mapping) else None
    if kind not in kinds:
        raise InputError(f"frequency law kind {kind!r} is unknown; use one of {sorted(kinds)}")
    return kinds[kind].from_dict(data)


@dataclass(frozen=True)
class ScaleFactorLaw(records.Written):
    """Scale-factor error against resonator temperature, a polynomial in ``T_r - T0``.

    .. math::

        k(T_r) = \\sum_{j=0}^{n} k_j (T_r - T_0)^j \\quad [\\mathrm{ppm}],
        \\qquad \\Omega_{out} = \\Omega_{in} (1 + 10^{-6} k) + B + \\text{noise}

    The simulator's own law (IEEE Std 1431 thermal tests characterise the scale
    factor against temperature; [1] models the bias only).

    Parameters
    ----------
    coefficients_ppm
        ``(k0, k1, k2, ...)``: coefficients of (T_r - T0)^j. [ppm/°C^j]
    reference_c
        Reference temperature T0. [°C]

    Examples
    --------
    >>> law = ScaleFactorLaw((120.0, 4.0, 0.05), reference_c=20.0)
    >>> law.ppm(np.array([20.0, 30.0])).tolist()
    [120.0, 165.0]
    """

    coefficients_ppm: Annotated[tuple[float, ...], Meta(min_length=1)]
    reference_c: float = 20.0

    def __post_init__(self) -> None:
        coefficients = tuple(float(c) for c in self.coefficients_ppm)
        if not coefficients or not all(math.isfinite(c) for c in coefficients):
            raise InputError(
                f"coefficients_ppm must be finite numbers, got {self.coefficients_ppm!r}"
            )
        reference = float(self.reference_c)
        if not math.isfinite(reference):
            raise InputError(f"reference_c must be finite [°C], got {self.reference_c!r}")
        object.__setattr__(self, "coefficients_ppm", coefficients)
        object.__setattr__(self, "reference_c", reference)

    def ppm(self, resonator_c: np.ndarray) -> np.ndarray:
        """Scale-factor error at a resonator temperature (Horner). [ppm]

        Parameters
        ----------
        resonator_c
            Resonator temperature. [°C]
        """
        dt = np.asarray(resonator_c, dtype=np.float64) - self.reference_c
        out = np.full(dt.shape, self.coefficients_ppm[-1])
        for c in self.coefficients_ppm[-2::-1]:
            out *= dt
            out += c
        return out


#: The record of :class:`ScaleFactorLaw` (nested in other records).
ScaleFactorLawRecord = records.record_of(ScaleFactorLaw)


@dataclass(frozen=True)
class BiasLaw(records.Written):
    """Thermal bias in resonator temperature and housing - resonator gradient.

    .. math::

        B = B_0 + \\sum_{k=1}^{3} c_k (T_r - T_0)^k + g\\,G + g_T (T_r - T_0)\\,G
            + h \\tanh(G / G_h) + s\\,(p - T_r), \\qquad G = T_h - T_r

    The gradient terms make the bias depend on the rate of change of the
    resonator temperature (``G = tau_r dT_r/dt``); the tanh term is a
    heating/cooling hysteresis (a different offset while warming, G > 0, than
    while cooling, G < 0) that saturates: a lag, no memory. The play term is a true
    memory: ``p`` is a play (backlash) operator of width ``w`` on the resonator
    temperature (:func:`play_operator`), whose state a chunk hands to the next
    (:meth:`play_dph`): settled after coming down by at least ``w`` it reads ``+s w/2``,
    after coming up ``-s w/2``, at any ramp rate. Its state at power-on is
    ``p = T_r(0) + play_initial_offset_c`` (the unit's past, which a model does not know).

    Parameters
    ----------
    bias0_dph
        Constant bias B0 at the reference temperature, no gradient. [°/h]
    reference_c
        Reference temperature T0. [°C]
    temperature_dph
        ``(c1, c2, c3)``: coefficients of (T_r - T0)^k. [°/h/°C^k]
    gradient_dph_per_c
        g: sensitivity to the gradient. [°/h/°C]
    gradient_temperature_dph_per_c2
        g_T: change of the gradient sensitivity with temperature. [°/h/°C²]
    hysteresis_dph
        h: half the heating - cooling offset. [°/h]
    hysteresis_width_c
        G_h: gradient over which the hysteresis switches. [°C]
    play_dph_per_c
        s: bias per °C of the play's lag p - T_r. [°/h/°C]
    play_width_c
        w: the play's width; 0 for no play. [°C]
    play_initial_offset_c
        p - T_r at power-on, within ±w/2. [°C]
    """

    bias0_dph: float
    reference_c: float = 20.0
    temperature_dph: tuple[float, float, float] = (0.0, 0.0, 0.0)
    gradient_dph_per_c: float = 0.0
    gradient_temperature_dph_per_c2: float = 0.0
    hysteresis_dph: float = 0.0
    hysteresis_width_c: records.Positive = 1.0
    play_dph_per_c: float = 0.0
    play_width_c: records.NonNegative = 0.0
    play_initial_offset_c: float = 0.0

    # written only by a unit with a play (the other units' ground truth unchanged)
    omit_when_default: ClassVar[tuple[str, ...]] = (
        "play_dph_per_c", "play_width_c", "play_initial_offset_c")

    def __post_init__(self) -> None:
        temperature = tuple(float(c) for c in self.temperature_dph)
        if len(temperature) != 3:
            raise InputError(
                f"temperature_dph must be (c1, c2, c3), got {self.temperature_dph!r}"
            )
        object.__setattr__(self, "temperature_dph", temperature)
        values = (
            self.bias0_dph,
            self.reference_c,
            self.gradient_dph_per_c,
            self.gradient_temperature_dph_per_c2,
            self.hysteresis_dph,
            *temperature,
        )
        if not all(math.isfinite(float(v)) for v in values):
            raise InputError(f"BiasLaw coefficients must be finite, got {self!r}")
        if not (math.isfinite(self.hysteresis_width_c) and self.hysteresis_width_c > 0):
            raise InputError(
                f"hysteresis_width_c must be > 0 [°C], got {self.hysteresis_width_c!r}"
            )
        slope, width, offset = (float(v) for v in (self.play_dph_per_c, self.play_width_c,
                                                   self.play_initial_offset_c))
        if not (math.isfinite(slope) and math.isfinite(width) and width >= 0.0):
            raise InputError(f"the play needs a finite play_dph_per_c and play_width_c >= 0 "
                             f"[°C], got {self.play_dph_per_c!r}, {self.play_width_c!r}")
        if not (math.isfinite(offset) and abs(offset) <= 0.5 * width):
            raise InputError(f"play_initial_offset_c must be within ±play_width_c/2 = "
                             f"±{0.5 * width:g} °C, got {self.play_initial_offset_c!r}")

    def bias_dph(self, resonator_c: np.ndarray, housing_c: np.ndarray) -> np.ndarray:
        """Thermal bias (noise-free), B0 included. [°/h]

        Parameters
        ----------
        resonator_c
            Resonator temperature. [°C]
        housing_c
            Housing temperature. [°C]
        """
        dt = np.asarray(resonator_c, dtype=np.float64) - self.reference_c
        gradient = np.asarray(housing_c, dtype=np.float64) - resonator_c
        # ((c3 dt + c2) dt + c1 + g_T G) dt, skipping zero terms (runs on every sample).
        c1, c2, c3 = self.temperature_dph
        if c3:
            out = c3 * dt
            out += c2
            out *= dt
        else:
            out = c2 * dt
        out += c1
        if self.gradient_temperature_dph_per_c2:
            out += self.gradient_temperature_dph_per_c2 * gradient
        out *= dt
        if self.gradient_dph_per_c:
            out += self.gradient_dph_per_c * gradient
        out += self.bias0_dph
        if self.hysteresis_dph:
            gradient /= self.hysteresis_width_c
            out += self.hysteresis_dph * np.tanh(gradient, out=gradient)
        return out

    @property
    def has_play(self) -> bool:
        """Whether the law has a play memory (``play_width_c`` > 0)."""
        return self.play_width_c > 0.0

    def play_state(self, resonator_c: float) -> float:
        """The play's state at power-on, at the first resonator temperature. [°C]"""
        return float(resonator_c) + self.play_initial_offset_c

    def play_dph(self, resonator_c: np.ndarray, state: float) -> tuple[np.ndarray, float]:
        """The play's part ``s (p - T_r)`` of the bias over a chunk (not in
        :meth:`bias_dph`, which has no memory), and the state after it. [°/h], [°C]

        Parameters
        ----------
        resonator_c
            Resonator temperature. [°C]
        state
            The play's output before the chunk (:meth:`play_state` at power-on). [°C]
        """
        resonator = np.asarray(resonator_c, dtype=np.float64)
        played, last = play_operator(resonator, self.play_width_c, state)
        played -= resonator
        played *= self.play_dph_per_c
        return played, last

#: The record of :class:`BiasLaw` (nested in other records).
BiasLawRecord = records.record_of(BiasLaw)


@njit(cache=True, nogil=True)
def _play_loop(x, half_width, state, out):  # pragma: no cover - compiled
    p = state
    for i in range(x.size):
        low = x[i] - half_width
        high = x[i] + half_width
        if p < low:
            p = low
        elif p > high:
            p = high
        out[i] = p
    return p


def play_operator(x: np.ndarray, width: float, state: float) -> tuple[np.ndarray, float]:
    """The play (backlash) operator of width ``w`` over a sequence, from a state.

    ``p[k] = min(max(p[k-1], x[k] - w/2), x[k] + w/2)``: the output stays where it
    was until the input pushes it from one side, so it remembers which way the input
    came from (rate-independent memory, unlike a lag). A settled input ``x`` reads
    ``p = x + w/2`` when it came down to ``x`` (by at least ``w``) and ``x - w/2``
    when it came up.

    Parameters
    ----------
    x
        The input (a temperature). [°C]
    width
        The play's width w >= 0. [°C]
    state
        The output before the first sample (``p[-1]``). [°C]

    Returns
    -------
    out, last : numpy.ndarray, float
        The output at each sample and the state after the last (carried to the next chunk).

    Examples
    --------
    >>> out, last = play_operator(np.array([0.0, 1.0, 3.0, 2.5, 1.0]), 2.0, 0.0)
    >>> out.tolist(), last
    ([0.0, 0.0, 2.0, 2.0, 2.0], 2.0)
    """
    x = np.ascontiguousarray(x, dtype=np.float64)
    out = np.empty_like(x)
    last = _play_loop(x, 0.5 * float(width), float(state), out)
    return out, float(last)
