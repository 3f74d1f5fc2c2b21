"""The lineage of an updated model file: its parent, the data used, what changed.

Every file written by an in-field update (``hrgtc update``, :meth:`hrgtc.model.Model.update`)
carries a :class:`Lineage` in the model file's optional ``lineage`` field (a part of the
model file's schema, :class:`hrgtc.model_schema.FileRecord`; files without it load as
before): the SHA-256 of the parent file and of its parameters, the parent's bytes
(compressed) so that a rollback writes the parent back byte for byte, the recordings
used (SHA-256, still intervals), and each axis's coefficients and covariance before and
after. See docs/guide/update.md.
"""

from __future__ import annotations

import base64
import hashlib
import zlib
from dataclasses import dataclass, field
from typing import Annotated, Any

from msgspec import Meta

from hrgtc.core import records
from hrgtc.core.errors import ModelFileError

__all__ = ["AxisChange", "Lineage", "LineageData", "LineageRecord", "pack", "rollback_bytes",
           "unpack"]

Sha256 = Annotated[str, Meta(pattern="^[0-9a-f]{64}$")]


@dataclass(frozen=True)
class LineageData(records.Written):
    """One recording an update used.

    Attributes
    ----------
    path
        The file as it was given (or ``"<recording>"`` for an in-memory recording).
    sha256
        SHA-256 of the file's bytes (of the columns of an in-memory one, names and bytes).
    intervals_s
        The still intervals used, ``(start, end)`` in the recording's time. [s]
    source
        Where the intervals came from: ``"motion"`` (the motion detector) or ``"given"``
        (``--still``).
    """

    path: str
    sha256: Sha256
    intervals_s: tuple[tuple[float, float], ...] = ()
    source: str = "motion"


@dataclass(frozen=True)
class AxisChange(records.Written):
    """What an update changed on one axis: the updated coefficients (``"const"``: the
    intercept B0 [°/h]; ``"f"``: the linear term [°/h per unit of f]) before and after,
    with their covariance (the prior and the posterior of the filter)."""

    axis: str
    terms: tuple[str, ...]
    before: tuple[float, ...]
    after: tuple[float, ...]
    covariance_before: tuple[tuple[float, ...], ...]
    covariance_after: tuple[tuple[float, ...], ...]


@dataclass(frozen=True)
class Lineage(records.Written):
    """Where an updated model comes from (the model file's ``lineage``).

    Attributes
    ----------
    parent_sha256
        SHA-256 of the parent model file's bytes.
    parent_parameters_sha256
        The parent's ``parameters_sha256`` (the hash a compensated output's mark names).
    parent_path
        The parent file as it was given.
    parent_unit
        The parent's unit (serial).
    parent_content
        The parent file's bytes, zlib-compressed and base64-encoded (:func:`pack`):
        ``hrgtc update --rollback`` writes them back byte for byte.
    data
        The recordings used.
    changes
        Each updated axis's coefficients before and after.
    settings
        The update's settings.
    mahalanobis
        Length of the step from the prior, in the prior's metric (the largest axis's).
    heldout_rms_before_dph, heldout_rms_after_dph
        Residual rms of the held-out still segments before and after (the largest
        axis's). [°/h]
    hrgtc_version, created_utc
        Who wrote the update, and when.
    """

    parent_sha256: Sha256
    parent_parameters_sha256: str
    parent_path: str
    parent_unit: str
    parent_content: str
    data: tuple[LineageData, ...]
    changes: tuple[AxisChange, ...]
    settings: dict[str, Any] = field(default_factory=dict)
    mahalanobis: records.Statistic = 0.0
    heldout_rms_before_dph: records.Statistic = 0.0
    heldout_rms_after_dph: records.Statistic = 0.0
    hrgtc_version: str = ""
    created_utc: str = ""


#: The record of :class:`Lineage` in the model file's schema.
LineageRecord = records.record_of(Lineage, "LineageRecord")


def pack(content: bytes) -> str:
    """``content`` as :attr:`Lineage.parent_content`: zlib (level 9), then base64."""
    return base64.b64encode(zlib.compress(content, 9)).decode("ascii")


def unpack(text: str) -> bytes:
    """Inverse of :func:`pack`."""
    return zlib.decompress(base64.b64decode(text.encode("ascii"), validate=True))


def rollback_bytes(lineage: Lineage, source: str) -> bytes:
    """The parent file's bytes kept in ``lineage``, checked against its SHA-256.

    Raises
    ------
    ModelFileError
        The kept content is damaged (it does not decode, or its hash is not the parent's).
    """
    try:
        content = unpack(lineage.parent_content)
    except (ValueError, zlib.error) as exc:
        raise ModelFileError(f"{source}: the lineage's parent content does not decode "
                             f"({exc}); the file is damaged, no rollback") from None
    digest = hashlib.sha256(content).hexdigest()
    if digest != lineage.parent_sha256:
        raise ModelFileError(f"{source}: the lineage's parent content hashes to {digest}, not "
                             f"the parent's {lineage.parent_sha256}; the file is damaged, no "
                             "rollback")
    return content
