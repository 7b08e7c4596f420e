"""MOOS benchmark: round trip in both client patterns, and the CPU of the DB (and clients) per message in bulk.

Compares our client + our ``moos-db`` with the C++ MOOSDB + the real pymoos, each used as its users use it:

- round trip, pattern (a) "callback": pymoos's usual pattern, ``fetch()`` and ``notify()`` inside the on-mail
  callback (the client's I/O thread); ping and echo are both written that way;
- round trip, pattern (b) "owner": the on-mail callback only wakes the owner thread, which fetches and notifies
  (the translators' and the helm's pattern; docs/ARCHITECTURE.md "Contract: MOOS");
- bulk: 300,000 doubles one way (1→1) and 20,000 to 8 subscribers (1→8), unpaced: deliveries per second, messages
  lost, and CPU seconds per 100,000 messages of the DB process and of the client processes.

Every client runs in its own child process. The real MOOSDB listens on every address, so the C++ columns run only
inside a private network namespace: when MOOSDB (``$MOOS_IVP_BIN`` or PATH) is there and this process is not in one,
the benchmark re-executes itself under ``unshare -n`` (loopback up) with ``$MOOS_IVP_BIN`` on PATH and
``$PYMOOS_PATH`` on PYTHONPATH; without the binaries, or without ``unshare``, it runs ours only and says why:

    MOOS_IVP_BIN=/path/to/moos-ivp/bin PYMOOS_PATH=/path/to/pymoos .venv/bin/python -m bench.bench_moos

``--quick`` shrinks the counts for a smoke run.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import shutil
import signal
import statistics
import sys
import tempfile
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

from bench.netns import NETNS_FLAG, reexec_in_netns
from bench.stats import markdown_table, median_p99
from gateway.moos.factory import choose_client, pymoos_available
from gateway.moos.testing import moosdb_process, private_netns, real_moos_skip_reason
from util.process import ChildProcess

HERE = Path(__file__).resolve().parents[1]


# ---- client side (child processes) --------------------------------------------------------------------------
class Waker:
    """An on-mail callback that only wakes the owner thread (pattern b)."""

    def __init__(self) -> None:
        self.event = threading.Event()

    def __call__(self) -> bool:
        self.event.set()
        return True


def connect(kind: str, port: int, name: str, registrations: list[str], on_mail: Callable[[], bool]) -> Any:
    comms = choose_client(kind).comms
    comms.set_quiet(True)  # the C++ client prints connection banners on stdout otherwise
    comms.set_on_connect_callback(lambda: all(comms.register(v, 0) for v in registrations))
    comms.set_on_mail_callback(on_mail)
    comms.run("127.0.0.1", port, name)
    if not comms.wait_until_connected(10_000):
        raise RuntimeError(f"{name} could not connect to 127.0.0.1:{port}")
    time.sleep(0.3)  # let the registrations reach the DB
    return comms


def report(**values: object) -> None:
    print("RESULT " + json.dumps(values), flush=True)


def hold_signals() -> None:
    """Block the bench's signals in every thread (call before the client starts its threads): sigwait takes them."""
    signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGUSR1, signal.SIGUSR2})


def hold() -> None:
    """Stay connected until the bench has read the DB's CPU (SIGUSR2): the C++ MOOSDB's CPU for a client is in
    that client's threads, which end when it disconnects, taking their CPU times out of /proc."""
    signal.sigtimedwait({signal.SIGUSR2}, 120)


def echo_worker(args: argparse.Namespace) -> None:
    """PING → PONG until PING -1 (or ``seconds``)."""
    ping, pong = f"PING_{args.pattern}", f"PONG_{args.pattern}"  # fresh names: a DB keeps the last run's values
    finished = threading.Event()
    if args.pattern == "callback":
        comms: Any = None

        def on_mail() -> bool:
            for msg in comms.fetch():
                if msg.key() == ping:
                    if msg.double() < 0:
                        finished.set()
                    comms.notify(pong, msg.double())
            return True

        comms = connect(args.client, args.port, args.name, [ping], on_mail)
        print("ready", flush=True)
        finished.wait(args.seconds)
    else:
        waker = Waker()
        comms = connect(args.client, args.port, args.name, [ping], waker)
        print("ready", flush=True)
        deadline = time.monotonic() + args.seconds
        while not finished.is_set() and time.monotonic() < deadline:
            if not waker.event.wait(0.5):
                continue
            waker.event.clear()
            for msg in comms.fetch():
                if msg.key() == ping:
                    if msg.double() < 0:
                        finished.set()
                    comms.notify(pong, msg.double())
    comms.close(True)


def ping_worker(args: argparse.Namespace) -> None:
    """Send PING i, wait for PONG i, ``count`` times after ``warmup``; report the round trips and our CPU."""
    ping, pong = f"PING_{args.pattern}", f"PONG_{args.pattern}"
    total = args.count + args.warmup
    samples: list[float] = []
    progress: list[float] = [0, 0.0]  # next ping, when it was sent
    done = threading.Event()
    resent = [0]

    def received(value: float, comms: Any) -> None:
        i, start = progress
        if value != float(i):
            return
        now = time.perf_counter()
        if i >= args.warmup:
            samples.append(now - start)
        progress[0] = i + 1
        if i + 1 == total:
            done.set()
            return
        progress[1] = time.perf_counter()
        comms.notify(ping, float(i + 1))

    if args.pattern == "callback":
        comms: Any = None

        def on_mail() -> bool:
            for msg in comms.fetch():
                if msg.key() == pong:
                    received(msg.double(), comms)
            return True

        comms = connect(args.client, args.port, args.name, [pong], on_mail)
        cpu0 = time.process_time()
        progress[1] = time.perf_counter()
        comms.notify(ping, 0.0)
        last: float = -1
        while not done.wait(5.0):  # a ping lost before the echo registered is sent again
            if progress[0] == last:
                resent[0] += 1
                progress[1] = time.perf_counter()
                comms.notify(ping, float(progress[0]))
            last = progress[0]
    else:
        waker = Waker()
        comms = connect(args.client, args.port, args.name, [pong], waker)
        cpu0 = time.process_time()
        progress[1] = time.perf_counter()
        comms.notify(ping, 0.0)
        while not done.is_set():
            if not waker.event.wait(5.0):
                resent[0] += 1
                progress[1] = time.perf_counter()
                comms.notify(ping, float(progress[0]))
                continue
            waker.event.clear()
            for msg in comms.fetch():
                if msg.key() == pong:
                    received(msg.double(), comms)
    cpu = time.process_time() - cpu0
    comms.notify(ping, -1.0)
    time.sleep(0.2)
    comms.close(True)
    report(samples=samples, cpu=cpu, resent=resent[0])


def sink_worker(args: argparse.Namespace) -> None:
    """Count numbered streams (``--var A,B,..``; owner pattern); report how many arrived, in order or not, and our
    CPU."""
    hold_signals()
    names = args.var.split(",")
    waker = Waker()
    comms = connect(args.client, args.port, args.name, names, waker)
    print("ready", flush=True)
    received, in_order, last = 0, True, 0.0
    expected = dict.fromkeys(names, 0)
    cpu0 = time.process_time()
    last_activity = time.monotonic() + 60  # the source may take a while to start: wait longer for the first
    while received < args.count and time.monotonic() - last_activity < args.seconds:
        if not waker.event.wait(0.2):
            continue
        waker.event.clear()
        batch = comms.fetch()
        for msg in batch:
            key = msg.key()
            if key not in expected:
                continue
            value = int(msg.double())
            if value != expected[key]:
                in_order = False
            expected[key] = value + 1
            received += 1
            last = time.time()
        if batch:
            last_activity = time.monotonic()
    report(received=received, in_order=in_order, last=last, cpu=time.process_time() - cpu0)
    hold()
    comms.close(True)


def source_worker(args: argparse.Namespace) -> None:
    """Publish ``count`` numbered doubles as fast as the client takes them (or ``--rate`` a second, one at a time,
    as a MOOS app posts); report the start and our CPU."""
    hold_signals()
    comms = connect(args.client, args.port, args.name, [], lambda: True)
    print("ready", flush=True)
    signal.sigwait({signal.SIGUSR1})  # go
    cpu0 = time.process_time()
    start = time.time()
    refused = 0
    period = 1.0 / args.rate if args.rate else 0.0
    due = time.monotonic()
    for i in range(args.count):
        refused += not comms.notify(args.var, float(i))
        if period:
            due += period
            time.sleep(max(0.0, due - time.monotonic()))
    sent = time.time()
    report(start=start, sent=sent, refused=refused, cpu=time.process_time() - cpu0)
    hold()  # connected while the sinks receive the rest
    comms.close(True)


WORKERS = {"echo": echo_worker, "ping": ping_worker, "sink": sink_worker, "source": source_worker}


# ---- the bench process --------------------------------------------------------------------------------------
def worker_args(role: str, client: str, port: int, name: str, *, pattern: str = "owner", var: str = "",
                count: int = 0, warmup: int = 0, seconds: float = 60, rate: float = 0.0) -> list[str]:
    return [sys.executable, "-m", "bench.bench_moos", "--worker", role, "--client", client, "--port", str(port),
            "--name", name, "--pattern", pattern, "--var", var, "--count", str(count), "--warmup", str(warmup),
            "--seconds", str(seconds), "--rate", str(rate)]


@contextlib.contextmanager
def child(cmd: list[str], name: str, ready: bool = True) -> Iterator[ChildProcess]:
    logs = Path(tempfile.mkdtemp(prefix=f"bench_moos_{name}_"))
    proc = ChildProcess(cmd, logs / "stdout", name=name, stderr_path=logs / "stderr.log", cwd=HERE).start()
    try:
        if ready:
            proc.wait_ready(r"^ready$", timeout=60)  # skip anything a C++ client prints first
        yield proc
    except BaseException:
        print(f"  {name} failed; its output is in {logs}", file=sys.stderr)
        raise
    else:
        shutil.rmtree(logs, ignore_errors=True)
    finally:
        if proc.wait(30) is None:
            proc.kill()
        proc.stop()


def result(proc: ChildProcess, timeout: float = 120) -> dict[str, Any]:
    """The RESULT a worker printed (it may still be connected, waiting for SIGUSR2)."""
    # A C++ client may print text without a newline just before our line, so look for the marker anywhere.
    found = proc.wait_for_output(r"RESULT (\{.*\})$", timeout)
    if found is None:
        raise RuntimeError(f"{proc.name} failed (exit {proc.returncode}): {proc.stderr_text()[-600:]}")
    values: dict[str, Any] = json.loads(found.group(1))
    return values


def release(procs: list[ChildProcess]) -> None:
    for proc in procs:
        proc.send_signal(signal.SIGUSR2)


def process_cpu(pid: int) -> float:
    """CPU seconds the live threads of a process have used so far (nanoseconds from /proc/<pid>/task/*/schedstat;
    the clock-tick counts of /proc/<pid>/stat are too coarse for 0.05 s). Threads that ended are not counted, so
    clients stay connected until it is read (``hold``)."""
    total = 0
    for stat in Path(f"/proc/{pid}/task").glob("*/schedstat"):
        try:
            total += int(stat.read_text().split()[0])
        except (OSError, ValueError, IndexError):
            continue  # a thread that just ended
    return total / 1e9


def peak_rss_mib(pid: int) -> float:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmHWM:"):
            return int(line.split()[1]) / 1024
    return 0.0


def round_trip(kind: str, port: int, pattern: str, n: int, warmup: int) -> dict[str, float]:
    echo = worker_args("echo", kind, port, "bench_echo", pattern=pattern, seconds=300)
    ping = worker_args("ping", kind, port, "bench_ping", pattern=pattern, count=n, warmup=warmup)
    with child(echo, "bench_echo"), child(ping, "bench_ping", ready=False) as pinger:
        got = result(pinger)
    median, p99 = median_p99(got["samples"])
    return {"median_us": median * 1e6, "p99_us": p99 * 1e6, "ping_cpu_us": got["cpu"] / (n + warmup) * 1e6}


def one_way(kind: str, port: int, db_pid: int, n: int, subscribers: int) -> dict[str, Any]:
    var = f"SEQ_{subscribers}"
    with contextlib.ExitStack() as stack:
        sinks = [stack.enter_context(child(worker_args("sink", kind, port, f"bench_sink{i}", var=var, count=n,
                                                       seconds=10), f"bench_sink{i}"))
                 for i in range(subscribers)]
        source = stack.enter_context(child(worker_args("source", kind, port, "bench_source", var=var, count=n),
                                           "bench_source"))
        db_cpu0 = process_cpu(db_pid)
        source.send_signal(signal.SIGUSR1)
        results = [result(p) for p in sinks]
        sent = result(source)
        db_cpu = process_cpu(db_pid) - db_cpu0
        release([*sinks, source])
    received = sum(r["received"] for r in results)
    last = max(r["last"] for r in results) or sent["sent"]
    client_cpu = sent["cpu"] + sum(r["cpu"] for r in results)
    return {
        "rate": received / max(1e-9, last - sent["start"]),  # deliveries per second, send start → last receipt
        "lost": n * subscribers - received - sent["refused"] * subscribers,
        "refused": sent["refused"],
        "in_order": all(r["in_order"] for r in results),
        # CPU per 100,000 messages *delivered* (for the fan-out: per 100,000 deliveries)
        "db_cpu": db_cpu / max(1, received) * 100_000,
        "client_cpu": client_cpu / max(1, received) * 100_000,
    }


def paced(kind: str, port: int, db_pid: int, sources: int, rate: float, seconds: float) -> dict[str, Any]:
    """``sources`` publishers posting one double at a time at ``rate`` Hz to one subscriber (a vehicle's traffic,
    not a flood): the DB's CPU per 1,000 messages when every message is its own packet."""
    n = int(rate * seconds)
    names = [f"PACED_{i}" for i in range(sources)]
    with contextlib.ExitStack() as stack:
        sink = stack.enter_context(child(worker_args("sink", kind, port, "bench_paced_sink", var=",".join(names),
                                                     count=n * sources, seconds=10), "bench_paced_sink"))
        procs = [stack.enter_context(child(worker_args("source", kind, port, f"bench_paced{i}", var=name, count=n,
                                                       rate=rate), f"bench_paced{i}"))
                 for i, name in enumerate(names)]
        db_cpu0 = process_cpu(db_pid)
        for proc in procs:
            proc.send_signal(signal.SIGUSR1)
        got = result(sink)
        sent = [result(proc) for proc in procs]
        db_cpu = process_cpu(db_pid) - db_cpu0
        release([sink, *procs])
    received = max(1, got["received"])
    return {"received": got["received"], "lost": n * sources - got["received"], "in_order": got["in_order"],
            "db_cpu_1k": db_cpu / received * 1000,
            "client_cpu_1k": (got["cpu"] + sum(r["cpu"] for r in sent)) / received * 1000}


@contextlib.contextmanager
def start_db(kind: str) -> Iterator[tuple[int, int]]:
    """Yield (port, pid) of a running DB: ``ours`` (moos-db) or ``MOOSDB`` (the C++ one)."""
    with tempfile.TemporaryDirectory() as workdir, \
            moosdb_process(workdir, community="bench", program=None if kind == "ours" else "MOOSDB") as db:
        yield db.port, db.pid


PARTS = ("rtt", "bulk", "fan", "paced")


def run_suite(db_kind: str, client_kind: str, quick: bool, parts: tuple[str, ...] = PARTS) -> dict[str, Any]:
    scale = 10 if quick else 1
    with start_db(db_kind) as (port, pid):
        row: dict[str, Any] = {"db": db_kind, "client": client_kind}
        if "rtt" in parts:
            row["rtt_a"] = round_trip(client_kind, port, "callback", 2000 // scale, 200 // scale)
            row["rtt_b"] = round_trip(client_kind, port, "owner", 2000 // scale, 200 // scale)
        if "bulk" in parts:
            row["bulk"] = one_way(client_kind, port, pid, 300_000 // scale, 1)
        if "fan" in parts:
            row["fan"] = one_way(client_kind, port, pid, 20_000 // scale, 8)
        if "paced" in parts:
            row["paced"] = paced(client_kind, port, pid, 5, 200.0, 5.0 / (5 if quick else 1))
        row["db_peak_mib"] = peak_rss_mib(pid)
    return row


def median_row(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """The median of every figure over repeated runs of one combination (flags: all of them)."""
    merged: dict[str, Any] = {}
    for key, value in rows[0].items():
        if isinstance(value, dict):
            merged[key] = median_row([r[key] for r in rows])
        elif isinstance(value, bool):
            merged[key] = all(r[key] for r in rows)
        elif isinstance(value, (int, float)):
            merged[key] = statistics.median(r[key] for r in rows)
        else:
            merged[key] = value
    return merged


def table(rows: list[dict[str, Any]]) -> str:
    header = ["DB", "client", "RTT (a) callback med / p99", "RTT (b) owner med / p99", "ping CPU/rt (a, b)",
              "1→1 msg/s (lost)", "DB CPU s/100k (1→1)", "clients CPU s/100k (1→1)", "1→8 del/s (lost)",
              "DB CPU s/100k del (1→8)", "paced 5×200 Hz: DB CPU ms/1k (lost)", "paced: clients CPU ms/1k",
              "DB peak RSS"]
    lines = []
    for r in rows:
        cells = [r["db"], r["client"]]
        if "rtt_a" in r:
            a, b = r["rtt_a"], r["rtt_b"]
            cells += [f"{a['median_us']:,.0f} / {a['p99_us']:,.0f} µs", f"{b['median_us']:,.0f} / {b['p99_us']:,.0f} µs",
                      f"{a['ping_cpu_us']:,.0f} / {b['ping_cpu_us']:,.0f} µs"]
        else:
            cells += ["-"] * 3
        if "bulk" in r:
            bulk = r["bulk"]
            order = "" if bulk["in_order"] else " REORDERED"
            cells += [f"{bulk['rate']:,.0f} ({bulk['lost']:,.0f}){order}", f"{bulk['db_cpu']:.3f}",
                      f"{bulk['client_cpu']:.3f}"]
        else:
            cells += ["-"] * 3
        if "fan" in r:
            fan = r["fan"]
            order = "" if fan["in_order"] else " REORDERED"
            cells += [f"{fan['rate']:,.0f} ({fan['lost']:,.0f}){order}", f"{fan['db_cpu']:.3f}"]
        else:
            cells += ["-"] * 2
        if "paced" in r:
            order = "" if r["paced"]["in_order"] else " REORDERED"
            cells.append(f"{r['paced']['db_cpu_1k'] * 1000:.1f} ({r['paced']['lost']:,.0f}){order}")
            cells.append(f"{r['paced']['client_cpu_1k'] * 1000:.1f}")
        else:
            cells += ["-"] * 2
        cells.append(f"{r['db_peak_mib']:.0f} MiB")
        lines.append(cells)
    return markdown_table(header, lines)


LEGEND = ("RTT: A notifies PING, B echoes PONG, A receives it (median / p99 of the samples). (a): fetch+notify inside "
          "the on-mail callback (pymoos's usual pattern); (b): on-mail wakes the owner thread, which fetches and "
          "notifies. ping CPU/rt: CPU of the pinging process per round trip. 1→1: 300,000 doubles unpaced, send start "
          "to last receipt; lost = never received and not refused. DB CPU: CPU seconds of the DB process per 100,000 "
          "messages delivered (1→8: per 100,000 deliveries); clients CPU: source + sinks. paced: 5 publishers posting one "
          "double every 5 ms each for 5 s to one subscriber; DB CPU, and the 6 clients' CPU, in ms per 1,000 messages.")


# ---- the private network namespace for the real MOOSDB -----------------------------------------------------

def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    parser = argparse.ArgumentParser(prog="bench_moos", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="a tenth of the counts")
    parser.add_argument("--ours-only", action="store_true", help="skip the C++ MOOSDB and pymoos")
    parser.add_argument("--only", default=",".join(PARTS),
                        help=f"comma-separated parts to run, of {', '.join(PARTS)} (default all)")
    parser.add_argument("--repeat", type=int, default=1,
                        help="run every combination N times, interleaved, and report the medians")
    parser.add_argument(NETNS_FLAG, action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--worker", choices=sorted(WORKERS), help=argparse.SUPPRESS)
    parser.add_argument("--client", default="ours", help=argparse.SUPPRESS)
    parser.add_argument("--pattern", default="owner", choices=["callback", "owner"], help=argparse.SUPPRESS)
    parser.add_argument("--port", type=int, default=0, help=argparse.SUPPRESS)
    parser.add_argument("--name", default="", help=argparse.SUPPRESS)
    parser.add_argument("--var", default="", help=argparse.SUPPRESS)
    parser.add_argument("--count", type=int, default=0, help=argparse.SUPPRESS)
    parser.add_argument("--warmup", type=int, default=0, help=argparse.SUPPRESS)
    parser.add_argument("--seconds", type=float, default=60, help=argparse.SUPPRESS)
    parser.add_argument("--rate", type=float, default=0.0, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.worker:
        WORKERS[args.worker](args)
        return 0

    if not args.ours_only and not args.in_netns and not private_netns():
        env = dict(os.environ)
        if env.get("MOOS_IVP_BIN"):
            env["PATH"] = env["MOOS_IVP_BIN"] + os.pathsep + env.get("PATH", "")
        if env.get("PYMOOS_PATH"):
            env["PYTHONPATH"] = os.pathsep.join(p for p in (env.get("PYTHONPATH"), env["PYMOOS_PATH"]) if p)
        if shutil.which("MOOSDB", path=env.get("PATH")) is None:
            print("(C++ columns skipped: the real MOOSDB is not on PATH (set MOOS_IVP_BIN to the MOOS-IvP bin "
                  "directory))", flush=True)
        else:
            status = reexec_in_netns("bench.bench_moos", argv, "C++ columns", "the real MOOSDB listens on all "
                                     "addresses", env=env, say=lambda line: print(line, flush=True))
            if status is not None:
                return status
    combos = [("ours", "ours")]
    if not args.ours_only:
        real_db = real_moos_skip_reason("MOOSDB") is None
        if real_db:
            combos.append(("MOOSDB", "ours"))
        if pymoos_available():
            if real_db:
                combos.append(("MOOSDB", "pymoos"))
            combos.append(("ours", "pymoos"))
        else:
            print("(pymoos columns skipped: pymoos is not importable; set PYMOOS_PATH)")
    parts = tuple(p for p in args.only.split(",") if p)
    unknown = set(parts) - set(PARTS)
    if unknown:
        parser.error(f"--only: unknown part(s) {', '.join(sorted(unknown))}; expected {', '.join(PARTS)}")
    runs: dict[tuple[str, str], list[dict[str, Any]]] = {combo: [] for combo in combos}
    for round_number in range(max(1, args.repeat)):
        for db_kind, client_kind in combos:  # interleaved, so a change of load spreads over every combination
            print(f"running: DB={db_kind} client={client_kind} (run {round_number + 1}) ...", flush=True)
            runs[(db_kind, client_kind)].append(run_suite(db_kind, client_kind, args.quick, parts))
            print(table(runs[(db_kind, client_kind)][-1:]), flush=True)
    rows = [median_row(runs[combo]) for combo in combos]
    print()
    if args.repeat > 1:
        print(f"medians of {args.repeat} runs:")
    print(table(rows))
    print(LEGEND)
    if len(rows) > 1:
        summary(rows)
    return 0


def summary(rows: list[dict[str, Any]]) -> None:
    """The issue's targets: our round trip vs C++ MOOSDB + pymoos, our DB's CPU per message vs MOOSDB's."""
    by = {(r["db"], r["client"]): r for r in rows}
    ours, cpp = by.get(("ours", "ours")), by.get(("MOOSDB", "pymoos"))
    if ours and cpp and "rtt_a" in ours:
        for key, what in (("rtt_a", "(a) callback"), ("rtt_b", "(b) owner")):
            print(f"round trip {what}: ours {ours[key]['median_us']:,.0f} µs vs MOOSDB+pymoos "
                  f"{cpp[key]['median_us']:,.0f} µs (ratio {ours[key]['median_us'] / cpp[key]['median_us']:.2f})")
    for client in ("ours", "pymoos"):
        a, b = by.get(("ours", client)), by.get(("MOOSDB", client))
        if a and b:
            for key in ("bulk", "fan"):
                if key not in a:
                    continue
                ratio = a[key]["db_cpu"] / max(1e-9, b[key]["db_cpu"])
                print(f"DB CPU per message, {key}, {client} clients: moos-db {a[key]['db_cpu']:.3f} s/100k vs MOOSDB "
                      f"{b[key]['db_cpu']:.3f} s/100k (ratio {ratio:.2f})")
            if "paced" not in a:
                continue
            ours_ms, cpp_ms = a["paced"]["db_cpu_1k"] * 1000, b["paced"]["db_cpu_1k"] * 1000
            print(f"DB CPU per message, paced, {client} clients: moos-db {ours_ms:.1f} ms/1k vs MOOSDB {cpp_ms:.1f} "
                  f"ms/1k (ratio {ours_ms / max(1e-9, cpp_ms):.2f})")
    print(f"(load average at the end: {', '.join(f'{x:.2f}' for x in os.getloadavg())})")


if __name__ == "__main__":
    sys.exit(main())
