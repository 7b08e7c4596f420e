"""pNodeReporter's job without MOOS: ownship's NAV_* and the helm's state in, NODE_REPORT_LOCAL out.

:class:`NodeReporter` takes mail (:meth:`~NodeReporter.handle_mail`) and, at each tick (:meth:`~NodeReporter.iterate`),
returns the report in pNodeReporter's format (:func:`translators.node_report_codec.format_local_report`). As the
current pNodeReporter does, nothing is reported until the record is valid: a speed, a heading, and x/y or lat/lon.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field

from translators.node_report_codec import NodeReport, angle360, format_local_report

log = logging.getLogger(__name__)

# pNodeReporter's guesses for an unknown platform_length, by platform_type.
_DEFAULT_LENGTHS = {"kayak": 4.0, "mokai": 4.0, "auv": 4.0, "uuv": 4.0, "ship": 8.0, "glider": 3.0, "usv": 6.0,
                    "kingfisher": 3.0}
#: The NAV_* variables copied as they are into the report (NAV_HEADING is normalised to [0, 360)).
_NAV_FIELDS = {"NAV_X": "x", "NAV_Y": "y", "NAV_LAT": "lat", "NAV_LONG": "lon", "NAV_SPEED": "speed",
               "NAV_DEPTH": "depth", "NAV_YAW": "yaw"}
_HELM_STATES = ("DRIVE", "PARK", "MALCONFIG", "DISABLED")
_MOOS_APP_PARAMS = {"apptick", "commstick", "maxapptick", "app_logging", "term_report_interval",
                    "max_appcast_events"}
REGISTRATIONS = ("NAV_X", "NAV_Y", "NAV_LAT", "NAV_LONG", "NAV_SPEED", "NAV_HEADING", "NAV_YAW", "NAV_DEPTH",
                 "IVPHELM_SUMMARY", "IVPHELM_STATE", "IVPHELM_ALLSTOP", "PNR_PAUSE")


def _bool(value: str) -> bool | None:
    lowered = value.strip().lower()
    return True if lowered in ("true", "yes") else False if lowered in ("false", "no") else None


@dataclass
class NodeReporterConfig:
    """The ``ProcessConfig = pNodeReporter`` parameters this reporter reads (pNodeReporter's names)."""

    platform_type: str = "unknown"
    platform_color: str = ""
    platform_length: float = 0.0
    group: str = ""
    output: str = "NODE_REPORT_LOCAL"
    terse: bool = False
    paused: bool = False
    nohelm_threshold: float = 5.0
    app_tick: float = 4.0
    problems: list[str] = field(default_factory=list)

    @classmethod
    def from_pairs(cls, pairs: list[tuple[str, str]], where: str) -> NodeReporterConfig:
        """Read the block; an unusable line is kept in ``problems`` (pNodeReporter reports it and runs on)."""
        cfg = cls()
        for key, value in pairs:
            if not cfg._set(key.strip().lower(), value.strip()):
                cfg.problems.append(f"{where}: unhandled or bad parameter '{key} = {value}'")
        if cfg.platform_length == 0:
            guess = _DEFAULT_LENGTHS.get(cfg.platform_type.lower())
            if guess is None:
                cfg.problems.append(f"{where}: unrecognized platform type '{cfg.platform_type}'")
            else:
                cfg.platform_length = guess
        return cfg

    def _set(self, key: str, value: str) -> bool:
        number = _number(value)
        flag = _bool(value)
        if key in ("platform_type", "vessel_type"):
            self.platform_type = value
        elif key == "platform_color" and value:
            self.platform_color = value
        elif key in ("platform_length", "vessel_length") and number is not None and number >= 0:
            self.platform_length = number
        elif key in ("node_report_output", "node_report_summary", "node_report_var") and value \
                and not any(c.isspace() for c in value):
            self.output = value
        elif key == "group":
            self.group = value
        elif key == "terse_reports" and flag is not None:
            self.terse = flag
        elif key == "paused" and flag is not None:
            self.paused = flag
        elif key == "nohelm_threshold" and number is not None and number > 0:
            self.nohelm_threshold = number
        elif key == "apptick" and number is not None and number > 0:
            self.app_tick = number
        elif key in _MOOS_APP_PARAMS:
            pass
        else:
            return False
        return True


def _number(text: str) -> float | None:
    try:
        return float(text)
    except ValueError:
        return None


class NodeReporter:
    """One vehicle's node reports; ``name`` is the MOOS community, as pNodeReporter uses it."""

    def __init__(self, name: str, config: NodeReporterConfig) -> None:
        self.config = config
        self.record = NodeReport(name=name, type=config.platform_type, color=config.platform_color,
                                 group=config.group, length=config.platform_length)
        self.paused = config.paused
        self.posted = 0
        self._helm_last: float | None = None
        self._helm_state = "unknown"
        self._helm_modes = "none"
        self._allstop = "unknown"

    def handle_mail(self, var: str, value: float | str, now: float) -> None:
        """One message; numbers for NAV_*, strings for the helm's variables and PNR_PAUSE."""
        record = self.record
        if isinstance(value, float):
            if var == "NAV_HEADING":
                record.heading = angle360(value)
            elif var in _NAV_FIELDS:
                setattr(record, _NAV_FIELDS[var], value)
            return
        if var == "IVPHELM_SUMMARY":
            self._helm_last = now
            for item in value.split(","):
                key, _, text = item.partition("=")
                if key.strip() == "modes":
                    self._helm_modes = text.strip()
        elif var == "IVPHELM_ALLSTOP":
            self._helm_last = now
            self._allstop = value
        elif var == "IVPHELM_STATE":
            self._helm_last = now
            state = value.strip()
            if state in _HELM_STATES:
                self._helm_state = state
            if state.startswith("MALCONFIG"):
                self._allstop = "n/a"
        elif var == "PNR_PAUSE":
            flag = _bool(value)
            if flag is not None:
                self.paused = flag

    def valid(self) -> bool:
        """A speed, a heading, and x/y or lat/lon: what a node report needs to be of use to anyone."""
        r = self.record
        located = (r.x is not None and r.y is not None) or (r.lat is not None and r.lon is not None)
        return located and r.speed is not None and r.heading is not None

    def iterate(self, now: float) -> list[tuple[str, str]]:
        """The postings of one tick: ``<output>_FIRST`` once, then ``<output>`` every tick."""
        if self.paused or not self.valid():
            return []
        self.record.index = self.posted
        self.record.time = now
        self.record.mode = self._mode(now)
        self.record.allstop = self._allstop
        report = format_local_report(self.record, terse=self.config.terse)
        out = [(self.config.output + "_FIRST", report)] if self.posted == 0 else []
        out.append((self.config.output, report))
        self.posted += 1
        return out

    def _mode(self, now: float) -> str:
        if self._helm_last is None or now - self._helm_last > self.config.nohelm_threshold:
            return "NOHELM-EVER" if self._helm_last is None else f"NOHELM-{now - self._helm_last:.0f}"
        if self._helm_state == "DRIVE" and self._helm_modes not in ("none", ""):
            return self._helm_modes
        return self._helm_state
