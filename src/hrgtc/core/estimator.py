"""The one contract of hrgtc's streaming objects (docs/architecture.md, "Estimators").

A file larger than memory is read in chunks, and every object that gathers something
over those chunks -- window means, running statistics, a validator's findings, a
timeline, a regression's triangular factor -- has the same two verbs:

* ``partial_fit(chunk, ...)`` takes the next chunk and returns the accumulator itself,
  so ``acc.partial_fit(a).partial_fit(b)`` chains;
* ``finish()`` takes no argument and returns the result (a report, a table, a
  model). Where the figures are read as methods of the accumulator (a running
  statistic), ``finish()`` closes what is still open and returns the accumulator.

An object that turns each chunk into another chunk (a compensator, the window means of
a chunk, a feature stream) is a transformer and has ``transform(chunk)`` instead.
``tests/core/test_estimator.py`` checks every class of the package that has a
``partial_fit`` against this contract.
"""

from __future__ import annotations

from typing import Any, Protocol, Self, TypeVar, runtime_checkable

R_co = TypeVar("R_co", covariant=True)


@runtime_checkable
class Accumulator(Protocol[R_co]):
    """What gathers a result over chunks: ``partial_fit(chunk) -> self``, ``finish() -> result``."""

    def partial_fit(self, chunk: Any, /, *args: Any, **kwargs: Any) -> Self:
        """Take the next chunk; returns the accumulator."""

    def finish(self) -> R_co:
        """The result of every chunk taken."""
