"""track.png: the vehicle's track coloured by DEPLOY_STATE, the loiter rings, the waypoints, and where each
command from shore arrived. Uses matplotlib's Agg backend, so it works headless."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402 - the backend must be chosen first

from launch.record import NavSample  # noqa: E402
from launch.usv.analysis import CommandEffect, LoiterPhase  # noqa: E402
from launch.usv.geometry import Point  # noqa: E402

PHASE_COLOURS = {"POLYGON": "tab:blue", "WAYPOINTS": "tab:orange"}


def _segments(nav: list[NavSample], deploy: list[tuple[float, str]]) -> list[tuple[str, list[NavSample]]]:
    """Split the track where DEPLOY_STATE changes, so each piece gets its phase's colour."""
    pieces: list[tuple[str, list[NavSample]]] = []
    index, state = 0, ""
    for sample in nav:
        while index < len(deploy) and deploy[index][0] <= sample.t:
            state = deploy[index][1]
            index += 1
        if not pieces or pieces[-1][0] != state:
            pieces.append((state, [pieces[-1][1][-1]] if pieces else []))
        pieces[-1][1].append(sample)
    return pieces


def write_track_png(
    path: Path,
    nav: list[NavSample],
    deploy: list[tuple[float, str]],
    phases: list[LoiterPhase],
    waypoints: list[Point],
    commands: list[CommandEffect],
    title: str,
) -> None:
    fig, ax = plt.subplots(figsize=(9, 9), dpi=100)
    labelled: set[str] = set()
    for state, samples in _segments(nav, deploy):
        label = f"track ({state or 'before DEPLOY_STATE'})"
        ax.plot(
            [s.x for s in samples],
            [s.y for s in samples],
            color=PHASE_COLOURS.get(state, "tab:gray"),
            linewidth=1.4,
            zorder=3,
            label=None if label in labelled else label,
        )
        labelled.add(label)
    for i, phase in enumerate(phases):
        xs = [v[0] for v in phase.ring.vertices] + [phase.ring.vertices[0][0]]
        ys = [v[1] for v in phase.ring.vertices] + [phase.ring.vertices[0][1]]
        radius = phase.ring.mean_radius
        ax.plot(xs, ys, linestyle="--", color="tab:green" if i == 0 else "tab:purple", linewidth=1.0,
                label=f"loiter ring {len(phase.ring.vertices)} sides, r~{radius:.0f} m")
    if waypoints:
        ax.plot([p[0] for p in waypoints], [p[1] for p in waypoints], linestyle=":", color="tab:orange",
                marker=".", markersize=4, linewidth=0.8, label="waypoints")
        ax.plot(*waypoints[0], marker="*", markersize=14, color="tab:orange", linestyle="none",
                label="first waypoint")
    for n, command in enumerate(commands, start=1):
        where = next((s for s in nav if s.t >= command.t), nav[-1] if nav else None)
        if where is None:
            continue
        ax.plot(where.x, where.y, marker="o", markersize=9, color="tab:red", linestyle="none", zorder=4,
                label="command arrived" if n == 1 else None)
        ax.annotate(f"{n}: {command.state}\nt={command.t:.0f} s", (where.x, where.y), textcoords="offset points",
                    xytext=(8, 8), fontsize=8, color="tab:red")
    if nav:
        ax.plot(nav[0].x, nav[0].y, marker="s", color="black", linestyle="none", label="start")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x (m east of origin)")
    ax.set_ylabel("y (m north of origin)")
    ax.set_title(title)
    ax.grid(True, linewidth=0.3)
    ax.legend(loc="best", fontsize=8)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
