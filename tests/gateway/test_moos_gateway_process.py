"""moos-gateway end to end: our MOOSDB, goby-broker and moos-gateway as processes, a plugin file in a temp dir.

Checks both directions, buffering, the translator time variable, re-registration after the MOOSDB restarts,
and a clean exit on SIGTERM/SIGINT.
"""

from __future__ import annotations

import re
import signal
import time

import pytest
from gateway_plugin_sources import ECHO_PLUGIN

from gateway.goby.portal.testing import PortalClient, broker_process
from gateway.moos.testing import collect_mail, connected_comms, moosdb_process, real_moos_skip_reason
from translators.moos_interface import TIME_VAR
from translators.testing import GatewayProcess


def _gateway_config(broker, moos_port: int) -> str:
    return (f'app {{ name: "gw_under_test" }} interprocess {{ {broker.interprocess_text()} }} '
            f'moos {{ server: "127.0.0.1" port: {moos_port} }}')


def _moos_to_goby(poster, peer: PortalClient, got: list[str], tag: str, buffered: str) -> str:
    """Notify B then IN until the translator (which connects asynchronously) forwards one; returns it."""
    for attempt in range(150):
        poster.notify("B", buffered)
        poster.notify("IN", f"{tag}{attempt}")
        if peer.poll_until(lambda: any(g.startswith(tag) for g in got), 0.2):
            return next(g for g in got if g.startswith(tag))
    raise AssertionError(f"no {tag} message came through the gateway; got {got}")


REAL = pytest.param("real", signal.SIGTERM, id="real-MOOSDB-SIGTERM", marks=[
    pytest.mark.interop, pytest.mark.skipif(real_moos_skip_reason() is not None, reason=str(real_moos_skip_reason()))])


@pytest.mark.parametrize(("moosdb_kind", "stop_signal"), [pytest.param("ours", signal.SIGTERM, id="ours-SIGTERM-restart"),
                                                         pytest.param("ours", signal.SIGINT, id="ours-SIGINT"), REAL])
def test_gateway_process_end_to_end(tmp_path, moosdb_kind, stop_signal):
    plugin = tmp_path / "echo_plugin.py"
    plugin.write_text(ECHO_PLUGIN)
    with moosdb_process(tmp_path, program=None if moosdb_kind == "ours" else "MOOSDB") as db, broker_process(tmp_path, platform="gwe2e") as broker:
        gateway = GatewayProcess(tmp_path, [str(plugin)], _gateway_config(broker, db.port), extra_args=["-v"])
        with gateway, PortalClient(broker.interprocess_config(), name="peer") as peer, \
                connected_comms(db.port, "poster", register=["OUT", "OUT_LOWER", TIME_VAR, "DB_CLIENTS"]) as poster:
            from_moos = peer.collect("from_moos", str)
            assert peer.wait_subscribed()

            # MOOS -> Goby, with the buffered B of the same or an earlier batch
            first = _moos_to_goby(poster, peer, from_moos, "before", "bee")
            assert re.fullmatch(r"before\d+\|bee", first)

            # Goby -> MOOS: one publication becomes two notifies
            peer.publish("to_moos", "Hello")
            out = collect_mail(poster, ["OUT", "OUT_LOWER"])
            assert sorted((m.key(), m.string()) for m in out) == [("OUT", "HELLO"), ("OUT_LOWER", "hello")]
            assert all(m.source().startswith("goby::moos::Translator::") for m in out)

            # the translator's time variable, about once a second
            times = collect_mail(poster, [TIME_VAR], until=2, timeout=20)
            assert len(times) >= 2
            assert re.fullmatch(r"moostime=[0-9.e+]+,gobytime=[0-9.e+]+\n", times[-1].string())

            if stop_signal == signal.SIGTERM:
                # the MOOSDB dies and comes back on the same port: the translator re-registers by itself
                db.restart()
                assert poster.wait_until_connected(20_000)
                from_moos.clear()
                again = _moos_to_goby(poster, peer, from_moos, "after", "bee2")
                assert re.fullmatch(r"after\d+\|bee2", again)
                for attempt in range(100):
                    peer.publish("to_moos", f"Again{attempt}")
                    if collect_mail(poster, ["OUT"], until=1, timeout=0.3):
                        break
                else:
                    raise AssertionError("Goby -> MOOS did not resume after the MOOSDB restart")

            def translator_listed(got) -> bool:
                return any("goby::moos::Translator::" in m.string() for m in got)

            assert translator_listed(collect_mail(poster, ["DB_CLIENTS"], until=translator_listed, timeout=20))
            assert gateway.stop(stop_signal) == 0, gateway.stderr()
            # the translator's MOOS client closed: the DB no longer lists it (a DB publishes DB_CLIENTS while it
            # handles traffic, so keep poking it)
            clients: list = []
            for _ in range(40):
                poster.notify("POKE", 1.0)
                clients += collect_mail(poster, ["DB_CLIENTS"], until=1, timeout=0.5)
                if clients and not translator_listed(clients[-1:]):
                    break
            assert clients and not translator_listed(clients[-1:]), [m.string() for m in clients]
        assert "Traceback" not in gateway.stderr()


def test_warp_speeds_up_the_translator_clock(tmp_path):
    """With ``use_sim_time`` and warp 10, the translator ticks once per simulated second (its plugin does not
    override ``loop()``), so the time variable comes ~10 times a real second, carrying warped MOOS and Goby times."""
    plugin = tmp_path / "echo_plugin.py"
    plugin.write_text(ECHO_PLUGIN)
    with moosdb_process(tmp_path, warp=10) as db, broker_process(tmp_path, platform="gwwarp") as broker:
        config = _gateway_config(broker, db.port) + " app { simulation { time { use_sim_time: true warp_factor: 10 } } }"
        with GatewayProcess(tmp_path, [str(plugin)], config), \
                connected_comms(db.port, "watcher", register=[TIME_VAR]) as watcher:
            assert collect_mail(watcher, [TIME_VAR], until=1, timeout=30)  # the translator is up
            start = time.time()
            posts = collect_mail(watcher, [TIME_VAR], until=lambda got: time.time() - start > 2.0, timeout=10)
    assert len(posts) >= 6, [p.string() for p in posts]  # warp 1 would give 2
    values = [re.fullmatch(r"moostime=([0-9.e+]+),gobytime=([0-9.e+]+)\n", p.string()) for p in posts]
    goby_times = [float(v.group(2)) for v in values]
    moos_times = [float(v.group(1)) for v in values]
    assert moos_times[-1] - moos_times[0] > 5.0  # MOOS time is warped too (SetMOOSTimeWarp)
    # warped Goby time runs ahead of real time (Goby's warp is relative to the start of the year)
    assert goby_times[-1] - goby_times[0] > 5.0
    assert goby_times[-1] > time.time() + 60
