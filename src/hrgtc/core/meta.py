"""What this package is: its version and the paper it implements.

Imports nothing of hrgtc, so any module may take ``__version__`` from here
without importing the package's stages.
"""

from typing import Any


def __getattr__(name: str) -> Any:
    """``__version__`` from the installed package's metadata, looked up on first use:
    ``importlib.metadata`` costs a third of ``hrgtc --help``'s start (PEP 562)."""
    if name != "__version__":
        raise AttributeError(f"module 'hrgtc.core.meta' has no attribute {name!r}")
    from importlib.metadata import PackageNotFoundError, version

    try:
        value = version("hrgtc")
    except PackageNotFoundError:  # pragma: no cover - running from a source tree
        value = "0.0.0"
    globals()["__version__"] = value
    return value


PAPER_REFERENCE = (
    "X. Wang, W. Wu, Z. Fang, B. Luo, Y. Li, Q. Jiang, 'Temperature Drift Compensation for "
    "Hemispherical Resonator Gyro Based on Natural Frequency', Sensors 12(5), 6434-6446, 2012. "
    "doi:10.3390/s120506434"
)
#: The paper cited without its title, as a model of a gyro's own temperature sensor cites it
#: (``--thermometer sensor``): the method, a stepwise drift model in the thermometer and its
#: rate, is the paper's; the resonator and natural frequency of its title are not the sensor's.
PAPER_CITATION = "X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434"
#: DOI of the paper. [1]
PAPER_DOI = "10.3390/s120506434"
