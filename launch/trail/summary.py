"""The trail demo's printed summary and progress lines."""

from __future__ import annotations

import statistics
from dataclasses import dataclass

from launch.mission import ending_lines
from launch.record import MissionRecord
from launch.trail.analysis import (
    CommandOutcome,
    RecoverOutcome,
    TrailPerformance,
    distance_travelled,
    state_timeline,
)
from launch.trail.links import LinkStats
from launch.trail.mission import TrailResult
from launch.trail.operator import RECOVER

NO_SUBSCRIBERS = "EXPIRED_NO_SUBSCRIBERS"  # the reason the operator files (ExpireData.reason's name)


@dataclass
class LinkAccount:
    """One link's commands as their publisher saw them: each sent command goes to ``recipients`` subscribers, and
    each (command, recipient) must end acked or expired. ``no_subscribers`` counts EXPIRED_NO_SUBSCRIBERS notices
    apart: every link of the publisher's broker reports one for a command none of its subscribers wants (the USV's
    satellite link for each RECOVER), so they settle no delivery."""

    name: str
    recipients: int
    sent: int = 0
    acked: int = 0
    expired: int = 0
    no_subscribers: int = 0

    @property
    def deliveries(self) -> int:
        return self.sent * self.recipients

    @property
    def unsettled(self) -> int:
        """Deliveries neither acked nor expired yet (still within their ttl when the mission ended)."""
        return self.deliveries - self.acked - self.expired


def link_accounting(operator: MissionRecord, n_auvs: int) -> dict[str, LinkAccount]:
    """Per link, the operator's commands sent, acked and expired (its ``command`` events): USV commands cross the
    satellite link to the USV, RECOVER the acoustic link to every AUV."""
    accounts = {"satellite": LinkAccount("satellite", 1), "acomms": LinkAccount("acomms", n_auvs)}
    for event in operator.snapshot()[1]:
        if event.source != "command":
            continue
        account = accounts["acomms" if event.value == RECOVER else "satellite"]
        if event.name == "sent":
            account.sent += 1
        elif event.name == "ack":
            account.acked += 1
        elif event.name == "expire" and event.origin == NO_SUBSCRIBERS:
            account.no_subscribers += 1
        elif event.name == "expire":
            account.expired += 1
    return accounts


def _accounting_lines(accounts: dict[str, LinkAccount], channels: dict[str, str]) -> list[str]:
    lines = ["commands per link (acks and expiries as their publisher got them; sent = acked + expired + unsettled):"]
    for account in accounts.values():
        to = f"{account.recipients} recipient{'s' if account.recipients != 1 else ''}"
        unsettled = account.unsettled
        tail = "" if unsettled == 0 else (f", {unsettled} UNSETTLED (within their ttl at the end)" if unsettled > 0
                                         else f", {-unsettled} more outcomes than deliveries")
        if account.no_subscribers:
            tail += (f" ({account.no_subscribers} {NO_SUBSCRIBERS} from a link of the publisher that carries no such "
                     "command)")
        lines.append(f"  {account.name} ({channels.get(account.name, 'lossless')}): {account.sent} sent x {to} = "
                     f"{account.deliveries}: {account.acked} acked, {account.expired} expired{tail}")
    return lines


def _latest(record: MissionRecord, name: str, source: str = "moos") -> str:
    events = record.events_named(name, source)
    return events[-1].value.removeprefix("INTERFACE_") if events else "?"


def progress_line(records: dict[str, MissionRecord], elapsed: float, duration: float | None) -> str:
    """One line while the mission runs: sim time, then per vehicle its state (the interface's until the helm has
    command, then DEPLOY_STATE / AUV_DEPLOY_STATE), position and depth."""
    parts = []
    for name, record in records.items():
        if name == "topside":
            continue
        nav = record.snapshot()[0]
        state = _latest(record, "interface_state", "interface")
        deploy = _latest(record, "DEPLOY_STATE" if name == "usv" else "AUV_DEPLOY_STATE")
        if state == "COMMAND" and deploy != "?":
            state = deploy  # under helm command the mission's state is the news (RECOVER), not the interface's
        where = f"({nav[-1].x:.0f},{nav[-1].y:.0f})" if nav else "(no nav)"
        depth = f" {nav[-1].depth:.0f}m" if nav and nav[-1].depth else ""
        parts.append(f"{name} {state} {where}{depth}")
    total = f"/{duration:.0f}" if duration else ""
    return f"t={elapsed:6.0f}{total} s | " + " | ".join(parts)


def _timeline(items: list[tuple[float, str, str]], what: str) -> str:
    picked = [(t, v) for t, w, v in items if w == what]
    return " -> ".join(f"{v} ({round(t):d})" for t, v in picked) or "-"


def summary_text(result: TrailResult, trails: list[TrailPerformance], commands: list[CommandOutcome],
                 recovers: list[RecoverOutcome], links: dict[str, LinkStats] | None, sim_seconds: float,
                 link_error: str | None = None, topside_view: dict[str, int] | None = None,
                 accounts: dict[str, LinkAccount] | None = None, channels: dict[str, str] | None = None) -> str:
    """The summary; ``channels`` (link -> its simulated channel, described) and ``accounts`` (per link, commands
    sent / acked / expired) are printed when given."""
    lines = ["", "=== Trail mission summary (sim seconds; t=0 when every vehicle was under helm command) ==="]
    if channels is not None:
        described = "; ".join(f"{link} {channels.get(link, 'lossless')}" for link in ("satellite", "acomms"))
        lines.append(f"channels (simulated on receive by each modem driver, docs/intervehicle.md): {described}")
    if topside_view is not None:
        seen = ", ".join(f"{name} x{count}" for name, count in sorted(topside_view.items())) or "nothing"
        lines.append(f"topside NodeStatus (the topside manager's republished nav, over satellite): {seen}")
    lines.append("vehicles (state changes with their times; distance travelled):")
    for name, record in result.records.items():
        if name == "topside":
            continue
        timeline = state_timeline(record)
        nav = record.snapshot()[0]
        deploy = "DEPLOY_STATE" if name == "usv" else "AUV_DEPLOY_STATE"
        lines.append(f"  {name}: interface {_timeline(timeline, 'interface')}; helm {_timeline(timeline, 'IVPHELM_STATE')}; "
                     f"{deploy} {_timeline(timeline, deploy)}; {distance_travelled(nav):.0f} m over {len(nav)} fixes")
    if trails:
        lines.append("trail (range 50 m at each AUV's angle; errors from the first fix within 20 m of the trail point "
                     "until RECOVER or the end):")
    for trail in trails:
        if trail.settled_at is None:
            lines.append(f"  {trail.name} (angle {trail.trail_angle:g}, depth {trail.depth:g} m): never within 20 m "
                         "of its trail point")
            continue
        lines.append(f"  {trail.name} (angle {trail.trail_angle:g}, depth {trail.depth:g} m): trailing from "
                     f"t={trail.settled_at:.0f} s; range error {trail.range_error} m; angle error {trail.angle_error} "
                     f"deg; depth error {trail.depth_error} m")
    lines.append("commands (sent from the topside over satellite / RECOVER from the USV over acomms):")
    for n, command in enumerate(commands, start=1):
        ack = (f"acked t={command.acked_at:.0f} ({'; '.join(who for _, who in command.acks)})" if command.acks else
               f"EXPIRED ({command.expired})" if command.expired else "not acked")
        arrived = ", ".join(f"{v} t={t:.0f} (+{t - command.sent_at:.0f} s)" for v, t in command.arrived_at.items())
        lines.append(f"  {n}. {command.what}: sent t={command.sent_at:.0f}, {ack}; in MOOS: {arrived or 'never'}")
    latencies = [x for c in commands for x in c.latencies]
    if latencies:
        lines.append(f"  command latency sender -> MOOS: mean {statistics.fmean(latencies):.1f} s, max "
                     f"{max(latencies):.1f} s over {len(latencies)} arrivals")
    if not commands:
        lines.append("  (none sent)")
    if accounts is not None:
        lines.extend(_accounting_lines(accounts, channels or {}))
    if recovers:
        lines.append("RECOVER (station 100,-100):")
    for r in recovers:
        if r.commanded_at is None:
            lines.append(f"  {r.name}: RECOVER never reached its MOOSDB")
            continue
        lines.append(f"  {r.name}: AUV_DEPLOY_STATE=RECOVER t={r.commanded_at:.0f} "
                     f"({'after' if r.depth_updates_first else 'WITHOUT'} DEPLOY_DEPTH_UPDATES=depth=0); final depth "
                     f"{r.final_depth:.1f} m, distance to station {r.final_distance_to_station:.0f} m "
                     f"(closest {r.min_distance_to_station:.0f} m)")
    if links is not None:
        lines.append(f"links (every datagram on the multicast groups, {sim_seconds:.0f} sim s):")
        for stats in links.values():
            saturation = stats.saturation(sim_seconds)
            sat = "-" if saturation is None else f"{100 * saturation:.0f}% of slot capacity"
            senders = ", ".join(f"{src}: {n}" for src, n in sorted(stats.by_src.items()))
            lines.append(f"  {stats.name}: {stats.data_transmissions} data transmissions ({senders or 'none'}), "
                         f"{stats.frames} frames, {stats.frame_bytes} bytes, {stats.acks} acks; {sat}")
    if link_error:
        lines.append(f"  link statistics incomplete: {link_error}")
    for t, name, tail in result.deaths:
        lines.append(f"DIED at t={t:.0f} s: {name} (the others kept running); last lines of its log:\n{tail}")
    lines.extend(ending_lines(result.outcomes, result.log_errors, result.failure, "launchers"))
    return "\n".join(lines)
