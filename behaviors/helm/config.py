"""The helm's settings, read from a mission file's ``ProcessConfig = pHelmIvP`` block (pHelmIvP's names).

Problems are collected, not raised: any problem puts the helm in MALCONFIG, and every message names
the file, the line and the token.
"""

from __future__ import annotations

import logging
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from .behavior import parse_bool
from .errors import BehaviorFileError, ParamError
from .ivp import IvPDomain
from .logic import is_number

if TYPE_CHECKING:
    from gateway.moos.mission_file import MissionFile

log = logging.getLogger(__name__)

# Accepted by every MOOS app (pHelmIvP passes them to the AppCasting base) and by pHelmIvP with no
# effect here: dynamic behaviour libraries do not exist in this helm (docs/helm.md).
_APP_PARAMS = {"apptick", "commstick", "maxapptick", "app_logging", "term_report_interval",
               "max_appcast_events", "deprecated_ok", "bhv_dir_not_found_ok", "seed_random", "verbose",
               "ivp_behavior_dir", "ivp_behavior_dirs", "pmgen", "contact_max_age",
               "hold_on_app", "hold_on_apps"}


@dataclass
class HelmConfig:
    """Everything the helm core needs; ``problems`` non-empty means MALCONFIG."""

    behavior_files: list[str] = field(default_factory=list)
    domain: IvPDomain = field(default_factory=IvPDomain)
    start_engaged: bool = False
    allow_park: bool = True
    park_on_allstop: bool = False
    other_override_var: str = ""
    ok_skew: float | None = 60.0
    goals_mandatory: bool = False
    helm_alias: str = ""
    helm_prefix: str = ""
    nav_grace: float = 5.0
    app_tick: float = 4.0
    time_warp: float = 1.0
    lat_origin: float | None = None
    long_origin: float | None = None
    node_skews: dict[str, float] = field(default_factory=dict)
    problems: list[str] = field(default_factory=list)

    @classmethod
    def from_pairs(cls, pairs: list[tuple[str, str]], where: str, base_dir: Path | None = None) -> HelmConfig:
        """Interpret ``(key, value)`` pairs of the ProcessConfig block; ``where`` names the block in messages."""
        cfg = cls()
        for key, value in pairs:
            try:
                cfg._set(key.strip().lower(), value.strip(), base_dir)
            except ParamError as exc:
                cfg.problems.append(f"{where}: {exc} (at '{key} = {value}')")
        if not cfg.domain.vars:
            cfg.problems.append(f"{where}: no 'domain' given (at 'domain')")
        if not cfg.behavior_files:
            cfg.problems.append(f"{where}: no 'behaviors' file given (at 'behaviors')")
        return cfg

    def _set(self, key: str, value: str, base_dir: Path | None) -> None:
        if key == "behaviors":
            self.behavior_files.append(_resolve(value, base_dir))
        elif key == "domain":
            self.domain.add(value)
        elif key in ("start_engaged", "start_in_drive", "start_indrive", "active_start"):
            self.start_engaged = parse_bool(value, key)
        elif key == "allow_park":
            self.allow_park = parse_bool(value, key)
        elif key == "park_on_allstop":
            self.park_on_allstop = parse_bool(value, key)
        elif key == "other_override_var":
            self.other_override_var = value
        elif key == "ok_skew":
            if value.lower() == "any":
                self.ok_skew = None
            elif is_number(value) and float(value) >= 0:
                self.ok_skew = float(value)
            else:
                raise ParamError(f"ok_skew must be a number or 'any', not '{value}'")
        elif key == "goals_mandatory":
            self.goals_mandatory = parse_bool(value, key)
        elif key == "helm_alias":
            self.helm_alias = value
        elif key == "helm_prefix":
            self.helm_prefix = value
        elif key == "nav_grace":
            if not is_number(value):
                raise ParamError(f"nav_grace must be a number, not '{value}'")
            self.nav_grace = float(value)
        elif key == "node_skew":
            vname, _, skew = (part.strip() for part in value.partition(","))
            if not vname or not is_number(skew) or vname in self.node_skews:
                raise ParamError(f"node_skew must be VNAME,SECONDS, once per vehicle, not '{value}'")
            self.node_skews[vname] = float(skew)
        elif key == "standby":
            raise ParamError("standby helms are not supported by this helm")
        elif key in _APP_PARAMS:
            if key == "apptick":
                if not is_number(value) or float(value) <= 0:
                    raise ParamError(f"AppTick must be a positive number, not '{value}'")
                self.app_tick = float(value)
        else:
            raise ParamError(f"unknown pHelmIvP parameter '{key}'")


def _resolve(name: str, base_dir: Path | None) -> str:
    """A behaviour file as given (relative to the working directory), else next to the mission file."""
    if os.path.isabs(name) or os.path.exists(name) or base_dir is None:
        return name
    candidate = base_dir / name
    return str(candidate) if candidate.exists() else name


def config_from_mission(mission: MissionFile, app_name: str) -> HelmConfig:
    """Read the helm block ``app_name`` and the globals of a :class:`gateway.moos.MissionFile`."""
    where = f"{mission.path}: ProcessConfig = {app_name}"
    if hasattr(mission, "has_process_config") and not mission.has_process_config(app_name):
        cfg = HelmConfig.from_pairs([], where)
        cfg.problems.insert(0, f"{mission.path}: no 'ProcessConfig = {app_name}' block (at '{app_name}')")
    else:
        cfg = HelmConfig.from_pairs(mission.process_config(app_name), where, Path(mission.path).parent)
    cfg.time_warp = mission.time_warp
    try:
        cfg.lat_origin, cfg.long_origin = mission.lat_origin, mission.long_origin
    except Exception as exc:  # MissionFileError: a non-numeric origin
        cfg.problems.append(str(exc))
    if cfg.lat_origin is None or cfg.long_origin is None:
        cfg.problems.append(f"{mission.path}: LatOrigin and LongOrigin must both be set (at 'LatOrigin')")
    return cfg


__all__ = ["HelmConfig", "config_from_mission", "BehaviorFileError"]
