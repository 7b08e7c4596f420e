"""Restart accounting: SIGKILL and restart the server under a numbered stream, many times, and explain every number.

    python -m bench.bench_restarts [--trials 50] [--path moos|ipc|tcp] [--seed 1] [--period-ms 2]

One server (moos-db, or goby-broker over IPC or TCP), one publisher and one subscriber that live through all the
trials. Each trial streams for a random 0.3-0.9 s, kills the server (SIGKILL), leaves it down a random 0-0.5 s,
restarts it, and in half the trials keeps the subscriber from coming back for a random 0.2-1.5 s more (a MOOS
subscriber whose on-connect callback is slow, a portal thread that does not poll): the case where a publisher is
back before its subscriber. Every number sent is then delivered, refused (``notify``/``publish`` returned False) or
reported (the on-undelivered callback); the rest is *unexplained*, lost silently. "reported, arrived" counts the
reports that were false alarms (the message arrived after all). Exit 0 when nothing is unexplained, duplicated or
reordered.
"""

from __future__ import annotations

import argparse
import random
import sys
import tempfile
import threading
import time
from collections.abc import Callable
from pathlib import Path

from bench.bench_chaos import Ledger
from bench.stats import markdown_table
from gateway.goby.portal.testing import PortalClient, broker_process
from gateway.moos import comms
from gateway.moos.testing import moosdb_process
from util.cli import bounded_number

RECOVERY_TIMEOUT_S = 30.0


class Trials:
    """The schedule both paths share: per trial the stream time, the downtime and the subscriber's extra delay."""

    def __init__(self, count: int, rng: random.Random) -> None:
        self.plan = [(rng.uniform(0.3, 0.9), rng.uniform(0.0, 0.5), rng.uniform(0.2, 1.5) if rng.random() < 0.5
                      else 0.0) for _ in range(count)]
        self.ledger = Ledger()
        self.order: list[int] = []  # delivery order, to check for duplicates and reordering
        self.reader_delay = 0.0  # how long the subscriber stays away after the coming restart
        self.failures: list[str] = []
        self.warm = threading.Event()  # a warm-up message (-1) arrived: the publisher sees the subscription

    def delivered(self, n: int) -> None:
        if n < 0:
            self.warm.set()
            return
        self.order.append(n)
        self.ledger.deliver(n)

    def warm_up(self, send: Callable[[], object], idle: Callable[[float], object]) -> bool:
        """Send -1 until one arrives, so the stream starts with the subscription in place; False (a failure
        recorded) if none arrived within 30 s."""
        deadline = time.monotonic() + 30
        while not self.warm.is_set() and time.monotonic() < deadline:
            send()
            idle(0.05)
        if not self.warm.is_set():
            self.failures.append("the warm-up message never arrived within 30 s: no trial run")
        return self.warm.is_set()

    def record(self, n: int, accepted: bool) -> None:
        with self.ledger.lock:
            self.ledger.sent[n] = time.monotonic()
            if not accepted:
                self.ledger.refused.add(n)

    def reported(self, numbers: list[int]) -> None:
        with self.ledger.lock:
            self.ledger.reported.update(n for n in numbers if n >= 0)

    def run(self, send: Callable[[int], bool], kill: Callable[[], object], start: Callable[[], object],
            idle: Callable[[float], object], period_s: float) -> None:
        """Stream ``send(n)`` every ``period_s`` through every trial's kill and restart (``idle`` waits)."""
        n = 0

        def stream(seconds: float) -> None:
            nonlocal n
            end = time.monotonic() + seconds
            next_at = time.monotonic()
            while time.monotonic() < end:
                self.record(n, send(n))
                n += 1
                next_at += period_s
                idle(max(0.0, next_at - time.monotonic()))

        for run_s, down_s, reader_delay in self.plan:
            stream(run_s)
            self.reader_delay = reader_delay
            kill()
            stream(down_s)
            start()
            first = n
            deadline = time.monotonic() + RECOVERY_TIMEOUT_S
            while not any(i >= first for i in self.order[-5:]) and time.monotonic() < deadline:
                stream(0.05)
            if time.monotonic() >= deadline:
                self.failures.append(f"no delivery within {RECOVERY_TIMEOUT_S:g} s of a restart")
            stream(0.2)
        idle(1.0)

    def row(self, path: str) -> list[str]:
        led = self.ledger
        sent, delivered = set(led.sent), led.delivered & set(led.sent)
        explained = delivered | led.refused | led.reported
        false_alarms = len(led.reported & delivered)
        dup = len(self.order) != len(set(self.order)) or self.order != sorted(self.order)
        if dup:
            self.failures.append("duplicated or reordered")
        unexplained = len(sent - explained)
        if unexplained:
            self.failures.append(f"{unexplained} unexplained, first {sorted(sent - explained)[:10]}")
        share = f"{100 * false_alarms / len(led.reported):.0f} %" if led.reported else "-"
        return [path, str(len(self.plan)), f"{len(sent):,}", f"{len(delivered):,}", f"{len(led.refused):,}",
                f"{len(led.reported):,}", f"{false_alarms:,} ({share})", f"{unexplained:,}"]


def run_moos(trials: Trials, period_s: float, workdir: Path) -> None:
    """moos-db: the subscriber's on-connect callback sleeps ``reader_delay`` before it registers again."""
    with moosdb_process(workdir) as db:
        reader = comms()
        first_connect = [True]

        def on_connect() -> None:
            if not first_connect[0]:
                time.sleep(trials.reader_delay)  # registrations go after on-connect returns
            first_connect[0] = False

        reader.set_on_connect_callback(on_connect)
        def on_mail() -> None:
            for m in reader.fetch():
                if m.key() == "SEQ":
                    trials.delivered(int(m.double()))

        reader.set_on_mail_callback(on_mail)
        reader.register("SEQ", 0)
        writer = comms()
        writer.set_on_undelivered_callback(lambda msgs: trials.reported([int(m.double()) for m in msgs
                                                                         if m.key() == "SEQ"]))
        reader.run("127.0.0.1", db.port, "bench_reader")
        writer.run("127.0.0.1", db.port, "bench_writer")
        try:
            if not (reader.wait_until_connected(20_000) and writer.wait_until_connected(20_000)):
                trials.failures.append("the reader or the writer did not connect to moos-db within 20 s")
                return
            if not trials.warm_up(lambda: writer.notify("SEQ", -1.0), time.sleep):
                return
            trials.run(lambda n: writer.notify("SEQ", float(n)), db.kill, db.start, time.sleep, period_s)
        finally:
            writer.close()
            reader.close()


def run_portal(trials: Trials, period_s: float, workdir: Path, tcp: bool) -> None:
    """goby-broker: the subscriber is a portal on its own thread that stops polling for ``reader_delay`` after a
    restart (its subscriptions are sent again from its own thread)."""
    with broker_process(workdir, platform="restarts", tcp=tcp) as broker:
        cfg = broker.interprocess_config()
        stop, ready, restarted = threading.Event(), threading.Event(), threading.Event()

        def read() -> None:
            with PortalClient(cfg, "bench_reader") as reader:
                reader.subscribe("seq", str, lambda text: trials.delivered(int(text)))
                reader.wait_subscribed()
                ready.set()
                while not stop.is_set():
                    reader.poll(0.01)
                    if restarted.is_set():
                        restarted.clear()
                        time.sleep(trials.reader_delay)
                reader.poll_until(lambda: False, 1.0)

        thread = threading.Thread(target=read, name="bench-restarts-reader")
        thread.start()
        try:
            ready.wait(30)
            with PortalClient(cfg, "bench_writer") as writer:
                writer.portal.on_undelivered = lambda lost: trials.reported(
                    [int(p.rstrip(b"\0")) for g, p in lost if g == "seq"])
                writer.wait_ready()
                if not trials.warm_up(lambda: writer.publish("seq", "-1"), writer.poll):
                    return

                def start() -> None:
                    broker.start()
                    restarted.set()

                trials.run(lambda n: writer.publish("seq", str(n)), broker.kill, start,
                           lambda s: writer.poll(s), period_s)
        finally:
            stop.set()
            thread.join(30)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="bench_restarts", description=__doc__.split("\n\n")[0])
    parser.add_argument("--trials", type=bounded_number(int, 1, 10_000), default=50)
    parser.add_argument("--path", choices=("moos", "ipc", "tcp"), action="append",
                        help="moos-db, goby-broker over IPC or TCP (repeatable; default all three)")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--period-ms", type=bounded_number(float, 0.1, 1000), default=2.0)
    args = parser.parse_args(argv)
    header = ["path", "trials", "sent", "delivered", "refused", "reported", "reported, arrived", "unexplained"]
    rows, failures = [], []
    for path in args.path or ["moos", "ipc", "tcp"]:
        trials = Trials(args.trials, random.Random(f"{args.seed}-{path}"))
        started = time.monotonic()
        with tempfile.TemporaryDirectory(prefix="rs") as tmp:
            if path == "moos":
                run_moos(trials, args.period_ms / 1000, Path(tmp))
            else:
                run_portal(trials, args.period_ms / 1000, Path(tmp), tcp=path == "tcp")
        rows.append(trials.row(path))
        failures += [f"{path}: {f}" for f in trials.failures]
        print(f"{path}: {args.trials} trials in {time.monotonic() - started:.0f} s", file=sys.stderr, flush=True)
    print(markdown_table(header, rows))
    for failure in failures:
        print("FAIL", failure)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
