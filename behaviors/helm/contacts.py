"""Contacts as pHelmIvP 19.8.1 keeps them, and the linear extrapolation its contact behaviours use.

pHelmIvP 19.8.1 turns every ``NODE_REPORT`` (also ``NODE_REPORT_LOCAL``, ``AIS_REPORT``, ``AIS_REPORT_LOCAL``) into
info-buffer variables ``<NAME>_NAV_X/_Y/_SPEED/_HEADING/_DEPTH/_LAT/_LONG/_GROUP/_TYPE/_UTC`` (``HelmIvP::
processNodeReport``), NAME upper-cased and UTC = TIME plus an optional ``node_skew``. Contact behaviours read those
variables; :class:`ContactTable` writes them and keeps the last report of each contact. Unlike 19.8.1, a report
without NAME, TIME, or X/Y (or LAT/LON) is rejected whole instead of writing zeros (see docs/helm.md).
"""

from __future__ import annotations

from dataclasses import dataclass

from translators.node_report_codec import NodeReportError, parse_node_report
from util.geodesy import UTMGeodesy

from .geometry import project
from .info_buffer import InfoBuffer

NODE_REPORT_VARS = ("AIS_REPORT", "NODE_REPORT", "AIS_REPORT_LOCAL", "NODE_REPORT_LOCAL")


@dataclass(frozen=True)
class Contact:
    """The last report of one vehicle, on the local grid; ``utc`` includes the configured skew."""

    name: str
    type: str
    group: str
    x: float
    y: float
    lat: float
    lon: float
    depth: float
    heading: float
    speed: float
    utc: float


class ContactTable:
    """Contacts by upper-cased name; :meth:`handle_report` also writes the ``<NAME>_NAV_*`` info variables."""

    def __init__(self, info: InfoBuffer, geodesy: UTMGeodesy | None = None,
                 skews: dict[str, float] | None = None) -> None:
        self.info, self.geodesy = info, geodesy
        self.skews = dict(skews or {})
        self._contacts: dict[str, Contact] = {}

    def get(self, name: str) -> Contact | None:
        return self._contacts.get(name.upper())

    def names(self) -> list[str]:
        return sorted(self._contacts)

    def handle_report(self, text: str) -> Contact:
        """Parse one report and record it; :class:`NodeReportError` says why a report was not used."""
        report = parse_node_report(text)
        if not report.name:
            raise NodeReportError("no NAME")
        if report.time is None:
            raise NodeReportError(f"{report.name}: no TIME")
        lat, lon = report.lat, report.lon
        if report.x is not None and report.y is not None:
            x, y = report.x, report.y
            if (lat is None or lon is None) and self.geodesy is not None:
                lat, lon = self.geodesy.to_geo(x, y)
        elif lat is not None and lon is not None:
            if self.geodesy is None:
                raise NodeReportError(f"{report.name}: a LAT/LON report needs the mission's LatOrigin/LongOrigin")
            x, y = self.geodesy.to_local(lat, lon)
        else:
            raise NodeReportError(f"{report.name}: neither X and Y nor LAT and LON")
        name = report.name.upper()
        skew = self.skews.get(name, self.skews.get(report.name, 0.0))
        contact = Contact(name, report.type, report.group, x, y, lat or 0.0, lon or 0.0, report.depth or 0.0,
                          report.heading or 0.0, report.speed or 0.0, report.time + skew)
        self._contacts[name] = contact
        for suffix, value in (("X", contact.x), ("Y", contact.y), ("SPEED", contact.speed),
                              ("HEADING", contact.heading), ("DEPTH", contact.depth), ("LAT", contact.lat),
                              ("LONG", contact.lon), ("GROUP", contact.group), ("TYPE", contact.type),
                              ("UTC", contact.utc)):
            self.info.set(f"{name}_NAV_{suffix}", value)
        return contact


class LinearExtrapolator:
    """MOOS-IvP's LinearExtrapolator: dead reckoning along the last heading, with the speed decaying to zero.

    With ``dt = now - timestamp``: up to ``decay_start`` the contact moves at its speed; between ``decay_start``
    and ``decay_end`` the speed falls linearly to 0; after ``decay_end`` it stays put and :attr:`decay_maxed` is
    set. A ``dt`` below -0.1 s is a failure ("negative delta time, possible clock skew") that returns the raw
    position and leaves :attr:`decay_maxed` as it was.
    """

    def __init__(self, decay_start: float = 0.0, decay_end: float = 0.0) -> None:
        self.decay_start, self.decay_end = decay_start, decay_end
        self.decay_maxed = False
        self.failure_reason = ""
        self._state: tuple[float, float, float, float, float] | None = None

    def set_decay(self, start: float, end: float) -> None:
        self.decay_start, self.decay_end = start, end

    def set_position(self, x: float, y: float, speed: float, heading: float, timestamp: float) -> None:
        self._state = (x, y, speed, heading, timestamp)

    def position(self, now: float) -> tuple[float, float, bool]:
        """(x, y, ok) at ``now``; when not ok, :attr:`failure_reason` says why."""
        if self._state is None:
            self.failure_reason = "unknown contact position"
            return 0.0, 0.0, False
        x, y, speed, heading, timestamp = self._state
        dt = now - timestamp
        if self.decay_end < self.decay_start or dt < -0.1:
            self.failure_reason = f"negative delta time, possible clock skew, dtime={dt:.5f}"
            return x, y, False
        self.failure_reason = ""
        if dt == 0:
            return x, y, True
        self.decay_maxed = False
        start, span = self.decay_start, self.decay_end - self.decay_start
        if dt <= start:
            distance = speed * dt
        elif span <= 0:
            distance = speed * start
            self.decay_maxed = True
        elif dt <= self.decay_end:
            decaying = dt - start
            current = speed - speed / span * decaying
            distance = speed * start + (speed + current) / 2.0 * decaying
        else:
            distance = speed * start + speed / 2.0 * span
            self.decay_maxed = True
        px, py = project(x, y, heading, distance)
        return px, py, True
