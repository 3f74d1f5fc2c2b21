"""Accounting of samples: read, used, and dropped or flagged by reason.

Nothing is dropped silently: every stage that leaves samples out (a warm-up skip,
the edge of a gap, a partial window, a duplicate, a slice, a spike, motion, a value
out of range) says so through one :class:`Accounting`, which every command reports
in its plain output and its ``--json``. More than :data:`DROPPED_WARNING_FRACTION`
of the samples dropped is a warning in the summary line.

Adding a reason is one line in :data:`REASONS`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from hrgtc.core import records
from hrgtc.core.errors import InputError
from hrgtc.core.records import Count
from hrgtc.core.summary import Figure, Summary, escape

#: Reason -> how it reads in a report. One line per reason.
REASONS: dict[str, str] = {
    "warmup": "warm-up (df/dt filter settling)",
    "gap_edges": "gap edges (filter restart after a gap)",
    "partial_windows": "partial windows at segment ends",
    "slicing": "outside --start/--end",
    "duplicates": "duplicated rows",
    "spikes": "spikes",
    "motion": "motion (not at rest)",
    "out_of_range": "out of the calibrated range",
    "rate_out_of_range": "df/dt beyond its training range",
    "held_out": "held out for validation",
}
DROPPED_WARNING_FRACTION = 0.10


def _check_reason(reason: str) -> None:
    if reason not in REASONS:
        raise InputError(f"unknown accounting reason {reason!r}; known: {sorted(REASONS)}")


@dataclass
class Accounting(records.Written):
    """Samples read, used, and dropped or flagged by reason, for one command.

    Attributes
    ----------
    read
        Samples read from the file(s).
    dropped
        Reason -> samples left out of the computation.
    flagged
        Reason -> samples kept but flagged (``compensate`` flags, never drops).

    Examples
    --------
    >>> a = Accounting(read=6250)
    >>> a.drop("warmup", 250)
    >>> a.used, f"{a.dropped_fraction:.2f}"
    (6000, '0.04')
    """

    #: Its record (:data:`AccountingRecord`): what it holds, then what follows from it.
    record_order = ("read", "used", "dropped", "flagged", "dropped_fraction", "warning")
    required = ("read",)

    read: Count = 0
    dropped: dict[str, Count] = field(default_factory=dict)
    flagged: dict[str, Count] = field(default_factory=dict)

    def __post_init__(self) -> None:
        for counts in (self.dropped, self.flagged):  # each reason checked (a file's too)
            for reason in counts:
                _check_reason(reason)
        self.dropped = {reason: int(n) for reason, n in self.dropped.items() if n}
        self.flagged = {reason: int(n) for reason, n in self.flagged.items() if n}

    def add_read(self, count: int) -> None:
        """``count`` more samples read."""
        self.read += int(count)

    def drop(self, reason: str, count: int) -> None:
        """``count`` samples left out for ``reason`` (a key of :data:`REASONS`)."""
        _check_reason(reason)
        if count:
            self.dropped[reason] = self.dropped.get(reason, 0) + int(count)

    def flag(self, reason: str, count: int) -> None:
        """``count`` samples kept but flagged for ``reason``."""
        _check_reason(reason)
        if count:
            self.flagged[reason] = self.flagged.get(reason, 0) + int(count)

    def merge(self, other: Accounting) -> None:
        """Add another accounting (another file or axis) to this one."""
        self.read += other.read
        for reason, count in other.dropped.items():
            self.drop(reason, count)
        for reason, count in other.flagged.items():
            self.flag(reason, count)

    @property
    def n_dropped(self) -> int:
        """Samples dropped for any reason."""
        return sum(self.dropped.values())

    @records.derived(default=0)
    def used(self) -> Count:
        """Samples read and not dropped."""
        return self.read - self.n_dropped

    @records.derived(default=0.0)
    def dropped_fraction(self) -> float:
        """Share of the samples read that were dropped (0 when nothing was read)."""
        return self.n_dropped / self.read if self.read else 0.0

    @records.derived(default=None)
    def warning(self) -> str | None:
        """The summary-line warning when more than 10 % were dropped, else None."""
        if self.dropped_fraction <= DROPPED_WARNING_FRACTION:
            return None
        top = max(self.dropped, key=self.dropped.__getitem__)
        return (f"{self.dropped_fraction:.0%} of the samples dropped (most for "
                f"{REASONS[top]}: {self.dropped[top]})")

    def summary(self) -> Summary:
        """Read, used, dropped and flagged by reason (its text one line, with the warning
        when more than 10 % were dropped)."""
        figures = [Figure("read", "samples read", self.read,
                          definition="Samples read from the recording(s)."),
                   Figure("used", "samples used", self.used,
                          definition="Samples read and not dropped by any stage.")]
        line = "samples: {read} read, {used} used"
        for verb, counts in (("dropped", self.dropped), ("flagged", self.flagged)):
            if counts:
                figures += [Figure(f"{verb}.{reason}", f"{verb}: {REASONS[reason]}", count,
                                   definition=f"Samples {verb} for {REASONS[reason]}.")
                            for reason, count in counts.items()]
                line += f", {verb} " + ", ".join("{" + f"{verb}.{reason}" + "} "
                                                 + escape(REASONS[reason]) for reason in counts)
        warning = self.warning
        if warning:
            line += " -- warning: " + escape(warning)
        return Summary("samples", (("samples", tuple(figures)),),
                       (warning,) if warning else (), (line,))


#: The record of :class:`Accounting`, generated from its fields and derived properties.
AccountingRecord = records.record_of(
    Accounting, doc="The record of :class:`Accounting`: what it holds, then what follows "
    "from it\n(``used``, ``dropped_fraction``, ``warning``: written, not read back).")
