"""Loading the compiled modules: the module, or an error saying how to build it."""

from __future__ import annotations

import pytest

from hrgtc.core.native import native_module


def test_a_built_module_is_returned():
    module = native_module("hrgtc.recording._spike_native", "spike filter")
    assert module.__name__ == "hrgtc.recording._spike_native"
    assert module.__file__.endswith(".so")


def test_a_missing_module_names_itself_its_source_and_the_build():
    with pytest.raises(ImportError) as raised:
        native_module("hrgtc.drift._no_such_native", "nothing")
    message = str(raised.value)
    assert "compiled nothing (hrgtc.drift._no_such_native" in message
    assert "src/hrgtc/drift/_no_such_native.c" in message
    assert "make .venv/.installed" in message
    assert isinstance(raised.value.__cause__, ImportError)
