"""goby-liaison: end-to-end latency from a publish to the value drawn in the browser, and what the pages cost.

    python -m bench.bench_liaison [--seconds 8]

A real broker, ``goby-liaison`` as its own process and headless Chromium, at update_freq 5 Hz (Goby's) and 20 Hz.

The scope page.  Latency: a publisher sends ``seq`` on one group at 50 Hz and remembers when; the page records,
for every value it shows, the time of the animation frame after the DOM changed (``performance.timeOrigin +
now()``, the same wall clock).  Values that the coalescing skipped are not drawn and not counted.  CPU: 100 groups
at 50 Hz each (5000 publications/s) for the same time, with the CPU seconds of the liaison process and of every
process of this benchmark's Chromium (the page's cost).

The map page.  20 vehicles (one USV, 19 AUVs, 400 m apart, each circling at 3 m/s) publish NodeStatus on
``<name>::node_status`` at 5 Hz each, every report at a random phase (so a report waits a random part of the update
period); the page starts with 300 trail points per vehicle, what it shows mid-mission.  Latency: each NodeStatus
carries its publish time (``time``); the page records the animation frame in which each vehicle's new report was
drawn on the canvas (``LiveMap.draw`` wrapped from here).  CPU as for the scope, over the same window, alone and
with the 100 busy groups at 50 Hz besides (their publications reach the liaison whatever page is open).
"""

from __future__ import annotations

import argparse
import math
import os
import random
import re
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

from bench.stats import median_p99
from frontseat.protobuf.frontseat_data_pb2 import NodeStatus, VehicleType
from gateway.goby.portal.testing import BrokerProcess, PortalClient, broker_process
from launch.liaison.portal_side import READY_PREFIX
from launch.liaison.testing import PROFILE_PREFIX as PROFILE_MARKER
from launch.liaison.testing import browser_skip_reason, chromium
from util.geodesy import UTMGeodesy
from util.process import ChildProcess, ProcessError, free_port

if TYPE_CHECKING:  # selenium is a test extra; chromium() imports it when a browser runs
    from selenium.webdriver.remote.webdriver import WebDriver

RECORDER = """
window._drawn = [];
const body = document.querySelector('#scope-table tbody');
new MutationObserver(() => requestAnimationFrame(() => {
  const now = performance.timeOrigin + performance.now();
  for (const tr of body.querySelectorAll('tr.row')) {
    if (tr.children[0].textContent === 'latency') {
      const v = tr.children[3].textContent;
      if (!window._drawn.length || window._drawn[window._drawn.length - 1][0] !== v) window._drawn.push([v, now]);
    }
  }
})).observe(body, {subtree: true, childList: true, characterData: true});
"""
# The map draws on its animation frame (LiveMap.redraw -> LiveMap.draw); record, after each draw, the vehicles
# whose report changed since the last one: [name, the report's time (its publish time, s), the frame's time, ms].
MAP_RECORDER = """
window._drawn = [];
const last = new Map();
const draw = LiveMap.draw;
LiveMap.draw = function () {
  draw.call(this);
  const now = performance.timeOrigin + performance.now();
  for (const [name, v] of this.vehicles) {
    if (v.data && last.get(name) !== v.data.time) { last.set(name, v.data.time); window._drawn.push([name, v.data.time, now]); }
  }
};
"""
# Trails as a page has them mid-mission: each vehicle's past points, oldest first.
MAP_TRAILS = """
for (const [name, points] of Object.entries(arguments[0])) LiveMap.vehicles.get(name).points = points;
LiveMap.redraw();
"""
MAP_VEHICLES = 20
MAP_HZ = 5.0  # NodeStatus per vehicle per second (Goby's 5 Hz)
MAP_TRAIL_POINTS = 300  # the page's default trail (LiveMap.trailShown), one point every 5 m
SPEED_M_S = 3.0
RADIUS_M = 150.0
DATUM = (41.52, -70.68)


class Fleet:
    """20 vehicles circling at 3 m/s around centres 400 m apart, each with its next report due at a random phase."""

    def __init__(self, count: int = MAP_VEHICLES, hz: float = MAP_HZ) -> None:
        self.names = ["usv"] + [f"auv_{i:02d}" for i in range(1, count)]
        self.period = 1.0 / hz
        self.t0 = time.time()
        self.geodesy = UTMGeodesy(*DATUM)
        self.due = {name: time.monotonic() + random.random() * self.period for name in self.names}

    def position(self, index: int, t: float) -> tuple[float, float, float]:
        """(x, y, heading) of a vehicle at wall time ``t``: counter-clockwise on its circle."""
        angle = index * 0.7 + SPEED_M_S / RADIUS_M * (t - self.t0)
        cx, cy = (index % 5) * 400.0, (index // 5) * 400.0
        heading = (90.0 - math.degrees(angle + math.pi / 2)) % 360.0  # compass bearing of the tangent
        return cx + RADIUS_M * math.cos(angle), cy + RADIUS_M * math.sin(angle), heading

    def status(self, index: int, t: float) -> NodeStatus:
        name = self.names[index]
        x, y, heading = self.position(index, t)
        status = NodeStatus(name=name, type=VehicleType.USV if index == 0 else VehicleType.AUV, time=t)
        status.local_fix.x, status.local_fix.y = x, y
        status.global_fix.lat, status.global_fix.lon = self.geodesy.to_geo(x, y)
        status.pose.heading, status.speed.over_ground = heading, SPEED_M_S
        return status

    def publish_due(self, client: PortalClient) -> int:
        """Publish the reports that are due (now in ``time``); the next one of each after 0.5-1.5 periods."""
        sent = 0
        now = time.monotonic()
        for index, name in enumerate(self.names):
            if now >= self.due[name]:
                client.publish(f"{name}::node_status", self.status(index, time.time()))
                self.due[name] = now + self.period * (0.5 + random.random())
                sent += 1
        return sent

    def next_due(self) -> float:
        return min(self.due.values())

    def publish_all(self, client: PortalClient) -> None:
        for index, name in enumerate(self.names):
            client.publish(f"{name}::node_status", self.status(index, time.time()))

    def trails(self) -> dict[str, list[list[float]]]:
        """Each vehicle's last MAP_TRAIL_POINTS positions 5 m apart, oldest first."""
        now = time.time()
        step_s = 5.0 / SPEED_M_S
        return {name: [[round(c, 1) for c in self.position(index, now - k * step_s)[:2]]
                       for k in range(MAP_TRAIL_POINTS, 0, -1)]
                for index, name in enumerate(self.names)}


def cpu_seconds(pids: list[int]) -> float:
    """utime + stime of the given processes, in seconds."""
    tick = os.sysconf("SC_CLK_TCK")
    total = 0
    for pid in pids:
        try:
            fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        total += int(fields[11]) + int(fields[12])
    return total / tick


def chromium_pids(profile_marker: str) -> list[int]:
    """The processes whose command line names ``profile_marker`` (the browser's profile directory)."""
    pids = []
    for cmdline in Path("/proc").glob("[0-9]*/cmdline"):
        try:
            if profile_marker.encode() in cmdline.read_bytes():
                pids.append(int(cmdline.parent.name))
        except OSError:
            continue
    return pids


def serve_until(client: PortalClient, at: float) -> None:
    """Run the client's portal until ``time.monotonic()`` reaches ``at`` (``poll`` returns as soon as it has done
    some work, e.g. flushed the publications: pacing on one ``poll(period)`` published 20 times too fast)."""
    while (left := at - time.monotonic()) > 0:
        client.poll(left)


def serve_for(client: PortalClient, seconds: float) -> None:
    serve_until(client, time.monotonic() + seconds)


def start_liaison(broker: BrokerProcess, update_freq: float, log: Path) -> tuple[ChildProcess, str]:
    port = free_port()
    cfg = (f'interprocess {{ {broker.interprocess_text()} }} http_address: "127.0.0.1" http_port: {port} '
           f"update_freq: {update_freq}")
    path = log.with_suffix(".cfg")
    path.write_text(cfg)
    proc = ChildProcess([sys.executable, "-m", "launch.apps.goby_liaison", str(path)], log, name="goby-liaison")
    try:
        proc.start().wait_ready(re.escape(READY_PREFIX), timeout=30)
    except ProcessError as exc:
        raise SystemExit(str(exc)) from None
    return proc, f"http://127.0.0.1:{port}"


def run_latency(driver: WebDriver, client: PortalClient, url: str, seconds: float, period_s: float = 0.02,
                jitter: bool = False) -> list[float]:
    """Latencies (ms) of the values the page drew, publishing one value every ``period_s`` (random phase with
    ``jitter``, so a value waits a random part of the update period)."""
    driver.get(f"{url}/?_=/scope")
    client.publish("latency", "start")
    serve_for(client, 0.5)
    deadline = time.monotonic() + 10
    while not driver.execute_script(
            "return [...document.querySelectorAll('#scope-table tr.row')].some(r => r.children[0].textContent"
            " === 'latency')"):
        if time.monotonic() > deadline:
            raise SystemExit("the page never showed the latency row")
        time.sleep(0.1)
    driver.execute_script(RECORDER)
    sent: dict[str, float] = {}
    end = time.monotonic() + seconds
    seq = 0
    while time.monotonic() < end:
        seq += 1
        sent[str(seq)] = time.time()
        client.publish("latency", str(seq))
        serve_for(client, period_s * (0.5 + random.random()) if jitter else period_s)
    serve_for(client, 1.0)
    drawn = driver.execute_script("return window._drawn")
    return [(at / 1000.0 - sent[value]) * 1000.0 for value, at in drawn if value in sent]


def profile_marker(driver: WebDriver) -> str:
    """This browser's profile directory (other browsers on the machine, e.g. tests running beside, use others)."""
    chrome = driver.capabilities.get("chrome", {})
    return str(chrome.get("userDataDir") or PROFILE_MARKER)


def publish_for(client: PortalClient, seconds: float, groups: int, fleet: Fleet | None = None,
                hz: float = 50.0) -> int:
    """Publish ``groups`` busy groups at ``hz`` and the fleet's reports when due, for ``seconds``; the
    publications.  Between them the client waits for the next one due (a report is not held to the busy groups'
    grid: its phase against the liaison's tick stays random)."""
    started = time.monotonic()
    end = started + seconds
    period = 1.0 / hz
    sent = 0
    next_at = started
    while (now := time.monotonic()) < end:
        if groups and now >= next_at:
            for g in range(groups):
                client.publish(f"busy::group{g:03d}", f"value {sent}")
                sent += 1
            next_at += period
        wake = next_at if groups else end
        if fleet is not None:
            sent += fleet.publish_due(client)
            wake = min(wake, fleet.next_due())
        serve_until(client, min(wake, end))
    return sent


def cpu_while(driver: WebDriver, liaison_pid: int, publish: Callable[[], int]) -> tuple[float, float, int]:
    """(liaison CPU %, browser CPU %, publications/s) while ``publish`` runs."""
    browser_pids = chromium_pids(profile_marker(driver))
    start_liaison_cpu, start_browser_cpu = cpu_seconds([liaison_pid]), cpu_seconds(browser_pids)
    started = time.monotonic()
    sent = publish()
    elapsed = time.monotonic() - started
    liaison = (cpu_seconds([liaison_pid]) - start_liaison_cpu) / elapsed * 100
    browser = (cpu_seconds(browser_pids) - start_browser_cpu) / elapsed * 100
    return liaison, browser, int(sent / elapsed)


def run_load(driver: WebDriver, client: PortalClient, url: str, liaison_pid: int, seconds: float,
             groups: int = 100) -> tuple[float, float, int]:
    driver.get(f"{url}/?_=/scope")
    time.sleep(1.0)
    return cpu_while(driver, liaison_pid, lambda: publish_for(client, seconds, groups))


def run_map(driver: WebDriver, client: PortalClient, url: str, liaison_pid: int, seconds: float,
            groups: int = 0) -> tuple[list[float], float, float, int]:
    """The map page with the fleet (and ``groups`` busy groups at 50 Hz): latencies (ms) of the reports drawn,
    liaison CPU %, browser CPU %, publications/s."""
    fleet = Fleet()
    driver.get(f"{url}/?_=/map")
    deadline = time.monotonic() + 10
    while driver.execute_script("return Object.keys(LiveMap.drawn.vehicles).length") < len(fleet.names):
        if time.monotonic() > deadline:
            raise SystemExit("the map never drew the 20 vehicles")
        fleet.publish_all(client)
        serve_for(client, 0.3)
    driver.execute_script(MAP_TRAILS, fleet.trails())
    driver.execute_script(MAP_RECORDER)
    started = time.time()
    liaison_cpu, browser_cpu, rate = cpu_while(driver, liaison_pid,
                                               lambda: publish_for(client, seconds, groups, fleet))
    serve_for(client, 1.0)
    drawn = driver.execute_script("return window._drawn")
    latencies = [(at / 1000.0 - sent) * 1000.0 for _, sent, at in drawn if sent >= started]
    if not latencies:
        raise SystemExit("the map drew none of the reports")
    return latencies, liaison_cpu, browser_cpu, rate


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seconds", type=float, default=8.0)
    args = parser.parse_args(argv)
    skip = browser_skip_reason()
    if skip:
        print(f"skipped: {skip}")
        return 0
    rows = []
    map_rows = []
    with tempfile.TemporaryDirectory(prefix="bench-liaison-") as tmp:
        tmp_path = Path(tmp)
        with broker_process(tmp_path, platform="bench") as broker, PortalClient(broker.interprocess_config()) as client:
            client.wait_ready()
            with chromium() as driver:
                for freq in (5.0, 20.0):
                    proc, url = start_liaison(broker, freq, tmp_path / f"liaison{freq:g}.log")
                    try:
                        latencies = run_latency(driver, client, url, args.seconds)
                        sparse = run_latency(driver, client, url, args.seconds, period_s=0.25, jitter=True)
                        liaison_cpu, browser_cpu, rate = run_load(driver, client, url, proc.pid, args.seconds)
                        alone = run_map(driver, client, url, proc.pid, args.seconds)
                        busy = run_map(driver, client, url, proc.pid, args.seconds, groups=100)
                    finally:
                        proc.stop()
                    rows.append((freq, *median_p99(latencies), *median_p99(sparse), rate, liaison_cpu, browser_cpu))
                    map_rows.append((freq, alone, busy))
    print(f"{'update_freq':>11} | {'50 Hz group: median':>19} {'p99 ms':>7} | {'~4 Hz group: median':>19} {'p99 ms':>7} | "
          f"{'pubs/s':>6} {'liaison CPU':>11} {'browser CPU':>11}")
    for freq, busy_med, busy_p99, sparse_med, sparse_p99, rate, liaison_cpu, browser_cpu in rows:
        print(f"{freq:>8g} Hz | {busy_med:>19.1f} {busy_p99:>7.1f} | {sparse_med:>19.1f} {sparse_p99:>7.1f} | "
              f"{rate:>6} {liaison_cpu:>10.0f}% {browser_cpu:>10.0f}%")
    print("latency: publish -> the animation frame after the value reached the page's DOM (one machine clock), for "
          "the values drawn (coalescing skips the others); CPU: 100 groups at 50 Hz, % of one core")
    print()
    print(f"{'map page':>11} | {'20 vehicles x 5 Hz: median':>26} {'p99':>6} {'max ms':>6} {'liaison CPU':>11} "
          f"{'browser CPU':>11} | {'+ 100 groups x 50 Hz: median':>28} {'p99':>6} {'max ms':>6} "
          f"{'liaison CPU':>11} {'browser CPU':>11}")
    for freq, alone, busy in map_rows:
        cells = [f"{freq:>8g} Hz"]
        for width, (latencies, liaison_cpu, browser_cpu, _) in ((26, alone), (28, busy)):
            med, p99 = median_p99(latencies)
            cells.append(f"{med:>{width}.1f} {p99:>6.1f} {max(latencies):>6.1f} {liaison_cpu:>10.0f}% "
                         f"{browser_cpu:>10.0f}%")
        print(" | ".join(cells))
    within = ", ".join(f"{sum(ms <= 200.0 for run in runs for ms in run[0]) / sum(len(run[0]) for run in runs):.1%} "
                       f"at {freq:g} Hz" for freq, *runs in map_rows)
    print(f"map latency: a NodeStatus's publish -> the animation frame that drew it on the canvas, for every "
          f"vehicle's reports ({sum(len(run[0]) for _, *runs in map_rows for run in runs)} in all; within 200 ms: "
          f"{within}); trails of {MAP_TRAIL_POINTS} points; CPU % of one core")
    return 0


if __name__ == "__main__":
    sys.exit(main())
