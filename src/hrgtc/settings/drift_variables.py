"""The drift variables as the command line knows them: their names, in the grammar's
order, and the options each declares.

A drift variable is one module of :mod:`hrgtc.drift.variables` (its numpy reference, its
C, its keys of the parameter file); those modules load numpy, and ``hrgtc --help`` must
not. What the settings need of them is declared here, in the standard library:
:data:`DECLARATIONS` names every variable of the term grammar in order, each with the
class of its command-line options (fields written with :func:`~hrgtc.settings.setting`,
as in any settings class; ``D2Options``: ``--rate-tau2-s``).
:data:`hrgtc.settings.drift.DriftSettings` takes those fields and ``--terms``'s help the
names; the registry (:mod:`hrgtc.drift.variables.registry`) refuses a variable module
that is not declared here, or declared out of its order, naming this file
(docs/architecture.md, "Adding a drift variable").
"""

from __future__ import annotations

from dataclasses import dataclass

from hrgtc.settings import setting

#: The second df/dt filter (``d2``) is this many times slower than the first by default.
TAU2_FACTOR = 6.0


class D2Options:
    """d2's command-line option, a field of ``DriftSettings`` (``hrgtc calibrate
    --rate-tau2-s``); :func:`hrgtc.drift.variables.d2.derive` gives the default."""

    rate_tau2_s: float | None = setting(
        None, "Time constant of the second df/dt filter, variable d2 (terms like d2, f*d2).",
        unit="s", default_text=f"{TAU2_FACTOR:g} × --rate-tau-s")


class GsatOptions:
    """gsat's command-line option, a field of ``DriftSettings`` (``hrgtc calibrate
    --gradient-saturation-c``); :func:`hrgtc.drift.variables.gsat.derive` gives the default."""

    gradient_saturation_c: float | None = setting(
        None, "Gradient at which the saturating gradient term gsat = tanh(g / this) bends "
        "(terms like gsat, f*gsat).", unit="°C", default_text="1 °C")


class PlayOptions:
    """play's command-line option, a field of ``DriftSettings`` (``hrgtc calibrate
    --play-width-c``); :func:`hrgtc.drift.variables.play.derive` gives the default."""

    play_width_c: float | None = setting(
        None, "Width of the play (backlash) operator on the thermometer's temperature, "
        "variable play (terms like play); learn it with "
        "hrgtc.drift.variables.play.learn_width (a grid judged by leave-one-run-out).",
        unit="°C", default_text="2 °C")


@dataclass(frozen=True)
class Declaration:
    """One drift variable as the settings see it.

    Attributes
    ----------
    name
        Its spelling in terms (the ``name`` of its module's ``VARIABLE``).
    options
        The class of its command-line options (fields made with
        :func:`~hrgtc.settings.setting`), or None.
    """

    name: str
    options: type | None = None


#: Every drift variable of the term grammar, in its order (each module's ``order=``).
DECLARATIONS = (
    Declaration("f"),
    Declaration("df"),
    Declaration("h"),
    Declaration("dh"),
    Declaration("dpos"),
    Declaration("d2", D2Options),
    Declaration("g"),
    Declaration("gsat", GsatOptions),
    Declaration("play", PlayOptions),
    Declaration("a_NAME"),
)
