"""Logging speed: goby-logger against the real goby_logger, goby-log-tool's read speed, a day's log to MCAP.

``python -m bench.bench_logger [--rates 25000,50000,...] [--seconds 2] [--runs 3] [--read-entries 300000]
[--trail-log USV.goby | --trail-seconds 300] [--hours 24] [--python-only] [--parts logger,read,trail]``

1. **Logger**: one publisher (this process, a PortalClient publishing pre-serialized ``Sample`` messages of 12-16
   bytes, paced per millisecond) on a broker with a logger, for each rate of ``--rates`` in turn: a fresh broker and
   logger per rate, ``--seconds`` of publishing, then the logger is stopped (which flushes its file) and its log
   read: lost = published - logged. Ours: ``goby-broker`` + ``goby-logger``; C++: ``gobyd`` + ``goby_logger``
   (from ``$GOBY_BIN_DIR`` or PATH, their libraries from ``../lib``), run only inside a private network namespace
   (the real gobyd listens on every address): the benchmark re-executes itself under ``unshare -n`` as
   bench_platform does. Each rate runs ``--runs`` times (the runs interleaved); the figure is the highest rate
   kept with nothing lost in every run; the logger's CPU per message (utime + stime over the step) is beside it.
2. **Reader**: a log of ``--read-entries`` small protobuf entries read by ``LogReader`` (entries/s), then with every
   entry decoded as goby-log-tool's DEBUG_TEXT does before formatting (``EntryDecoder.decode``: the message
   objects), then formatted into DEBUG_TEXT lines.
3. **A day's log to MCAP**: the rate of a short trail-mission run (``--trail-log``: a USV log of such a run, or
   by default ``python -m launch.trail.demo --duration --trail-seconds`` run here with ``goby-logger`` on each
   platform's broker, warped as the mission so the log's times are simulated seconds): entries and bytes per
   simulated second of each platform's log, scaled to ``--hours``. The busiest platform's log is then built at
   that size by repeating its entries (timestamps shifted by the short log's span each time) and converted with
   ``goby-log-tool --format MCAP`` (wall time of the process, the MCAP file validated by the mcap reader).

Progress goes to stderr, tables to stdout; docs/bench.md ("Logging") has the figures.
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from bench.netns import NETNS_FLAG, cpp_side_here
from bench.progress import progress
from bench.stats import markdown_table
from gateway.goby.log import FILE_DESCRIPTOR_GROUP, EntryDecoder, LogReader, LogWriter, debug_text_line
from gateway.goby.portal import Scheme
from gateway.goby.portal.testing import PortalClient, app_process, broker_process
from gateway.goby.protobuf.interprocess_config_pb2 import InterProcessPortalConfig
from tests.goby3_real import interprocess_text, short_ipc_dir
from tests.protobuf.sample_messages_pb2 import Sample
from util.cli import bounded_number
from util.process import ChildProcess

HERE = Path(__file__).resolve().parent.parent
PY = sys.executable
GROUP = "bench::log"
TYPE = Sample.DESCRIPTOR.full_name
TRAIL_PLATFORMS = ("topside", "usv", "auv0", "auv1", "auv2", "auv3")
TRAIL_WARP = 10



# ---- 1. the logger under one publisher --------------------------------------------------------------------------
@dataclass(frozen=True)
class Step:
    rate: int
    published: int
    achieved: float  # messages per second the publisher managed
    logged: int
    cpu_s: float  # the logger's CPU seconds over the step

    @property
    def lost(self) -> int:
        return self.published - self.logged


def find_cpp() -> tuple[dict[str, str], str | None]:
    """gobyd and goby_logger from $GOBY_BIN_DIR or PATH, or why not."""
    found: dict[str, str] = {}
    search = os.pathsep.join(p for p in (os.environ.get("GOBY_BIN_DIR"), os.environ.get("PATH")) if p)
    for name in ("gobyd", "goby_logger"):
        path = shutil.which(name, path=search)
        if path is None:
            return {}, f"the real {name} is not in $GOBY_BIN_DIR or on PATH"
        found[name] = path
    return found, None


def cpp_env(programs: dict[str, str]) -> dict[str, str]:
    lib = Path(programs["gobyd"]).resolve().parent.parent / "lib"
    env = dict(os.environ)
    if lib.is_dir():
        env["LD_LIBRARY_PATH"] = os.pathsep.join(p for p in (str(lib), env.get("LD_LIBRARY_PATH")) if p)
    return env


def cpu_seconds(pid: int) -> float:
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except OSError:
        return 0.0
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def count_logged(path: Path) -> int:
    if not path.exists():
        return 0
    with LogReader(path, on_skip=lambda span: None) as reader:
        return sum(1 for e in reader if e.group == GROUP)


def wait_logging(client: PortalClient, path: Path, logger: ChildProcess) -> None:
    """Publish on "sync" until the logger has written one (its subscription is in place); C++ goby_logger writes
    through a 4 KiB buffer, so the sync messages carry padding."""
    deadline = time.monotonic() + 30
    while True:
        with LogReader(path, on_skip=lambda span: None) if path.exists() else _nothing() as reader:
            if reader is not None and any(e.group == "sync" for e in reader):
                return
        if time.monotonic() > deadline or logger.poll() is not None:
            raise RuntimeError(f"the logger never logged the sync group: {logger.tail()}")
        client.publish("sync", Sample(a=1, padding=b"s" * 1000))
        client.poll(0.02)


@contextmanager
def _nothing() -> Iterator[None]:
    yield None


def publish_paced(client: PortalClient, rate: int, seconds: float) -> tuple[int, float]:
    """Publish ``rate * seconds`` pre-serialized Samples at ``rate``/s (checked every millisecond)."""
    total = int(rate * seconds)
    payloads = [Sample(a=i, depth=i * 0.25).SerializeToString() for i in range(total)]
    publish = client.portal.publish_serialized
    start = time.perf_counter()
    sent = 0
    while sent < total:
        due = min(total, int((time.perf_counter() - start) * rate) + 1)
        while sent < due:
            publish(GROUP, Scheme.PROTOBUF, TYPE, payloads[sent])
            sent += 1
        if sent < total:
            ahead = sent / rate - (time.perf_counter() - start)
            if ahead > 0.0005:
                client.poll(ahead)
    elapsed = time.perf_counter() - start
    client.poll(0.2)
    return total, total / elapsed


def logger_step(side: str, rate: int, seconds: float, programs: dict[str, str], work: Path) -> Step:
    """A fresh broker and logger, ``rate`` msgs/s for ``seconds``, then count the log."""
    step_dir = work / f"{side}_{rate}"
    step_dir.mkdir(parents=True)
    log_path = step_dir / "bench.goby"
    omit = "--omit", "file_timestamp: true latest_symlink: true"
    if side == "python":
        with broker_process(step_dir, platform="bench") as broker:
            logger = app_process([PY, "-m", "gateway.apps.goby_logger", "--log_dir", str(step_dir), *omit,
                                  "--interprocess", broker.interprocess_text()], step_dir / "logger.log")
            return _run_step(broker.interprocess_config(), logger, log_path, rate, seconds)
    ipc_dir = short_ipc_dir()
    ipc = InterProcessPortalConfig(platform="bench", socket_name=str(ipc_dir / "goby_bench"))
    env = cpp_env(programs)
    gobyd = app_process([programs["gobyd"], "--interprocess", interprocess_text(ipc)], step_dir / "gobyd.log",
                        env=env)
    logger = app_process([programs["goby_logger"], "--log_dir", str(step_dir), "--omit",
                          "file_timestamp: true latest_symlink: true", "--interprocess", interprocess_text(ipc)],
                         step_dir / "logger.log", env=env)
    try:
        return _run_step(ipc, logger, log_path, rate, seconds)
    finally:
        gobyd.stop()
        shutil.rmtree(ipc_dir, ignore_errors=True)


def _run_step(ipc: InterProcessPortalConfig, logger: ChildProcess, log_path: Path, rate: int,
              seconds: float) -> Step:
    try:
        with PortalClient(ipc, "bench_publisher") as client:
            if not client.wait_ready():
                raise RuntimeError("the publisher never connected to the broker")
            wait_logging(client, log_path, logger)
            cpu0 = cpu_seconds(logger.pid)
            published, achieved = publish_paced(client, rate, seconds)
            # drained: the logger's CPU stops growing (it has written what reached it)
            last, still = cpu_seconds(logger.pid), 0
            while still < 3:
                client.poll(0.1)
                now = cpu_seconds(logger.pid)
                still = still + 1 if now - last < 0.005 else 0
                last = now
            cpu = last - cpu0
    finally:
        logger.stop(30)
    return Step(rate, published, achieved, count_logged(log_path), cpu)


def logger_table(results: dict[str, dict[int, list[Step]]]) -> str:
    rows = []
    for side, by_rate in results.items():
        for rate, steps in by_rate.items():
            rows.append([side, f"{rate:,}", f"{statistics.median(s.achieved for s in steps):,.0f}",
                         f"{steps[0].published:,}", ", ".join(f"{s.lost:,}" for s in steps),
                         f"{statistics.median(s.cpu_s for s in steps) / steps[0].published * 1e6:.1f}"])
    return markdown_table(["logger", "rate asked /s", "published /s (median)", "published per run",
                           "lost per run", "logger CPU µs/msg (median)"], rows)


def kept_rate(by_rate: dict[int, list[Step]]) -> str:
    kept = [min(s.achieved for s in steps) for steps in by_rate.values() if steps and all(s.lost == 0 for s in steps)]
    return f"{max(kept):,.0f}/s" if kept else "none"


# ---- 2. reading -------------------------------------------------------------------------------------------------
def reader_figures(n: int, work: Path) -> list[list[str]]:
    path = work / "read.goby"
    t0 = 1_795_000_000_000_000
    with open(path, "wb") as f:
        writer = LogWriter(f.write, lambda: t0)
        for i in range(n):
            writer.write(Sample(a=i, depth=i * 0.25).SerializeToString(), Scheme.PROTOBUF, TYPE, GROUP, t0 + i)
    rows = []
    for label, work_fn in (("LogReader: entries", None), ("+ EntryDecoder.decode (messages)", "decode"),
                           ("+ DEBUG_TEXT lines", "text")):
        best, count = 0.0, 0
        for _ in range(3):
            with LogReader(path) as reader:
                decoder = EntryDecoder(reader.descriptors)
                start = time.perf_counter()
                count = 0
                if work_fn is None:
                    for _entry in reader:
                        count += 1
                elif work_fn == "decode":
                    decode = decoder.decode
                    for entry in reader:
                        decode(entry)
                        count += 1
                else:
                    decode = decoder.decode
                    for entry in reader:
                        debug_text_line(entry, decode(entry))
                        count += 1
                rate = count / (time.perf_counter() - start)
            best = max(best, rate)
        rows.append([label, f"{count:,}", f"{best:,.0f}"])
    size = path.stat().st_size
    path.unlink()
    rows.append(["(log size)", f"{size / 2**20:.1f} MiB", ""])
    return rows


# ---- 3. a day of the trail mission to MCAP ----------------------------------------------------------------------
@dataclass(frozen=True)
class PlatformRate:
    platform: str
    path: Path
    entries: int
    size: int
    span_s: float  # simulated seconds between the first and last entry

    @property
    def per_s(self) -> tuple[float, float]:
        return self.entries / self.span_s, self.size / self.span_s


def trail_run(seconds: float, work: Path) -> dict[str, Path]:
    """A short trail demo (``launch.trail.demo``) with goby-logger on every platform's broker; the logs."""
    out = work / "trail"
    log_dir = work / "trail_logs"
    log_dir.mkdir()
    progress(f"trail: running the trail mission for {seconds:g} simulated s (warp {TRAIL_WARP}) with a logger on "
             "every platform")
    demo = subprocess.Popen([PY, "-m", "launch.trail.demo", "--out", str(out), "--duration", str(seconds),
                             "--warp", str(TRAIL_WARP)], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                            text=True, cwd=HERE)
    loggers: list[ChildProcess] = []
    warp = f"simulation {{ time {{ use_sim_time: true warp_factor: {TRAIL_WARP} }} }}"
    try:
        for name in TRAIL_PLATFORMS:
            socket = out / "run" / f"goby_{name}"
            deadline = time.monotonic() + 180
            while not Path(f"{socket}.manager").exists():
                if demo.poll() is not None or time.monotonic() > deadline:
                    raise RuntimeError(f"the trail demo never started {name}'s broker: {demo.stderr.read()[-500:]}"
                                       if demo.stderr else "the trail demo failed")
                time.sleep(0.2)
            loggers.append(app_process(
                [PY, "-m", "gateway.apps.goby_logger", "--log_dir", str(log_dir), "--app", warp, *trail_modules(),
                 "--interprocess", f'platform: "{name}" socket_name: "{socket}"'], work / f"logger_{name}.log",
                cwd=HERE))
        if demo.wait(seconds / TRAIL_WARP + 600) != 0:
            progress(f"trail: the demo exited {demo.returncode} (the logs are used anyway)")
    finally:
        if demo.poll() is None:
            demo.send_signal(signal.SIGINT)
            demo.wait(60)
        for logger in loggers:
            logger.send_signal(signal.SIGTERM)
        for logger in loggers:
            logger.stop(30)
    return {name: log_dir / f"{name}_latest.goby" for name in TRAIL_PLATFORMS}


def platform_rate(platform: str, path: Path) -> PlatformRate:
    with LogReader(path, on_skip=lambda span: None) as reader:
        times = [e.timestamp_micro for e in reader]
        size = reader.size
    return PlatformRate(platform, path, len(times), size, max(1e-6, (max(times) - min(times)) / 1e6))


def build_day(source: Path, target: Path, seconds: float) -> tuple[int, int]:
    """``target``: the entries of ``source`` repeated, shifted by its span each time, until ``seconds`` long (its
    descriptor entries once, at the start, as a logger writes them)."""
    with LogReader(source, on_skip=lambda span: None, include_descriptors=True) as reader:
        entries = [(e.data, e.scheme, e.type_name, e.group, e.timestamp_micro) for e in reader]
    described = [e for e in entries if e[3] == FILE_DESCRIPTOR_GROUP]
    entries = [e for e in entries if e[3] != FILE_DESCRIPTOR_GROUP]
    t0, t1 = entries[0][4], entries[-1][4]
    span = max(1, t1 - t0 + 1)
    count = 0
    with open(target, "wb", buffering=4 * 2**20) as f:
        writer = LogWriter(f.write, lambda: t0, describe_protobuf=False)
        for data, scheme, type_name, group, _ in described:
            writer.write(data, scheme, type_name, group, t0)
        shift = 0
        while shift < seconds * 1e6:
            for data, scheme, type_name, group, t in entries:
                writer.write(data, scheme, type_name, group, t + shift)
            count += len(entries)
            shift += span
    return count, target.stat().st_size


def mcap_day(rates: list[PlatformRate], hours: float, work: Path) -> list[list[str]]:
    busiest = max(rates, key=lambda r: r.size / r.span_s)
    day = work / f"{busiest.platform}_day.goby"
    progress(f"trail: building a {hours:g} h log of {busiest.platform} from its {busiest.span_s:.0f} s log")
    entries, size = build_day(busiest.path, day, hours * 3600)
    out = work / f"{busiest.platform}_day.mcap"
    progress(f"trail: converting {size / 2**30:.2f} GiB ({entries:,} entries) to MCAP")
    start = time.perf_counter()
    run = subprocess.run([PY, "-m", "gateway.apps.goby_log_tool", str(day), str(out), "--format", "MCAP",
                          *trail_modules()], capture_output=True, text=True, cwd=HERE)
    elapsed = time.perf_counter() - start
    if run.returncode != 0:
        raise RuntimeError(f"goby-log-tool exited {run.returncode}: {run.stderr[-800:]}")
    from mcap.reader import make_reader  # noqa: PLC0415 - the log extra

    with open(out, "rb") as f:
        summary = make_reader(f, validate_crcs=True).get_summary()
    messages = summary.statistics.message_count if summary and summary.statistics else 0
    mcap_size = out.stat().st_size
    day.unlink()
    out.unlink()
    for line in run.stderr.splitlines():
        if "kept as bytes" in line or "left out" in line:
            progress(f"trail: {line}")
    return [[f"{busiest.platform}, {hours:g} h", f"{size / 2**30:.2f} GiB", f"{entries:,}", f"{messages:,}",
             f"{mcap_size / 2**20:.0f} MiB", f"{elapsed:.1f}", f"{entries / elapsed:,.0f}",
             f"{size / elapsed / 2**20:.0f}"]]


def trail_modules() -> list[str]:
    """The trail mission's protobuf modules, so the conversion decodes its DCCL entries (load_shared_library)."""
    modules = ["gateway.goby.intervehicle.protobuf.intervehicle_pb2",
               "gateway.goby.intervehicle.protobuf.serializer_transporter_pb2", "frontseat.protobuf.frontseat_pb2"]
    for proto in sorted((HERE / "translators").glob("**/protobuf/*_pb2.py")):
        modules.append(".".join(proto.relative_to(HERE).with_suffix("").parts))
    return [arg for m in modules for arg in ("--load_shared_library", m)]


def rates_table(rates: list[PlatformRate], hours: float) -> str:
    rows = []
    for r in rates:
        per_entry, per_byte = r.per_s
        rows.append([r.platform, f"{r.span_s:.0f}", f"{r.entries:,}", f"{r.size / 2**20:.1f}", f"{per_entry:.1f}",
                     f"{per_byte / 1024:.1f}", f"{per_entry * hours * 3600:,.0f}",
                     f"{per_byte * hours * 3600 / 2**30:.2f}"])
    total_e = sum(r.per_s[0] for r in rates) * hours * 3600
    total_b = sum(r.per_s[1] for r in rates) * hours * 3600
    rows.append(["all", "", "", "", "", "", f"{total_e:,.0f}", f"{total_b / 2**30:.2f}"])
    return markdown_table(["platform", "log s (sim)", "entries", "MiB", "entries/s", "KiB/s",
                           f"entries in {hours:g} h", f"GiB in {hours:g} h"], rows)


# ---- the private network namespace ------------------------------------------------------------------------------

def logger_part(args: argparse.Namespace, sides: list[str], programs: dict[str, str], work: Path) -> None:
    print(f"## goby-logger{' vs goby_logger' if programs else ''}: one publisher, {args.seconds:g} s per rate, "
          f"{args.runs} run(s), {os.cpu_count()} cores")
    results: dict[str, dict[int, list[Step]]] = {side: {rate: [] for rate in args.rates} for side in sides}
    for run in range(args.runs):
        for side in sides:
            for rate in args.rates:
                progress(f"logger: {side} at {rate:,}/s, run {run + 1}/{args.runs}")
                try:
                    results[side][rate].append(logger_step(side, rate, args.seconds, programs, work / f"run{run}"))
                except RuntimeError as exc:
                    progress(f"logger: {side} at {rate:,}/s failed: {exc}")
    print(logger_table(results))
    print("\nhighest rate kept with 0 lost: " + "; ".join(f"{side} {kept_rate(steps)}"
                                                          for side, steps in results.items()))


def _rates(text: str) -> list[int]:
    try:
        values = [int(v) for v in re.split(r"[,\s]+", text.strip()) if v]
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a list of whole numbers: {text!r}") from None
    if not values or min(values) <= 0:
        raise argparse.ArgumentTypeError("rates must be positive")
    return values


PARTS = ("logger", "read", "trail")


def _parts(text: str) -> tuple[str, ...]:
    parts = tuple(p for p in text.split(",") if p)
    unknown = set(parts) - set(PARTS)
    if unknown or not parts:
        raise argparse.ArgumentTypeError(f"parts are {', '.join(PARTS)}")
    return parts


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    parser = argparse.ArgumentParser(prog="python -m bench.bench_logger", description=__doc__.split("\n\n")[0])
    parser.add_argument("--rates", type=_rates, default=[25_000, 50_000, 75_000, 100_000],
                        help="publisher rates to try, msgs/s (default 25000,50000,75000,100000)")
    parser.add_argument("--seconds", type=bounded_number(float, 0.5, 60), default=2.0,
                        help="publishing time per rate (default 2)")
    parser.add_argument("--runs", type=bounded_number(int, 1, 20), default=3,
                        help="runs per rate and logger (default 3); a rate counts as kept when no run lost any")
    parser.add_argument("--read-entries", type=bounded_number(int, 1000, 10_000_000), default=300_000,
                        help="entries in the read-speed log (default 300000)")
    parser.add_argument("--trail-log", type=Path, nargs="*", default=None, metavar="LOG",
                        help="logs of a short trail-mission run (platform = the name before the first _) "
                             "instead of running one")
    parser.add_argument("--trail-seconds", type=bounded_number(float, 30, 3600), default=300.0,
                        help="simulated seconds of the short trail run (default 300)")
    parser.add_argument("--hours", type=bounded_number(float, 0.01, 48), default=24.0,
                        help="length of the log converted to MCAP (default 24)")
    parser.add_argument("--python-only", action="store_true", help="skip the C++ logger")
    parser.add_argument("--parts", type=_parts, default=PARTS, help=f"what to run (default {','.join(PARTS)})")
    parser.add_argument(NETNS_FLAG, action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)

    programs: dict[str, str] = {}
    if "logger" not in args.parts:
        pass
    elif args.python_only:
        progress("(C++ logger skipped: --python-only)")
    else:
        found, why = find_cpp()
        here, status = cpp_side_here(why, args.in_netns, "bench.bench_logger", argv, "C++ logger",
                                     "the real gobyd listens on all addresses")
        if status is not None:
            return status
        if here:
            programs = found
    sides = ["python", *(["cpp"] if programs else [])]
    with tempfile.TemporaryDirectory(prefix="bench_logger_") as tmp:
        work = Path(tmp)
        if "logger" in args.parts:
            logger_part(args, sides, programs, work)
        if "read" in args.parts:
            print(f"\n## goby-log-tool read speed ({args.read_entries:,} small protobuf entries, best of 3)")
            print(markdown_table(["reading", "entries", "entries/s"], reader_figures(args.read_entries, work)))
        if "trail" not in args.parts:
            return 0
        if args.trail_log:
            logs = {p.name.split("_", 1)[0]: p for p in args.trail_log}
        else:
            logs = trail_run(args.trail_seconds, work)
        rates = [platform_rate(name, path) for name, path in logs.items() if path.exists()]
        if not rates:
            progress("trail: no logs")
            return 1
        print(f"\n## trail-mission logs: rates of a short run, scaled to {args.hours:g} h")
        print(rates_table(rates, args.hours))
        print(f"\n## a {args.hours:g} h log to MCAP (goby-log-tool --format MCAP, wall time)")
        print(markdown_table(["log", "size", "entries", "MCAP messages", "MCAP size", "seconds", "entries/s",
                              "MiB/s"], mcap_day(rates, args.hours, work)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
