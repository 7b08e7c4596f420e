"""Fleet scale: the trail mission with 0, 4, 8 and 16 AUVs at warp 5, as ``all.launch`` runs it.

``python -m bench.bench_fleet [--sizes 0,4,8,16] [--warp 5] [--sim 200]``. Per size it starts the whole mission
(topside, USV, N AUVs: every process of every platform), waits until every vehicle is under helm command, then
measures over ``--sim`` simulated seconds:

- CPU seconds (user+system, every process of the mission) per simulated second, and the share of the machine's cores
  that is; next to it the machine's busy share over the same window from ``/proc/stat`` (everything on the machine,
  this benchmark included).  The second is the saturation signal to trust: in a virtual machine the per-process
  counters over-count once the machine is saturated (they summed to 1.45 times the two cores' wall time at 16 AUVs
  here), while ``/proc/stat`` cannot exceed the cores;
- RSS per vehicle (every process of a platform summed; the topside counts as a vehicle);
- kept up? NAV fixes that reached each vehicle's MOOSDB per simulated second (the simulator sends one per simulated
  second, so 1.00 means the whole frontseat -> interface -> MOOS chain kept pace with the warp), worst vehicle;
- link saturation: bytes carried over what the slot plan could carry (satellite, acomms), from the multicast groups.

Start-up time (launch to every vehicle under command) is printed too: it is what grows fastest with the fleet.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

from bench.platform_proc import children_by_parent, machine_ticks, program_name, subtree
from launch.errors import LaunchError
from launch.trail.links import LinkMonitor
from launch.trail.mission import TrailMission, with_free_ports
from launch.trail.settings import TrailSettings

CLK_TCK = os.sysconf("SC_CLK_TCK")
PAGE = os.sysconf("SC_PAGE_SIZE")


def _cpu_by_program(pids: list[int]) -> dict[str, float]:
    out: dict[str, float] = {}
    for pid in pids:
        cpu, _ = _cpu_and_rss([pid])
        name = program_name(pid)
        out[name] = out.get(name, 0.0) + cpu
    return out


def _cpu_by_pid(pids: list[int]) -> dict[int, tuple[float, float]]:
    """pid -> (CPU seconds so far, start time in seconds since boot)."""
    out = {}
    for pid in pids:
        try:
            fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
        except (OSError, IndexError):
            continue
        out[pid] = ((int(fields[11]) + int(fields[12])) / CLK_TCK, int(fields[19]) / CLK_TCK)
    return out


def _uptime() -> float:
    return float(Path("/proc/uptime").read_text().split()[0])


def _cpu_delta(before: dict[int, tuple[float, float]], after: dict[int, tuple[float, float]], since: float) -> float:
    """CPU used between the two samples: a process missing from ``before`` counts only if it started after ``since``
    (a /proc read that failed under load must not add a process's whole start-up CPU)."""
    total = 0.0
    for pid, (cpu, started) in after.items():
        if pid in before:
            total += cpu - before[pid][0]
        elif started >= since:
            total += cpu
    return total


def _cpu_and_rss(pids: list[int]) -> tuple[float, int]:
    cpu, rss = 0.0, 0
    for pid in pids:
        try:
            fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
            rss += int(Path(f"/proc/{pid}/statm").read_text().split()[1]) * PAGE
        except (OSError, IndexError):
            continue
        cpu += (int(fields[11]) + int(fields[12])) / CLK_TCK  # utime, stime
    return cpu, rss


def measure(n_auvs: int, warp: int, sim_seconds: float) -> dict[str, object]:
    run_dir = Path(tempfile.mkdtemp(prefix=f"fleet{n_auvs}-", dir="/tmp"))
    settings = with_free_ports(TrailSettings(run_dir=run_dir, warp=warp), n_auvs, prefer_course=False)
    # the benchmark reads only NAV_X/NAV_Y from each vehicle's alog as it grows (moos-logger's, as the demo does)
    mission = TrailMission(settings, n_auvs, report=lambda line: None, launch_delay_s=1.0, moos_variables=("NAV_X", "NAV_Y"))
    links = LinkMonitor(settings, n_auvs)
    mission.add_hook(links.poll)
    row: dict[str, object] = {"auvs": n_auvs}
    started = time.monotonic()
    try:
        mission.start()
        mission.wait_for_command(timeout_s=600)
        row["startup_s"] = time.monotonic() - started
        assert mission.group is not None
        roots = {p.name: p.pid for p in mission.group.processes}
        tree = children_by_parent()
        all0 = [pid for root in roots.values() for pid in subtree(root, tree)]
        since = _uptime()
        pids0 = _cpu_by_pid(all0)
        programs0 = _cpu_by_program(all0)
        nav0 = {name: run.logs.counts.get("NAV_X", 0) for name, run in mission.runs.items() if run.logs.moos}
        real0, sim0, machine0 = time.monotonic(), mission.now(), machine_ticks()
        mission.run(None, until=lambda: mission.now() - sim0 >= sim_seconds)
        real, sim, machine1 = time.monotonic() - real0, mission.now() - sim0, machine_ticks()
        row["machine_busy"] = (machine1[0] - machine0[0]) / max(1e-9, machine1[1] - machine0[1])
        tree = children_by_parent()
        per_platform = {name: _cpu_and_rss(subtree(pid, tree)) for name, pid in roots.items()}
        programs = _cpu_by_program([pid for root in roots.values() for pid in subtree(root, tree)])
        row["programs"] = {k: (v - programs0.get(k, 0.0)) / sim for k, v in programs.items()}
        all1 = [pid for root in roots.values() for pid in subtree(root, tree)]
        cpu = _cpu_delta(pids0, _cpu_by_pid(all1), since)
        row["cpu_per_sim_s"] = cpu / sim
        row["core_share"] = cpu / real / (os.cpu_count() or 1)
        row["rss_mb_per_vehicle"] = sum(r for _, r in per_platform.values()) / len(per_platform) / 2**20
        rates = [(run.logs.counts.get("NAV_X", 0) - nav0[name]) / sim for name, run in mission.runs.items()
                 if run.logs.moos]
        row["nav_per_sim_s_min"] = min(rates) if rates else float("nan")
        row["kept_up"] = bool(rates) and min(rates) > 0.9
        row["sat_satellite"] = links.stats["satellite"].saturation(sim)
        row["sat_acomms"] = links.stats["acomms"].saturation(sim)
    except LaunchError as exc:
        row["error"] = str(exc).splitlines()[0]
    finally:
        links.close()
        mission.stop()
    return row


def _pct(value: object) -> str:
    return "-" if value is None else f"{100 * float(value):.0f}%"  # type: ignore[arg-type]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench.bench_fleet", description=__doc__.split("\n\n")[0])
    parser.add_argument("--sizes", default="0,4,8,16", help="AUV counts (default 0,4,8,16)")
    parser.add_argument("--warp", type=int, default=5, help="time warp (default 5, the course's)")
    parser.add_argument("--sim", type=float, default=200.0, help="simulated seconds measured per size (default 200)")
    args = parser.parse_args(argv)
    sizes = [int(s) for s in args.sizes.split(",")]
    print(f"trail mission fleet scale, warp {args.warp}, {args.sim:g} sim s per size, {os.cpu_count()} cores")
    header = (f"{'AUVs':>4} {'start-up s':>10} {'CPU s/sim s':>11} {'cores used':>10} {'machine busy':>12} "
              f"{'RSS MB/veh':>10} "
              f"{'NAV/sim s':>9} {'kept up':>7} {'sat. link':>9} {'acomms':>7}")
    print(header)
    last: dict[str, object] | None = None
    for n in sizes:
        row = measure(n, args.warp, args.sim)
        last = row if "programs" in row else last
        if "error" in row:
            print(f"{n:>4} failed: {row['error']}", flush=True)
            continue
        print(f"{n:>4} {row['startup_s']:>10.0f} {row['cpu_per_sim_s']:>11.2f} {_pct(row['core_share']):>10} "
              f"{_pct(row['machine_busy']):>12} {row['rss_mb_per_vehicle']:>10.0f} {row['nav_per_sim_s_min']:>9.2f} "
              f"{'yes' if row['kept_up'] else 'NO':>7} {_pct(row['sat_satellite']):>9} {_pct(row['sat_acomms']):>7}",
              flush=True)
    if last is not None:
        programs: dict[str, float] = last["programs"]  # type: ignore[assignment]
        total = sum(programs.values()) or 1.0
        top = sorted(programs.items(), key=lambda kv: -kv[1])[:8]
        print(f"CPU by program with {last['auvs']} AUVs (CPU s per sim s, share): "
              + ", ".join(f"{name} {cpu:.3f} ({100 * cpu / total:.0f}%)" for name, cpu in top))
    return 0


if __name__ == "__main__":
    sys.exit(main())
