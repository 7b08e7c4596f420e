"""The USV's health as the topside received it, for the trail demo's summary (docs/health.md).

Read from the platforms' goby-logger logs after the run: every ``HealthStatus`` on the topside's
``health_status_good`` / ``health_status_failed`` (what topside-manager received over the satellite link and
republished), and, for the reason of a FAILED, the USV's goby-coroner report (``goby::health::report``) it was made
from. HealthStatus carries only a state and a time (DCCL ``time2``: the second of the day), so a status is matched
to the report of the same second of the day. Times are sim seconds (the log's real time times the warp) from
``t0``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from gateway.goby.log import EntryDecoder
from gateway.goby.log.follow import LogFollower
from gateway.goby.portal.health import HEALTH_REPORT
from gateway.goby.portal.protobuf.coroner_pb2 import HEALTH__OK, HealthState, VehicleHealth
from translators.trail import groups
from translators.trail.protobuf.health_status_pb2 import HealthStatus

SECONDS_PER_DAY = 86400
HEALTH_GROUPS = {str(groups.health_status_good), str(groups.health_status_failed)}


@dataclass(frozen=True)
class HealthEvent:
    """One HealthStatus the topside received: when (sim s, the log's time), its state, and why (FAILED only)."""

    t: float
    state: str
    reason: str = ""


def _messages(path: Path, wanted: set[str], warp: float) -> list[tuple[float, object]]:
    """(sim time, message) of every entry of the log at ``path`` on one of the ``wanted`` groups."""
    follower = LogFollower(path)
    try:
        entries = follower.poll()
        decoder = EntryDecoder(follower.descriptors)
        return [(entry.timestamp_micro / 1e6 * warp, message) for entry in entries if entry.group in wanted
                for message in decoder.decode(entry).messages]
    finally:
        follower.close()


def _goby_log(logs: dict[str, list[Path]], platform: str) -> Path | None:
    return next((p for p in logs.get(platform, []) if p.suffix == ".goby"), None)


def _reason(report: VehicleHealth) -> str:
    """The processes of a coroner report that are not HEALTH__OK, with their error messages."""
    failed = [f"{p.name}: {p.main.error_message or HealthState.Name(p.main.state)}"
              for p in report.process if p.main.state != HEALTH__OK]
    return "; ".join(failed)


def health_events(logs: dict[str, list[Path]], warp: float) -> list[HealthEvent]:
    """What the topside received, in order, each FAILED with the reason from the USV's matching coroner report."""
    topside = _goby_log(logs, "topside")
    if topside is None:
        return []
    usv = _goby_log(logs, "usv")
    reports: dict[int, VehicleHealth] = {}
    if usv is not None:
        for _, report in _messages(usv, {str(HEALTH_REPORT)}, warp):
            if isinstance(report, VehicleHealth):
                reports[report.time // 1_000_000 % SECONDS_PER_DAY] = report
    events = []
    for t, status in _messages(topside, HEALTH_GROUPS, warp):
        if not isinstance(status, HealthStatus):
            continue
        state = HealthStatus.HealthState.Name(status.state)
        reason = ""
        if status.state != HealthStatus.GOOD:
            second = status.timestamp // 1_000_000 % SECONDS_PER_DAY
            report = reports.get(second) or reports.get((second - 1) % SECONDS_PER_DAY)
            reason = _reason(report) if report is not None else "no matching coroner report in the USV's log"
        events.append(HealthEvent(t, state, reason))
    return sorted(events, key=lambda e: e.t)


def health_timeline_lines(logs: dict[str, list[Path]], warp: float, t0: float) -> list[str]:
    """The summary's section: one line per change of state (with how many reports it lasted), FAILED with why."""
    events = health_events(logs, warp)
    if not events:
        return ["health the topside received: none (no HealthStatus in the topside's log)"]
    lines = [f"health the topside received over the satellite link ({len(events)} reports; sim s from t0):"]
    run: list[HealthEvent] = []
    for event in [*events, None]:
        if run and (event is None or event.state != run[0].state or event.reason != run[0].reason):
            first, last = run[0], run[-1]
            repeated = f" ({len(run)} reports, to t={last.t - t0:.0f})" if len(run) > 1 else ""
            lines.append(f"  t={first.t - t0:6.0f} {first.state}{repeated}" + (f": {first.reason}" if first.reason else ""))
            run = []
        if event is not None:
            run.append(event)
    return lines
