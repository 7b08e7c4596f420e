"""trail.png: every vehicle's track with the commands and RECOVER marked, and the AUVs seen from the USV.

Left panel: tracks in local metres (USV black, one colour per AUV), where the USV was when each command took effect
in its MOOSDB, where each AUV was when RECOVER reached it, the recovery station. Right panel: each AUV's position
in the USV's frame (starboard, ahead) while trailing, with its trail point (50 m at its relative angle).
Matplotlib's Agg backend, so it works headless.
"""

from __future__ import annotations

import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402 - the backend must be chosen first

from launch.record import MissionRecord  # noqa: E402
from launch.trail.analysis import STATION, TRAIL_RANGE, CommandOutcome, RecoverOutcome, TrailPerformance  # noqa: E402

COLOURS = ["tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown", "tab:pink", "tab:olive",
           "tab:cyan", "tab:gray"]


def _at(record: MissionRecord, t: float) -> tuple[float, float] | None:
    nav = record.snapshot()[0]
    sample = next((s for s in nav if s.t >= t), nav[-1] if nav else None)
    return None if sample is None else (sample.x, sample.y)


def _finish_panel(axes: plt.Axes, xlabel: str, ylabel: str, title: str) -> None:
    """Equal scales, labels, a light grid and the legend: both panels end the same way."""
    axes.set_aspect("equal", adjustable="datalim")
    axes.set_xlabel(xlabel)
    axes.set_ylabel(ylabel)
    axes.set_title(title)
    axes.grid(True, linewidth=0.3)
    axes.legend(loc="best", fontsize=8)


def write_trail_png(path: Path, records: dict[str, MissionRecord], commands: list[CommandOutcome],
                    recovers: list[RecoverOutcome], trails: list[TrailPerformance], title: str) -> None:
    fig, (ax, rel) = plt.subplots(1, 2, figsize=(15, 7.5), dpi=100, gridspec_kw={"width_ratios": [1.35, 1]})
    auvs = sorted(n for n in records if n.startswith("auv"))
    colour = {name: COLOURS[i % len(COLOURS)] for i, name in enumerate(auvs)}
    for name, record in records.items():
        nav = record.snapshot()[0]
        if not nav or name == "topside":
            continue
        style = {"color": "black", "linewidth": 1.6} if name == "usv" else {"color": colour[name], "linewidth": 0.9}
        ax.plot([s.x for s in nav], [s.y for s in nav], label=name.upper() if name == "usv" else name, **style)
        ax.plot(nav[0].x, nav[0].y, marker="s", color=style["color"], markersize=4, linestyle="none")
    for n, command in enumerate(commands, start=1):
        if command.what == "recover" or "usv" not in records or "usv" not in command.arrived_at:
            continue
        t = command.arrived_at["usv"]
        where = _at(records["usv"], t)
        if where is None:
            continue
        ax.plot(*where, marker="o", markersize=9, color="crimson", linestyle="none", zorder=5,
                label="USV command took effect" if n == 1 else None)
        ax.annotate(f"{command.what.split()[0]}\nt={t:.0f} s", where, textcoords="offset points", xytext=(8, 6),
                    fontsize=8, color="crimson")
    first = True
    for outcome in recovers:
        if outcome.commanded_at is None or outcome.name not in records:
            continue
        where = _at(records[outcome.name], outcome.commanded_at)
        if where is not None:
            ax.plot(*where, marker="X", markersize=10, color=colour.get(outcome.name, "k"), markeredgecolor="black",
                    linestyle="none", zorder=5, label="RECOVER reached the AUV" if first else None)
            first = False
    if recovers:
        ax.plot(*STATION, marker="*", markersize=16, color="gold", markeredgecolor="black", linestyle="none",
                zorder=6, label="recovery station (100,-100)")
    _finish_panel(ax, "x (m east of origin)", "y (m north of origin)", "tracks")

    rel.plot(0, 0, marker="^", markersize=12, color="black", linestyle="none", label="USV (heading up)")
    for trail in trails:
        auv = next((n for n in auvs if f"AUV_{n[3:]}" == trail.name), None)
        c = colour.get(auv or "", "tab:gray")
        points = [(x, y) for t, x, y in trail.relative if t >= (trail.settled_at or 0) and t <= trail.end]
        if points:
            rel.scatter([p[0] for p in points], [p[1] for p in points], s=4, color=c, alpha=0.5,
                        label=f"{trail.name} (trail angle {trail.trail_angle:g})")
        angle = math.radians(trail.trail_angle)
        rel.plot(TRAIL_RANGE * math.sin(angle), TRAIL_RANGE * math.cos(angle), marker="+", markersize=14, color=c,
                 markeredgewidth=2, linestyle="none")
    circle = plt.Circle((0, 0), TRAIL_RANGE, fill=False, linestyle="--", linewidth=0.8, color="gray")
    rel.add_patch(circle)
    _finish_panel(rel, "starboard of the USV (m)", "ahead of the USV (m)",
                  "AUVs relative to the USV while trailing (+: trail points, 50 m)")
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
