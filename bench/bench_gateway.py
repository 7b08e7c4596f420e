"""Gateway latency and throughput: one hop MOOS -> Goby and Goby -> MOOS through ``moos-gateway``.

Runs ``moos-db``, ``goby-broker`` and ``moos-gateway`` (with an echo plugin) as processes; this process is the
MOOS poster/receiver and the Goby peer.  "Added" latency = median through the gateway minus the medians of a
direct MOOS hop (client -> MOOSDB -> client) and a direct Goby hop (portal -> broker -> portal), measured the
same way.  The "10 Hz fetch" row runs the same translator with the on-mail wake-up disabled, i.e. the original's
behaviour (mail fetched in the 10 Hz loop).  Throughput keeps a window of messages in flight
(sustained rate) and checks that every one arrives.

Usage: ``python -m bench.bench_gateway [--samples N] [--burst N]``
"""

from __future__ import annotations

import argparse
import random
import statistics
import sys
import tempfile
import threading
import time
from collections.abc import Callable
from pathlib import Path

from bench.stats import percentile
from gateway.goby.portal.testing import PortalClient, broker_process
from gateway.moos.client import comms
from gateway.moos.testing import moosdb_process
from translators.testing import GatewayProcess

PLUGIN = '''
from translators.base import Translator


class BenchEcho(Translator):
    def __init__(self, cfg):
        super().__init__(cfg)
        self.moos().add_trigger("BENCH_IN", self.on_in)
        self.goby().interprocess().subscribe("bench_to_moos", str, self.on_goby)
        if {tick_only}:
            self.moos().comms().set_on_mail_callback(lambda: True)  # Goby's way: fetch only in the 10 Hz loop

    if {tick_only}:
        def loop(self):  # overriding loop() also makes the thread tick at Goby's 10 Hz x warp
            super().loop()
            self.moos().handle_mail()

    def on_in(self, msg):
        self.goby().interprocess().publish("bench_from_moos", msg.string())

    def on_goby(self, text):
        self.moos().comms().notify("BENCH_OUT", text)


def load(gateway):
    gateway.launch_thread(BenchEcho)
'''


class MoosReceiver:
    """A MOOS client whose on-mail callback sets an event; the bench thread fetches (as the translators do)."""

    def __init__(self, port: int, name: str, variables: list[str]) -> None:
        self.event = threading.Event()
        self.client = comms()
        self.client.set_on_connect_callback(lambda: [self.client.register(v, 0) for v in variables] and True)
        self.client.set_on_mail_callback(self._wake)
        self.client.run("127.0.0.1", port, name)
        if not self.client.wait_until_connected(20_000):
            raise RuntimeError(f"{name} could not connect to the MOOSDB")

    def _wake(self) -> bool:
        self.event.set()
        return True

    def fetch(self, timeout: float) -> list:
        if not self.event.wait(timeout):
            return []
        self.event.clear()
        return self.client.fetch()

    def close(self) -> None:
        self.client.close(True)


def _sample(n: int, send: Callable[[str], object], receive: Callable[[float], list[str]],
            timeout: float = 5.0, jitter_s: float = 0.0) -> list[float]:
    """Send one message at a time and wait for it; latencies in ms (lost ones raise).

    ``jitter_s``: a random pause before each send, so sends do not phase-lock to a polling loop.
    """
    latencies: list[float] = []
    for i in range(n):
        tag = f"s{i}"
        if jitter_s:
            time.sleep(random.uniform(0.0, jitter_s))
        start = time.perf_counter()
        send(tag)
        deadline = start + timeout
        while True:
            if tag in receive(max(0.0, deadline - time.perf_counter())):
                latencies.append((time.perf_counter() - start) * 1000.0)
                break
            if time.perf_counter() > deadline:
                raise RuntimeError(f"message {tag} lost")
    return latencies


def _moos_strings(receiver: MoosReceiver, name: str) -> Callable[[float], list[str]]:
    return lambda timeout: [m.string() for m in receiver.fetch(timeout) if m.key() == name]


def _goby_strings(peer: PortalClient, box: list[str]) -> Callable[[float], list[str]]:
    def receive(timeout: float) -> list[str]:
        peer.poll(min(timeout, 0.5))
        got, box[:] = list(box), []
        return got
    return receive


def _throughput(burst: int, send: Callable[[str], object], receive: Callable[[float], list[str]],
                window: int = 200) -> tuple[float, int]:
    """Send ``burst`` messages keeping at most ``window`` in flight (below ZeroMQ's and MOOS's queue limits, so a
    slow stage shows up as a lower rate, not as drops); returns (messages/s, number received)."""
    sent = received = 0
    start = time.perf_counter()
    deadline = start + 120
    while received < burst and time.perf_counter() < deadline:
        while sent < burst and sent - received < window:
            send(f"t{sent}")
            sent += 1
        received += len(receive(0.05))
    return received / (time.perf_counter() - start), received


def run(samples: int, burst: int, tick_samples: int) -> list[tuple[str, str, str, str]]:
    rows: list[tuple[str, str, str, str]] = []
    with tempfile.TemporaryDirectory(prefix="bench_gw") as tmp_name:
        tmp = Path(tmp_name)
        with moosdb_process(tmp) as db, broker_process(tmp, platform="benchgw") as broker:
            # baselines: one direct hop each
            poster = comms()
            poster.run("127.0.0.1", db.port, "bench_poster")
            poster.wait_until_connected(20_000)
            receiver = MoosReceiver(db.port, "bench_receiver", ["BENCH_DIRECT", "BENCH_OUT"])
            peer = PortalClient(broker.interprocess_config(), name="bench_peer")
            try:
                goby_box: list[str] = []
                peer.subscribe("bench_direct", str, goby_box.append)
                peer.subscribe("bench_from_moos", str, goby_box.append)
                peer.wait_subscribed()
                moos_direct = _sample(samples, lambda t: poster.notify("BENCH_DIRECT", t),
                                      _moos_strings(receiver, "BENCH_DIRECT"))
                goby_direct = _sample(samples, lambda t: peer.publish("bench_direct", t), _goby_strings(peer, goby_box))
                base_moos, base_goby = statistics.median(moos_direct), statistics.median(goby_direct)
                rows.append(("direct MOOS hop (baseline)", f"{base_moos:.3f}", f"{percentile(moos_direct, .99):.3f}", ""))
                rows.append(("direct Goby hop (baseline)", f"{base_goby:.3f}", f"{percentile(goby_direct, .99):.3f}", ""))

                for tick_only, n in ((False, samples), (True, tick_samples)):
                    work = tmp / ("tick" if tick_only else "wake")
                    work.mkdir()
                    plugin = work / "bench_plugin.py"
                    plugin.write_text(PLUGIN.format(tick_only=tick_only))
                    cfg = (f"interprocess {{ {broker.interprocess_text()} }} "
                           f'moos {{ server: "127.0.0.1" port: {db.port} }}')
                    with GatewayProcess(work, [str(plugin)], cfg):
                        _warm_up(poster, peer, goby_box)
                        label = "10 Hz fetch (Goby's way)" if tick_only else "gateway (wake on mail)"
                        jitter = 0.1 if tick_only else 0.0  # one 10 Hz period: arrivals at random phases
                        m2g = _sample(n, lambda t: poster.notify("BENCH_IN", t), _goby_strings(peer, goby_box),
                                      jitter_s=jitter)
                        g2m = _sample(n, lambda t: peer.publish("bench_to_moos", t),
                                      _moos_strings(receiver, "BENCH_OUT"), jitter_s=jitter)
                        base = base_moos + base_goby
                        for direction, values in (("MOOS->Goby", m2g), ("Goby->MOOS", g2m)):
                            median = statistics.median(values)
                            rows.append((f"{label} {direction}", f"{median:.3f}", f"{percentile(values, .99):.3f}",
                                         f"{median - base:+.3f}"))
                        if not tick_only:
                            rate, got = _throughput(burst, lambda t: poster.notify("BENCH_IN", t),
                                                    _goby_strings(peer, goby_box))
                            rows.append((f"throughput MOOS->Goby ({got}/{burst} received)", f"{rate:,.0f} msg/s", "", ""))
                            rate, got = _throughput(burst, lambda t: peer.publish("bench_to_moos", t),
                                                    _moos_strings(receiver, "BENCH_OUT"))
                            rows.append((f"throughput Goby->MOOS ({got}/{burst} received)", f"{rate:,.0f} msg/s", "", ""))
            finally:
                peer.close()
                receiver.close()
                poster.close(True)
    return rows


def _warm_up(poster: comms, peer: PortalClient, box: list[str]) -> None:
    """Wait until the freshly started gateway forwards (it connects to both sides asynchronously)."""
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline:
        poster.notify("BENCH_IN", "warm")
        peer.poll_until(lambda: "warm" in box, 0.3)
        if "warm" in box:
            time.sleep(0.3)
            peer.poll(0.1)
            box.clear()
            return
    raise RuntimeError("the gateway did not start forwarding within 30 s")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=1000, help="round trips per latency row")
    parser.add_argument("--tick-samples", type=int, default=100, help="round trips for the 10 Hz rows")
    parser.add_argument("--burst", type=int, default=20000, help="messages per throughput burst")
    args = parser.parse_args(argv)
    rows = run(args.samples, args.burst, args.tick_samples)
    header = ("path", "median ms", "p99 ms", "added ms (median)")
    widths = [max(len(r[i]) for r in [header, *rows]) for i in range(4)]
    print("  ".join(h.ljust(w) for h, w in zip(header, widths, strict=True)))
    for row in rows:
        print("  ".join(c.ljust(w) for c, w in zip(row, widths, strict=True)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
