"""goby-liaison: end-to-end latency from a publish to the value drawn in the browser, and what 100 busy groups cost.

    python -m bench.bench_liaison [--seconds 8]

A real broker, ``goby-liaison`` as its own process and headless Chromium on the scope page.  Latency: a publisher
sends ``seq`` on one group at 50 Hz and remembers when; the page records, for every value it shows, the time of
the animation frame after the DOM changed (``performance.timeOrigin + now()``, the same wall clock).  Values that
the coalescing skipped are not drawn and not counted.  CPU: 100 groups at 50 Hz each (5000 publications/s) for
the same time, with the CPU seconds of the liaison process and of every Chromium process (the page's cost).
"""

from __future__ import annotations

import argparse
import os
import random
import re
import sys
import tempfile
import time
from pathlib import Path
from typing import TYPE_CHECKING

from bench.stats import median_p99
from gateway.goby.portal.testing import BrokerProcess, PortalClient, broker_process
from launch.liaison.portal_side import READY_PREFIX
from launch.liaison.testing import PROFILE_PREFIX as PROFILE_MARKER
from launch.liaison.testing import browser_skip_reason, chromium
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
    pids = []
    for cmdline in Path("/proc").glob("[0-9]*/cmdline"):
        try:
            if profile_marker.encode() in cmdline.read_bytes():
                pids.append(int(cmdline.parent.name))
        except OSError:
            continue
    return pids


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
    client.poll(0.5)
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
        client.poll(period_s * (0.5 + random.random()) if jitter else period_s)
    client.poll(1.0)
    drawn = driver.execute_script("return window._drawn")
    return [(at / 1000.0 - sent[value]) * 1000.0 for value, at in drawn if value in sent]


def run_load(driver: WebDriver, client: PortalClient, url: str, liaison_pid: int, seconds: float,
             groups: int = 100, hz: float = 50.0) -> tuple[float, float, int]:
    driver.get(f"{url}/?_=/scope")
    time.sleep(1.0)
    browser_pids = chromium_pids(PROFILE_MARKER)
    start_liaison_cpu, start_browser_cpu = cpu_seconds([liaison_pid]), cpu_seconds(browser_pids)
    started = time.monotonic()
    period = 1.0 / hz
    sent = 0
    next_at = started
    while time.monotonic() - started < seconds:
        for g in range(groups):
            client.publish(f"busy::group{g:03d}", f"value {sent}")
            sent += 1
        next_at += period
        client.poll(max(0.0, next_at - time.monotonic()))
    elapsed = time.monotonic() - started
    liaison = (cpu_seconds([liaison_pid]) - start_liaison_cpu) / elapsed * 100
    browser = (cpu_seconds(browser_pids) - start_browser_cpu) / elapsed * 100
    return liaison, browser, int(sent / elapsed)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seconds", type=float, default=8.0)
    args = parser.parse_args(argv)
    skip = browser_skip_reason()
    if skip:
        print(f"skipped: {skip}")
        return 0
    rows = []
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
                    finally:
                        proc.stop()
                    rows.append((freq, *median_p99(latencies), *median_p99(sparse), rate, liaison_cpu, browser_cpu))
    print(f"{'update_freq':>11} | {'50 Hz group: median':>19} {'p99 ms':>7} | {'~4 Hz group: median':>19} {'p99 ms':>7} | "
          f"{'pubs/s':>6} {'liaison CPU':>11} {'browser CPU':>11}")
    for freq, busy_med, busy_p99, sparse_med, sparse_p99, rate, liaison_cpu, browser_cpu in rows:
        print(f"{freq:>8g} Hz | {busy_med:>19.1f} {busy_p99:>7.1f} | {sparse_med:>19.1f} {sparse_p99:>7.1f} | "
              f"{rate:>6} {liaison_cpu:>10.0f}% {browser_cpu:>10.0f}%")
    print("latency: publish -> the animation frame after the value reached the page's DOM (one machine clock), for "
          "the values drawn (coalescing skips the others); CPU: 100 groups at 50 Hz, % of one core")
    return 0


if __name__ == "__main__":
    sys.exit(main())
