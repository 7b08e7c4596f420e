"""moos-gateway's threads as a process: a translator handles MOOS mail on its own thread, the process has no MOOS
I/O thread (the client lives on the translator's reactor), and an idle gateway seldom wakes up."""

from __future__ import annotations

import json
import time
from pathlib import Path

from gateway_plugin_sources import THREADS_PLUGIN

from gateway.goby.portal.testing import broker_process
from gateway.moos.testing import collect_mail, connected_comms, moosdb_process
from translators.moos_interface import TIME_VAR
from translators.testing import GatewayProcess

WARP = 10
# Goby's translator loop alone would wake 10 Hz x warp = 100 times a second, plus the client's I/O thread.
MAX_IDLE_WAKE_UPS_PER_S = 60
WINDOW_S = 3.0


def _config(broker, moos_port: int, extra: str = "") -> str:
    return (f'app {{ name: "gw_threads" {extra} }} interprocess {{ {broker.interprocess_text()} }} '
            f'moos {{ server: "127.0.0.1" port: {moos_port} }}')


def _wake_ups(pid: int) -> int:
    """Voluntary context switches (a thread blocked, then was woken) of every thread of ``pid`` so far."""
    total = 0
    for status in Path(f"/proc/{pid}/task").glob("*/status"):
        try:
            lines = status.read_text().splitlines()
        except FileNotFoundError:  # the thread ended meanwhile
            continue
        total += sum(int(line.split()[1]) for line in lines if line.startswith("voluntary_ctxt_switches"))
    return total


def test_mail_is_handled_on_the_translator_thread_with_no_moos_io_thread(tmp_path):
    plugin = tmp_path / "threads_plugin.py"
    plugin.write_text(THREADS_PLUGIN)
    with moosdb_process(tmp_path) as db, broker_process(tmp_path, platform="gwthreads") as broker, \
            GatewayProcess(tmp_path, [str(plugin)], _config(broker, db.port)) as gateway, \
            connected_comms(db.port, "asker", register=["THREADS"]) as asker:
        reports: list = []
        for _ in range(100):  # until the translator has registered (it connects asynchronously)
            asker.notify("WHO", "?")
            reports = collect_mail(asker, ["THREADS"], until=1, timeout=0.2)
            if reports:
                break
        assert reports, gateway.stderr()
        assert gateway.stop() == 0, gateway.stderr()
    report = json.loads(reports[0].string())
    assert report["handled_on"] == report["constructed_on"]
    assert report["handler_thread"] == "ThreadsTranslator"
    # the gateway's main thread and the translator's: no moos-comms-* thread, nothing else that only waits
    assert report["threads"] == ["MainThread", "ThreadsTranslator"], report["threads"]


def test_an_idle_gateway_wakes_rarely(tmp_path):
    """At warp 10 the translator's tick runs once per simulated second (it does not override ``loop()``), and its
    MOOS client adds only its keep-alive: the whole process wakes far less often than Goby's 10 Hz x warp loop."""
    plugin = tmp_path / "threads_plugin.py"
    plugin.write_text(THREADS_PLUGIN)
    sim = f"simulation {{ time {{ use_sim_time: true warp_factor: {WARP} }} }}"
    with moosdb_process(tmp_path, warp=WARP) as db, broker_process(tmp_path, platform="gwidle") as broker, \
            GatewayProcess(tmp_path, [str(plugin)], _config(broker, db.port, sim)) as gateway, \
            connected_comms(db.port, "watcher", register=[TIME_VAR]) as watcher:
        assert collect_mail(watcher, [TIME_VAR], until=2, timeout=30), gateway.stderr()  # up and ticking
        pid = gateway.proc.pid
        before, start = _wake_ups(pid), time.monotonic()
        time.sleep(WINDOW_S)  # the measuring window: the gateway is left alone
        after, elapsed = _wake_ups(pid), time.monotonic() - start
        assert gateway.proc.running, gateway.stderr()
    rate = (after - before) / elapsed
    assert 0 < rate < MAX_IDLE_WAKE_UPS_PER_S, f"{rate:.1f} wake-ups/s"
