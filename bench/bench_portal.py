"""Portal benchmark: cross-process publish-to-callback latency and throughput through a real goby-broker.

Run: ``python -m bench.bench_portal`` (``--quick`` for a short run).  Three processes: the broker, this process
(publisher) and a subscriber child (``--child``).  Latency is one-way (publish call -> subscriber callback,
CLOCK_MONOTONIC is shared by processes on one host), measured ping-pong so no queue builds up.  Throughput is
measured with a window of in-flight messages below the high-water mark (the child reports progress), so it is
lossless; a final "blast" row publishes without a window to show what happens past the HWM.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

from google.protobuf import text_format

from bench.stats import median_p99
from gateway.goby.portal.testing import BrokerProcess, PortalClient, app_process
from gateway.goby.protobuf.interprocess_config_pb2 import InterProcessPortalConfig
from tests.protobuf.sample_messages_pb2 import Sample, Widget

WINDOW = 500  # in flight; below the default send/receive queue sizes (1000)
PROGRESS_EVERY = 100


def _now_us() -> int:
    return time.monotonic_ns() // 1000


def child(cfg_text: str) -> int:
    """Subscriber: record one-way latency of pings and answer each; count stream messages and report progress."""
    cfg = text_format.Parse(cfg_text, InterProcessPortalConfig())
    latencies: list[int] = []
    state = {"count": 0, "stop": False}
    with PortalClient(cfg, "bench_child", hold_settle_s=0.0) as client:

        def on_ping(msg: Sample) -> None:
            latencies.append(_now_us() - msg.sent_micro)
            client.publish("bench_pong", Widget(b=msg.a))

        def on_stream(msg: Sample) -> None:
            state["count"] += 1
            if state["count"] % PROGRESS_EVERY == 0:
                client.publish("bench_progress", Widget(b=state["count"]))

        def on_control(text: str) -> None:
            if text == "reset":
                state["count"] = 0
                latencies.clear()
            elif text == "report":
                client.publish("bench_report", json.dumps({"latencies_us": latencies, "count": state["count"]}))
            elif text == "stop":
                state["stop"] = True

        client.subscribe("bench_ping", Sample, on_ping)
        client.subscribe("bench_stream", Sample, on_stream)
        client.subscribe("bench_control", str, on_control)
        client.wait_subscribed()
        print("CHILD READY", flush=True)
        while not state["stop"]:
            client.poll(0.5)
    return 0


class Bench:
    def __init__(self, client: PortalClient) -> None:
        self.client = client
        self.pongs: list[Widget] = []
        self.progress = 0
        self.reports: list[str] = []
        client.subscribe("bench_pong", Widget, self.pongs.append)
        client.subscribe("bench_progress", Widget, lambda w: setattr(self, "progress", w.b))
        client.subscribe("bench_report", str, self.reports.append)

    def control(self, text: str) -> None:
        self.client.publish("bench_control", text)

    def report(self) -> dict:
        self.reports.clear()
        self.control("report")
        if not self.client.poll_until(lambda: bool(self.reports), 30):
            raise RuntimeError("subscriber did not report")
        return json.loads(self.reports[0])

    def latency(self, n: int, padding: int) -> tuple[float, float, float]:
        self.control("reset")
        self.client.poll(0.2)
        pad = b"x" * padding
        for i in range(n):
            self.pongs.clear()
            self.client.publish("bench_ping", Sample(a=i, sent_micro=_now_us(), padding=pad))
            if not self.client.poll_until(lambda: bool(self.pongs), 5):
                raise RuntimeError(f"ping {i} lost")
        lat = sorted(self.report()["latencies_us"])
        return (*median_p99(lat), float(len(lat)))

    def throughput(self, n: int, padding: int, window: int | None) -> tuple[float, int, float]:
        """(received msg/s, lost, published msg/s)."""
        self.control("reset")
        self.client.poll_until(lambda: self.report()["count"] == 0, 10)
        self.progress = 0
        msg = Sample(a=0, temperature=1.0, salinity=35.0, depth=10.0, padding=b"x" * padding)
        start = time.perf_counter()
        for i in range(n):
            msg.a = i
            self.client.publish("bench_stream", msg)
            if window is not None:
                while i - self.progress >= window:
                    self.client.poll(0.01)
            elif i % 200 == 0:
                self.client.poll(0)
        publish_rate = n / (time.perf_counter() - start)
        expected = n - n % PROGRESS_EVERY
        self.client.poll_until(lambda: self.progress >= expected, 10 if window is not None else 2)
        elapsed = time.perf_counter() - start
        received = self.report()["count"]
        return received / elapsed, n - received, publish_rate


def call_soon_latency(n: int) -> tuple[float, float]:
    """call_soon from this thread to a SimpleThread blocked in its poll: (median, p99) µs until fn runs there."""
    import threading

    from gateway.goby.portal import MultiThreadApplication, SimpleThread
    from gateway.goby.portal.testing import running_app
    from gateway.goby.protobuf.app_config_pb2 import AppConfig

    class Idle(SimpleThread):
        pass

    samples: list[float] = []
    with running_app(MultiThreadApplication, AppConfig(name="bench_call_soon")) as app:
        worker = app.launch_thread(Idle, None)
        done = threading.Event()
        for _ in range(n):
            done.clear()
            start = time.perf_counter()

            def arrived(start: float = start) -> None:
                samples.append(time.perf_counter() - start)
                done.set()

            worker.call_soon(arrived)
            done.wait(5)
            time.sleep(0.0005)  # let the worker block in its poll again
    samples.sort()
    med, p99 = median_p99(samples)
    return med * 1e6, p99 * 1e6


def in_process_costs(client: PortalClient, n: int) -> tuple[float, float]:
    """(publish µs, receive-dispatch µs) per small message, measured in this process without the network."""
    from gateway.goby.portal.identifier import encode_frame, make_identifier

    received: list[Sample] = []
    client.subscribe("bench_local", Sample, received.append)
    msg = Sample(a=1, temperature=2.0)
    start = time.perf_counter()
    for _ in range(n):
        client.publish("bench_unsubscribed", msg)
    publish_us = (time.perf_counter() - start) / n * 1e6
    frame = encode_frame(make_identifier("bench_local", 1, Sample.DESCRIPTOR.full_name), msg.SerializeToString())
    start = time.perf_counter()
    for _ in range(n):
        client.portal._dispatch(frame)  # the receive path after the socket read
    dispatch_us = (time.perf_counter() - start) / n * 1e6
    assert len(received) == n
    return publish_us, dispatch_us


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--child", help=argparse.SUPPRESS)
    parser.add_argument("--quick", action="store_true", help="fewer messages (a smoke run)")
    args = parser.parse_args(argv)
    if args.child:
        return child(args.child)
    n_lat, n_small, n_big = (500, 5_000, 2_000) if args.quick else (5_000, 50_000, 20_000)
    with tempfile.TemporaryDirectory(prefix="gbb", dir="/tmp") as tmp, \
            BrokerProcess(Path(tmp), platform="bench") as broker:
        cfg_text = broker.interprocess_text()
        with app_process([sys.executable, "-m", "bench.bench_portal", "--child", cfg_text], Path(tmp) / "sub.log",
                         cwd=str(Path(__file__).resolve().parents[1])) as sub, \
                PortalClient(broker.interprocess_config(), "bench_pub", hold_settle_s=0.0) as client:
            if sub.wait_for_output("CHILD READY", 60) is None:
                print("subscriber did not start", file=sys.stderr)
                return 1
            bench = Bench(client)
            client.wait_subscribed()
            client.poll(0.5)
            rows = []
            for label, pad in (("small (~30 B)", 0), ("1 KiB", 1024)):
                med, p99, count = bench.latency(n_lat, pad)
                rows.append((f"latency {label}", f"median {med:.0f} µs", f"p99 {p99:.0f} µs", f"n={count:.0f}"))
            for label, pad, n in (("small (~30 B)", 0, n_small), ("1 KiB", 1024, n_big)):
                rate, lost, _ = bench.throughput(n, pad, WINDOW)
                rows.append((f"throughput {label}", f"{rate:,.0f} msg/s", f"lost {lost}", f"n={n}, window {WINDOW}"))
            _, lost, published = bench.throughput(n_small, 0, None)
            rows.append(("blast small, no window", f"{published:,.0f} msg/s published", f"lost {lost}",
                         f"n={n_small}; past the HWM (1000+1000) the broker drops for the slow subscriber"))
            pub_us, dispatch_us = in_process_costs(client, n_lat * 4)
            rows.append(("in-process cost per small message", f"publish {pub_us:.1f} µs",
                         f"dispatch {dispatch_us:.1f} µs", f"n={n_lat * 4}"))
            med, p99 = call_soon_latency(n_lat // 2)
            rows.append(("call_soon wake-up (same process)", f"median {med:.0f} µs", f"p99 {p99:.0f} µs",
                         f"n={n_lat // 2}"))
            bench.control("stop")
            client.poll(0.2)
            sub.wait(10)
    width = [max(len(r[i]) for r in rows) for i in range(4)]
    print(f"{'measure':<{width[0]}}  {'value':<{width[1]}}  {'':<{width[2]}}  conditions")
    for row in rows:
        print("  ".join(f"{cell:<{w}}" for cell, w in zip(row, width, strict=True)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
