"""A pHelmIvP-compatible helm in Python: .bhv files, behaviours, the IvP grid solver, and the ``ivp-helm`` MOOS app.

The core (:class:`Helm`) needs no MOOS: feed it mail and call ``iterate``. :class:`HelmApp` connects it to a
MOOSDB. See docs/helm.md.
"""

from __future__ import annotations

from .config import HelmConfig, config_from_mission
from .errors import BehaviorFileError, ConditionError, IvPHelmError, ParamError
from .helm import Helm, Post

__all__ = ["BehaviorFileError", "ConditionError", "Helm", "HelmConfig", "IvPHelmError", "ParamError", "Post",
           "config_from_mission"]
