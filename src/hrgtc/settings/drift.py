"""Settings of the drift fit (stage 2b): Eq. (21)-(22) of [1] on window means.

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

from dataclasses import dataclass

from hrgtc.settings import setting

#: The nine candidate terms of Eq. (21) of [1].
EQ21_TERMS = ("f", "f^2", "f^3", "df", "df^2", "df^3", "f*df", "f^2*df", "f*df^2")
#: Default candidates when every training run logs ``housing_c``: the cubic in f of Eq. (21)
#: of [1] with the housing - resonator gradient g = housing_c - T(f) in place of df/dt (the
#: gradient is what makes the bias depend on the rate of change; measured, it carries over
#: to held-out warm-ups and cycles where the df/dt terms fitted on a cool-down do not:
#: bench/heldout_gradient.jsonl).
GRADIENT_TERMS = ("f", "f^2", "f^3", "g", "f*g", "f^2*g")
#: The second df/dt filter (``d2``) is this many times slower than the first by default.
TAU2_FACTOR = 6.0
#: The warm-up left out of each run is this many of the longest filter time constant.
WARMUP_FACTOR = 5.0
#: A term enters the stepwise model below this p-value (MATLAB ``stepwisefit``'s default).
PENTER = 0.05
#: A term leaves the stepwise model above this p-value unless ``premove`` says otherwise
#: (``max(penter, PREMOVE_FLOOR)``, MATLAB ``stepwisefit``).
PREMOVE_FLOOR = 0.10
#: Term-selection methods of :func:`hrgtc.drift.fit`.
SELECTIONS = ("guarded", "stepwise", "cv")
#: Nuisance offsets of the drift fit (:mod:`hrgtc.drift.offsets`).
OFFSET_MODES = ("auto", "none", "run", "orientation", "run+orientation")
#: How the stepwise F-tests account for correlated window residuals.
AUTOCORRELATIONS = ("newey-west", "none")

_FIT = "Drift model"


@dataclass(frozen=True)
class DriftSettings:
    """How the drift model is fitted: candidates, windows, stepwise thresholds, filters.

    Every field is a parameter of :func:`hrgtc.drift.fit` and an option of ``hrgtc
    calibrate``; the model file's provenance records them.
    """

    terms: tuple[str, ...] | None = setting(
        None, "Candidate drift terms, comma separated. Variables: f, df, h, dh, dpos, d2, g, "
        "a_NAME (--aux).",
        default_text=f"{','.join(GRADIENT_TERMS)} (g the housing - resonator gradient) when "
        f"the runs log housing_c, else Eq. 21's {','.join(EQ21_TERMS)}", panel=_FIT)
    window_s: float = setting(10.0, "Averaging window of the fit.", unit="s", panel=_FIT)
    penter: float = setting(PENTER, "Stepwise p-value to enter.", panel=_FIT)
    premove: float | None = setting(
        None, "Stepwise p-value to remove.", default_text=f"max(--penter, {PREMOVE_FLOOR:g})",
        panel=_FIT)
    reference_c: float | None = setting(
        None, "Reference temperature of f.", unit="°C",
        default_text="the centre of the still training data, so a temperature offset does "
        "not change the model", panel=_FIT)
    rate_tau_s: float = setting(
        10.0, "Time constant of each stage of the causal df/dt filter.", unit="s", panel=_FIT)
    rate_tau2_s: float | None = setting(
        None, "Time constant of the second df/dt filter, variable d2 (terms like d2, f*d2).",
        unit="s", default_text=f"{TAU2_FACTOR:g} × --rate-tau-s", panel=_FIT)
    warmup_s: float | None = setting(
        None, "Start of each run left out while the df/dt filters settle.", unit="s",
        default_text=f"{WARMUP_FACTOR:g} × the longest filter time constant", panel=_FIT)
    select: str = setting(
        "guarded", "Term selection: guarded (F-tests, then terms that do not carry over to "
        "held-out runs, or to held-out time blocks of a single run, are dropped), stepwise "
        "(F-tests only) or cv (leave-one-run-out cross-validated bias stability; needs two "
        "training runs or more).", choices=SELECTIONS, panel=_FIT)
    offsets: str = setting(
        "auto", "Constant offsets that are nuisance parameters of the drift fit, not "
        "temperature terms: auto (one per orientation when the runs log accel_x/y/z or an "
        "orientation column, else none), none, run (one per training run: restarts), "
        "orientation, run+orientation.", choices=OFFSET_MODES, panel=_FIT)
    autocorrelation: str = setting(
        "newey-west", "Stepwise F-tests on correlated window means: divide each F by the "
        "long-run / plain variance ratio of the full candidate model's residuals "
        "(newey-west, bandwidth n^(1/3) windows: bias instability keeps 10 s means "
        "correlated, and plain F-tests admit terms that fit noise), or plain F-tests (none, "
        "MATLAB stepwisefit).", choices=AUTOCORRELATIONS, panel=_FIT)
    hierarchical: bool = setting(
        True, "Marginality: a term enters only after its lower-order parents (f before f^2, "
        "f and df before f*df) and leaves only after its children; off gives MATLAB's plain "
        "stepwisefit.", cli="--hierarchical/--no-hierarchical", panel=_FIT)

    def tau2_s(self, uses_d2: bool) -> float:
        """The second filter's time constant (0 when no candidate uses ``d2``). [s]"""
        if not uses_d2:
            return 0.0
        return TAU2_FACTOR * self.rate_tau_s if self.rate_tau2_s is None else self.rate_tau2_s

    def warmup(self, tau2_s: float) -> float:
        """The warm-up left out of each run: ``warmup_s`` or its default. [s]"""
        if self.warmup_s is not None:
            return self.warmup_s
        return WARMUP_FACTOR * max(self.rate_tau_s, tau2_s)
