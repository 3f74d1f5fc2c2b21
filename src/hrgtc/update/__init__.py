"""In-field update of a fitted model (issue 29): still periods of a new recording -> a Kalman
filter on the drift model's offset and slope (a triad's offsets from |Ω|,
:mod:`hrgtc.update.triad`) -> an updated model file with its lineage.

Takes a :class:`hrgtc.model.Model` (its drift model's coefficients and covariance,
:meth:`hrgtc.drift.DriftModel.coefficient_prior`) and field recordings; gives an
:class:`UpdateResult` (the updated model, each coefficient before and after with its
interval, the held-out still residual before and after). :meth:`hrgtc.model.Model.update`
is the library call, ``hrgtc update`` the command; :mod:`hrgtc.update.lineage` is the
record every updated file carries (parent hash and content, data used, what changed), so
that ``hrgtc update --rollback`` restores the parent byte for byte. See
docs/guide/update.md.
"""

from hrgtc.settings.update import UpdateSettings
from hrgtc.update.core import update_model
from hrgtc.update.lineage import AxisChange, Lineage, LineageData, rollback_bytes
from hrgtc.update.result import AxisUpdate, FilterProblem, UpdateResult

__all__ = ["AxisChange", "AxisUpdate", "FilterProblem", "Lineage", "LineageData",
           "UpdateResult", "UpdateSettings", "rollback_bytes", "update_model"]
