"""Idle cost of a moos-gateway process: how often its threads wake and the CPU it uses with nothing to translate.

``python -m bench.bench_gateway_idle [--warp 10] [--seconds 15]``. Starts a moos-db, a goby-broker and
``moos-gateway`` with the ``goby3_course`` plugin (IvPHelmTranslation + CommandTranslation), lets it settle 8 s,
then prints per thread the voluntary and involuntary context switches per second over the window (from
``/proc/<pid>/task/*/status``) and the process's CPU per second (utime + stime of ``/proc/<pid>/stat``, in clock
ticks: about +-0.7 ms/s over 15 s). ``STRACE=1`` adds an ``strace -f -c`` of the process over a second window.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from gateway.goby.portal.testing import broker_process
from gateway.moos.testing import moosdb_process
from util.cli import HelpFormatter, positive_number
from util.process import ChildProcess

TICKS = os.sysconf("SC_CLK_TCK")


def snapshot(pid: int) -> tuple[dict[str, tuple[str, int, int]], int]:
    tasks: dict[str, tuple[str, int, int]] = {}
    for tid in os.listdir(f"/proc/{pid}/task"):
        try:
            name = Path(f"/proc/{pid}/task/{tid}/comm").read_text().strip()
            status = Path(f"/proc/{pid}/task/{tid}/status").read_text()
        except FileNotFoundError:
            continue
        vol = sum(int(line.split()[1]) for line in status.splitlines() if line.startswith("voluntary_ctxt"))
        invol = sum(int(line.split()[1]) for line in status.splitlines() if line.startswith("nonvoluntary_ctxt"))
        tasks[tid] = (name, vol, invol)
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    cpu = int(fields[11]) + int(fields[12])  # utime + stime (ticks), all threads
    return tasks, cpu


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(prog="python -m bench.bench_gateway_idle", formatter_class=HelpFormatter,
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("--warp", type=int, default=10, help="time warp (default 10)")
    parser.add_argument("--seconds", type=positive_number, default=15.0, help="measured window (default 15)")
    options = parser.parse_args(argv)
    warp, window = options.warp, options.seconds
    with tempfile.TemporaryDirectory() as tmp, moosdb_process(tmp, community="usv", warp=warp) as db, \
            broker_process(Path(tmp), platform="usv") as broker:
        env = broker.env()
        env["GOBY_MOOS_GATEWAY_PLUGINS"] = "goby3_course"
        app = 'geodesy { lat_origin: 43.8253 lon_origin: -70.3304 }'
        if warp != 1:
            app += f" simulation {{ time {{ use_sim_time: true warp_factor: {warp} }} }}"
        args = [sys.executable, "-m", "gateway.apps.moos_gateway", "--moos", f'server: "127.0.0.1" port: {db.port}',
                "--app", app]
        child = ChildProcess(args, Path(tmp) / "gw.log", name="gw", cwd=tmp, env=env).start()
        try:
            time.sleep(8.0)  # start up, connect, settle
            pid = child.pid
            t0 = time.monotonic()
            before, cpu0 = snapshot(pid)
            time.sleep(window)
            after, cpu1 = snapshot(pid)
            dt = time.monotonic() - t0
            total_v = total_i = 0
            print(f"warp {warp}, window {dt:.1f} s, threads {len(after)}")
            for tid, (name, v1, i1) in sorted(after.items(), key=lambda kv: kv[1][0]):
                _, v0, i0 = before.get(tid, (name, 0, 0))
                total_v += v1 - v0
                total_i += i1 - i0
                label = f"{name} (main)" if tid == str(pid) else name
                print(f"  {label:<24} {(v1 - v0) / dt:7.1f} voluntary/s {(i1 - i0) / dt:6.1f} involuntary/s")
            print(f"  total {total_v / dt:.1f} voluntary/s, {total_i / dt:.1f} involuntary/s; "
                  f"CPU {(cpu1 - cpu0) / TICKS / dt * 1000:.2f} ms/s")
            if os.environ.get("STRACE"):
                out = Path(tmp) / "strace.txt"
                subprocess.run(["timeout", "-s", "INT", str(window), "strace", "-f", "-c", "-o", str(out),
                                "-p", str(pid)], check=False, capture_output=True)
                print(out.read_text())
        finally:
            child.stop(15)


if __name__ == "__main__":
    main()
