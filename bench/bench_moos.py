"""MOOS benchmark: round trip, one-way throughput, 1 KiB strings and 1→8 fan-out between client processes.

Runs our client against our DB always; adds the real MOOSDB and the real pymoos when they are on PATH /
importable and this process is inside a private network namespace (the C++ MOOSDB listens on all addresses):
    /opt/moos/bin/netns-run env PATH=/opt/moos/bin:$PATH PYTHONPATH=/opt/moos/pysite .venv/bin/python -m bench.bench_moos
Every client uses the integration-contract pattern: the on-mail callback only wakes the client's own thread,
which then calls fetch(). ``--quick`` shrinks the counts for a smoke run.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import statistics
import sys
import tempfile
import threading
import time
from collections.abc import Iterator
from pathlib import Path

from bench.stats import median_p99
from gateway.moos.factory import choose_client, pymoos_available
from gateway.moos.testing import moosdb_process, real_moos_skip_reason
from util.process import ChildProcess

HERE = Path(__file__).resolve().parents[1]


# ---- client side helpers ---------------------------------------------------------------------------------
class Waker:
    """An on-mail callback that only wakes the owner thread (the contract translators and the helm follow)."""

    def __init__(self) -> None:
        self.event = threading.Event()
        self.stamp = 0.0  # when the client announced mail (for the mail → fetch latency)

    def __call__(self) -> bool:
        self.stamp = time.perf_counter()
        self.event.set()
        return True


def connect(kind: str, port: int, name: str, registrations: list[str]) -> tuple[object, Waker]:
    comms = choose_client(kind).comms
    comms.set_quiet(True)  # the C++ client prints connection banners on stdout otherwise
    waker = Waker()
    comms.set_on_connect_callback(lambda: all(comms.register(v, 0) for v in registrations))
    comms.set_on_mail_callback(waker)
    comms.run("127.0.0.1", port, name)
    if not comms.wait_until_connected(10_000):
        raise RuntimeError(f"{name} could not connect to 127.0.0.1:{port}")
    time.sleep(0.3)  # let the registrations reach the DB
    return comms, waker


def worker(args: argparse.Namespace) -> int:
    """Child process roles: ``echo`` (PING → PONG) and ``sink`` (count a numbered stream)."""
    if args.worker == "echo":
        comms, waker = connect(args.client, args.port, args.name, ["PING"])
        print("ready", flush=True)
        deadline = time.monotonic() + args.seconds
        while time.monotonic() < deadline:
            if not waker.event.wait(0.5):
                continue
            waker.event.clear()
            for msg in comms.fetch():
                if msg.key() == "PING":
                    if msg.double() < 0:
                        deadline = 0
                    comms.notify("PONG", msg.double())
        comms.close(True)
        return 0
    comms, waker = connect(args.client, args.port, args.name, [args.var])
    print("ready", flush=True)
    received, in_order, expected, first, last = 0, True, 0, 0.0, 0.0
    idle_limit = args.seconds
    last_activity = time.monotonic()
    while received < args.count and time.monotonic() - last_activity < idle_limit:
        if not waker.event.wait(0.2):
            continue
        waker.event.clear()
        batch = comms.fetch()
        now = time.time()
        for msg in batch:
            if msg.key() != args.var:
                continue
            value = int(msg.double()) if msg.is_double() else int(msg.string().split(":", 1)[0])
            if value != expected:
                in_order = False
            expected = value + 1
            received += 1
            first = first or now
            last = now
        if batch:
            last_activity = time.monotonic()
    print(json.dumps({"received": received, "in_order": in_order, "first": first, "last": last,
                      "cpu": time.process_time()}), flush=True)
    comms.close(True)
    return 0


@contextlib.contextmanager
def child(role: str, client: str, port: int, name: str, var: str = "", count: int = 0,
          seconds: float = 60) -> Iterator[ChildProcess]:
    cmd = [sys.executable, "-m", "bench.bench_moos", "--worker", role, "--client", client, "--port", str(port),
           "--name", name, "--var", var, "--count", str(count), "--seconds", str(seconds)]
    logs = Path(tempfile.mkdtemp(prefix=f"bench_moos_{name}_"))
    proc = ChildProcess(cmd, logs / "stdout", name=name, stderr_path=logs / "stderr.log", cwd=HERE).start()
    try:
        proc.wait_ready(r"^ready$", timeout=60)  # skip anything a C++ client prints first
        yield proc
    finally:
        if proc.wait(seconds + 10) is None:
            proc.kill()
        proc.stop()


def sink_result(proc: ChildProcess) -> dict[str, object]:
    proc.wait(60)
    out = proc.output()
    # A C++ client may print text without a newline just before our JSON, so look for the JSON itself.
    lines = ["{" + line.split("{", 1)[1] for line in out.splitlines() if '{"received"' in line]
    if not lines:
        tail = proc.stderr_text()[-300:]
        print(f"  a sink failed (exit {proc.returncode}): {tail!r} {out[-300:]!r}", file=sys.stderr)
        return {"received": 0, "in_order": False, "first": 0.0, "last": 0.0}
    return json.loads(lines[-1])


# ---- measurements ----------------------------------------------------------------------------------------
def round_trip(kind: str, port: int, n: int, warmup: int) -> dict[str, float]:
    with child("echo", kind, port, "bench_echo", seconds=120):
        comms, waker = connect(kind, port, "bench_ping", ["PONG"])
        samples = []
        handoffs = []
        try:
            for i in range(warmup + n):
                waker.event.clear()
                start = time.perf_counter()
                comms.notify("PING", float(i))
                got = False
                while not got:
                    if not waker.event.wait(5):
                        raise RuntimeError(f"no PONG for ping {i}")
                    waker.event.clear()
                    mail = comms.fetch()
                    fetched = time.perf_counter()
                    got = any(m.key() == "PONG" and m.double() == float(i) for m in mail)
                if i >= warmup:
                    samples.append(time.perf_counter() - start)
                    handoffs.append(fetched - waker.stamp)
            comms.notify("PING", -1.0)
        finally:
            comms.close(True)
    median, p99 = median_p99(samples)
    return {"median_us": median * 1e6, "p99_us": p99 * 1e6,
            "handoff_us": statistics.median(handoffs) * 1e6}


def one_way(kind: str, port: int, n: int, subscribers: int = 1, payload: str | None = None) -> dict[str, float]:
    var = f"SEQ_{subscribers}_{'S' if payload else 'D'}"
    with contextlib.ExitStack() as stack:
        sinks = [stack.enter_context(child("sink", kind, port, f"bench_sink{i}", var, n, seconds=10))
                 for i in range(subscribers)]
        comms, _ = connect(kind, port, "bench_source", [])
        start = time.time()
        refused = 0
        for i in range(n):
            ok = comms.notify(var, f"{i}:{payload}") if payload else comms.notify(var, float(i))
            refused += not ok
        sent = time.time()
        results = [sink_result(p) for p in sinks]
        comms.close(True)
    last = max(r["last"] for r in results) or sent  # type: ignore[type-var]
    received = sum(r["received"] for r in results)  # type: ignore[misc]
    return {
        "rate": received / max(1e-9, last - start),  # deliveries per second, send start → last receipt
        "sent_rate": n / max(1e-9, sent - start),
        "lost": n * subscribers - received,
        "in_order": all(r["in_order"] for r in results),
        "refused": refused,
    }


# ---- DBs ---------------------------------------------------------------------------------------------------
@contextlib.contextmanager
def start_db(kind: str) -> Iterator[tuple[int, int]]:
    """Yield (port, pid) of a running DB: ``ours`` (moos-db) or ``MOOSDB`` (the C++ one)."""
    with tempfile.TemporaryDirectory() as workdir, \
            moosdb_process(workdir, community="bench", program=None if kind == "ours" else "MOOSDB") as db:
        yield db.port, db.pid


def process_stats(pid: int) -> tuple[float, float]:
    """(CPU seconds used so far, peak resident MiB) of a process, from /proc."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    cpu = (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
    peak = 0.0
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmHWM:"):
            peak = int(line.split()[1]) / 1024
    return cpu, peak


def run_suite(db_kind: str, client_kind: str, quick: bool) -> dict[str, object]:
    scale = 10 if quick else 1
    with start_db(db_kind) as (port, pid):
        t0 = time.monotonic()
        rtt = round_trip(client_kind, port, 2000 // scale, 200 // scale)
        doubles = one_way(client_kind, port, 50_000 // scale)
        strings = one_way(client_kind, port, 20_000 // scale, payload="x" * 1024)
        fan = one_way(client_kind, port, 20_000 // scale, subscribers=8)
        cpu, peak = process_stats(pid)
        wall = time.monotonic() - t0
    return {"db": db_kind, "client": client_kind, "rtt": rtt, "doubles": doubles, "strings": strings, "fan": fan,
            "server_cpu_pct": 100 * cpu / wall, "server_peak_mib": peak}


def print_table(rows: list[dict[str, object]]) -> None:
    head = (f"{'DB':<7} {'client':<7} {'rtt med':>8} {'rtt p99':>8} {'mail→fetch':>10} {'dbl/s':>9} {'lost':>6} {'1KiB/s':>8} "
            f"{'lost':>5} {'1→8 del/s':>10} {'lost':>6} {'order':>5} {'srv cpu':>7} {'srv MiB':>7}")
    print(head)
    print("-" * len(head))
    for r in rows:
        d, s, f = r["doubles"], r["strings"], r["fan"]
        order = "ok" if d["in_order"] and s["in_order"] and f["in_order"] else "BAD"
        print(f"{r['db']:<7} {r['client']:<7} {r['rtt']['median_us']:>6.0f}us {r['rtt']['p99_us']:>6.0f}us "
              f"{r['rtt']['handoff_us']:>8.0f}us "
              f"{d['rate']:>9.0f} {d['lost']:>6} {s['rate']:>8.0f} {s['lost']:>5} {f['rate']:>10.0f} {f['lost']:>6} "
              f"{order:>5} {r['server_cpu_pct']:>6.0f}% {r['server_peak_mib']:>7.1f}")
    print("rtt: A notifies, B echoes, A receives (median, p99). mail→fetch: from the on-mail callback (client's"
          " thread) to fetch() returning on the owner thread (median). dbl/s: 50,000 doubles one way, unpaced, send start"
          " to last receipt; lost = never received. 1→8: deliveries/s to 8 subscriber processes.")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="bench_moos", description=__doc__)
    parser.add_argument("--quick", action="store_true", help="a tenth of the counts")
    parser.add_argument("--worker", choices=["echo", "sink"], help=argparse.SUPPRESS)
    parser.add_argument("--client", default="ours", help=argparse.SUPPRESS)
    parser.add_argument("--port", type=int, default=0, help=argparse.SUPPRESS)
    parser.add_argument("--name", default="", help=argparse.SUPPRESS)
    parser.add_argument("--var", default="", help=argparse.SUPPRESS)
    parser.add_argument("--count", type=int, default=0, help=argparse.SUPPRESS)
    parser.add_argument("--seconds", type=float, default=60, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.worker:
        return worker(args)

    combos = [("ours", "ours")]
    real_db = real_moos_skip_reason("MOOSDB") is None
    if real_db:
        combos.append(("MOOSDB", "ours"))
    if pymoos_available():
        if real_db:
            combos.append(("MOOSDB", "pymoos"))
        combos.append(("ours", "pymoos"))
    if not real_db:
        print("(the real MOOSDB is not on PATH or this is not a private network namespace: ours only)")
    rows = []
    for db_kind, client_kind in combos:
        print(f"running: DB={db_kind} client={client_kind} ...", flush=True)
        rows.append(run_suite(db_kind, client_kind, args.quick))
        print_table(rows[-1:])
    print()
    print_table(rows)
    return 0


if __name__ == "__main__":
    sys.exit(main())
