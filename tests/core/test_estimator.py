"""Every streaming accumulator of hrgtc keeps one contract (hrgtc.core.estimator):
``partial_fit(chunk, ...)`` returns the accumulator and ``finish()`` takes no argument."""

from __future__ import annotations

import ast
import importlib
import inspect
import pkgutil
import textwrap

import numpy as np
import pytest

import hrgtc
from hrgtc.core.estimator import Accumulator

#: Modules not imported here: the CLI entry point runs on import.
SKIP = ("hrgtc.cli.__main__",)


def _accumulators() -> list[type]:
    """Every class defined in hrgtc with a ``partial_fit``."""
    found = {}
    for info in pkgutil.walk_packages(hrgtc.__path__, "hrgtc."):
        if info.name in SKIP:
            continue
        module = importlib.import_module(info.name)
        for _, cls in inspect.getmembers(module, inspect.isclass):
            if (cls.__module__ == info.name and "partial_fit" in vars(cls)
                    and cls is not Accumulator):
                found[f"{cls.__module__}.{cls.__qualname__}"] = cls
    return [found[name] for name in sorted(found)]


ACCUMULATORS = _accumulators()


def test_the_accumulators_are_found():
    """The walk finds the streaming classes the architecture names (it would pass
    vacuously on an empty list)."""
    names = {cls.__name__ for cls in ACCUMULATORS}
    assert {"TimelineBuilder", "QRAccumulator", "RestPass", "SeriesStatistics",
            "RecordingValidator", "RunPass", "DirectionSplit", "SettlingCut",
            "BlockMeans", "FileRows", "TimeContinuity", "ChannelShape"} <= names
    assert len(ACCUMULATORS) >= 14


@pytest.mark.parametrize("cls", ACCUMULATORS, ids=lambda c: c.__qualname__)
def test_partial_fit_returns_self_and_finish_takes_nothing(cls):
    source = textwrap.dedent(inspect.getsource(cls.partial_fit))
    function = ast.parse(source).body[0]
    returns = [node for node in ast.walk(function) if isinstance(node, ast.Return)]
    assert returns, f"{cls.__qualname__}.partial_fit returns nothing"
    for node in returns:
        assert isinstance(node.value, ast.Name) and node.value.id == "self", (
            f"{cls.__qualname__}.partial_fit line {node.lineno}: returns "
            f"{ast.unparse(node.value) if node.value else 'None'}, not self")
    assert isinstance(function.body[-1], ast.Return), (
        f"{cls.__qualname__}.partial_fit can fall off its end (returns None)")
    finish = getattr(cls, "finish", None)
    assert callable(finish), f"{cls.__qualname__} has no finish()"
    required = [p for p in list(inspect.signature(finish).parameters.values())[1:]
                if p.default is inspect.Parameter.empty
                and p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD)]
    assert not required, f"{cls.__qualname__}.finish needs {[p.name for p in required]}"
    for verb in ("result", "timeline", "add"):
        assert verb not in vars(cls), f"{cls.__qualname__} still closes with {verb}()"


def test_the_protocol_is_the_behaviour():
    """Two real accumulators, fed and finished through the protocol alone."""
    from hrgtc.core.timeline_builder import TimelineBuilder
    from hrgtc.drift.qr_accumulator import QRAccumulator

    builder = TimelineBuilder(0.1)
    assert isinstance(builder, Accumulator)
    timeline = builder.partial_fit(np.arange(10) * 0.1).partial_fit(
        np.arange(20, 30) * 0.1).finish()
    assert timeline.n_segments == 2

    rng = np.random.default_rng(1)
    x = rng.normal(size=(200, 2))
    y = 1.5 + x @ np.array([2.0, -3.0]) + rng.normal(scale=0.01, size=200)
    acc = QRAccumulator(["a", "b"])
    assert isinstance(acc, Accumulator)
    fitted = acc.partial_fit(x[:120], y[:120]).partial_fit(x[120:], y[120:]).finish()
    expected = np.linalg.lstsq(np.column_stack([np.ones(200), x]), y, rcond=None)[0]
    np.testing.assert_allclose(fitted.params, expected, rtol=1e-10)
