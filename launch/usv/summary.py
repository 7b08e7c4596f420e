"""The demo's printed summary and its one-line progress reports, from a recorded mission."""

from __future__ import annotations

import math

from launch.mission import ending_lines
from launch.record import MissionRecord
from launch.usv.analysis import (
    command_effects,
    helm_timeline,
    interface_timeline,
    link_acks,
    loiter_phases,
    normalized_heading,
    transitions,
    waypoint_approach,
)
from launch.usv.geometry import Point
from launch.usv.mission import MissionResult


def progress_line(record: MissionRecord, elapsed: float, duration: float | None) -> str:
    """One line while the mission runs: sim time, states, position."""
    nav, _ = record.snapshot()
    iface = interface_timeline(record)
    helm = helm_timeline(record)
    deploy = transitions(record.events_named("DEPLOY_STATE", source="moos"))
    if nav:
        heading = nav[-1].heading
        hdg = "    ?" if heading is None else f"{normalized_heading(heading):5.1f}"
        where = f"x={nav[-1].x:7.1f} y={nav[-1].y:7.1f} hdg={hdg}"
    else:
        where = "no nav yet"
    total = f"/{duration:.0f}" if duration else ""
    return (
        f"t={elapsed:6.0f}{total} s sim | interface {iface[-1][1] if iface else '?'} | helm "
        f"{helm[-1][1] if helm else '?'} | DEPLOY_STATE {deploy[-1][1] if deploy else '?'} | {where}"
    )


def _timeline(items: list[tuple[float, str]]) -> str:
    return " -> ".join(f"{value} (t={t:.0f} s)" for t, value in items) or "(nothing seen)"


def summary_text(result: MissionResult, waypoints: list[Point]) -> str:
    """The report printed at the end of the demo; times are sim seconds after the helm took command."""
    record = result.record
    lines = ["", "=== USV mission summary (sim seconds; t=0 when the interface reached COMMAND) ==="]
    lines.append(f"frontseat interface: {_timeline(interface_timeline(record))}")
    lines.append(f"helm (IVPHELM_STATE): {_timeline(helm_timeline(record))}")
    lines.append("commands from shore and the MOOS values they produced:")
    effects = command_effects(record)
    for n, effect in enumerate(effects, start=1):
        order = " (POLYGON_UPDATES before DEPLOY_STATE)" if effect.polygon_before_state else ""
        lines.append(f"  {n}. t={effect.t:.0f} s: {effect.describe()}{order}")
    if not effects:
        lines.append("  (none reached the MOOSDB)")
    acks = [e for e in record.snapshot()[1] if e.source == "ack"]
    if acks:
        lines.append(f"  acknowledgements: {len([a for a in acks if a.name == 'POSTED_TO_MOOS'])} posted to MOOS, "
                     f"{len([a for a in acks if a.name == 'REFUSED'])} refused")
    links = link_acks(record)
    if links:
        lines.append("  over the satellite link (5 s / 64 B slots): " + "; ".join(
            f"t={a.t:.0f} s {'acked' if a.acked else 'EXPIRED'}: slot wait {a.slot_wait:.1f} s, "
            f"{'ack' if a.acked else 'expired'} after {a.latency:.1f} s" for a in links))
    lines.append("loiter phases (distance to the ring after the vehicle first came within 15 m of it):")
    for phase in loiter_phases(record):
        cx, cy = phase.ring.center
        ring = f"{len(phase.ring.vertices)} sides r~{phase.ring.mean_radius:.0f} m at ({cx:.0f},{cy:.0f}) [{phase.ring_source}]"
        if phase.mean_distance is None:
            lines.append(f"  t={phase.start:.0f}..{phase.end:.0f} s {ring}: never reached the ring")
        else:
            lines.append(
                f"  t={phase.start:.0f}..{phase.end:.0f} s {ring}: on ring from t={phase.settled_at:.0f} s, "
                f"mean distance {phase.mean_distance:.1f} m over {phase.samples} fixes"
            )
    approach = waypoint_approach(record, waypoints)
    if approach is not None:
        wx, wy = approach.waypoint
        heading = (f"heading error {approach.start_heading_error:.0f} -> min {approach.min_heading_error:.0f} deg"
                   if approach.min_heading_error is not None else "no heading data")
        until = "until the next command" if approach.ended_by_command else "until the end of the run"
        lines.append(
            f"waypoints phase t={approach.t_command:.0f}..{approach.t_end:.0f} s ({approach.duration:.0f} s, {until}): "
            f"first waypoint ({wx:.0f},{wy:.0f}), range {approach.start_range:.0f} -> min {approach.min_range:.0f} m, "
            f"{heading}"
        )
    nav = record.snapshot()[0]
    if len(nav) > 1:
        distance = sum(math.hypot(b.x - a.x, b.y - a.y) for a, b in zip(nav, nav[1:], strict=False))
        last = nav[-1]
        final_heading = "" if last.heading is None else f" heading {normalized_heading(last.heading):.0f} deg"
        lines.append(f"track: {len(nav)} fixes over {last.t - nav[0].t:.0f} s, {distance:.0f} m travelled; "
                     f"last fix ({last.x:.0f},{last.y:.0f}){final_heading}")
    lines.extend(ending_lines(result.outcomes, result.log_errors, result.failure, "processes"))
    return "\n".join(lines)
