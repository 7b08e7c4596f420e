"""Our client against a DB: ours always, the real MOOSDB when it may run (same tests, parametrised)."""

from __future__ import annotations

import threading
import time

import pytest

from gateway.moos import MoosMessage, comms
from gateway.moos.clock import MoosClock
from gateway.moos.errors import PoisonedError
from gateway.moos.testing import collect_mail, connected_comms
from util.process import wait_until


def values(msgs: list[MoosMessage]) -> list[object]:
    return [m.double() if m.is_double() else m.binary_data() if m.is_binary() else m.string() for m in msgs]


def test_connects_and_reports_identity(db_port: int) -> None:
    with connected_comms(db_port, "ident") as c:
        assert c.is_connected() and c.is_running() and c.is_asynchronous()
        assert c.get_community_name() == "moos"
        assert c.get_moos_name() == "ident"
        assert c.get_description() == f"127.0.0.1:{db_port}"


def test_notify_all_types_with_aux_and_time(db_port: int) -> None:
    with connected_comms(db_port, "sub", ["D", "S", "B"]) as sub, connected_comms(db_port, "pub") as pub:
        assert pub.notify("D", 3.25, 1234.5)
        assert pub.notify("S", "héllo", "aux-info")
        assert pub.notify("B", "string-typed bytes? no", "aux2", 99.0)
        assert pub.notify_binary("B2", b"\x00\x01\xff", 77.0) is True
        got = collect_mail(sub, ["D", "S", "B"])
        by_key = {m.key(): m for m in got}
        assert by_key["D"].is_double() and by_key["D"].double() == 3.25 and by_key["D"].time() == 1234.5
        assert by_key["S"].is_string() and not by_key["S"].is_binary() and by_key["S"].string() == "héllo"
        assert by_key["S"].source_aux() == "aux-info" and by_key["S"].double() == -1.0
        assert by_key["B"].time() == 99.0 and by_key["B"].source_aux() == "aux2"
        for m in got:
            assert m.source() == "pub" and m.community() == "moos"
        sub.register("B2", 0)
        (blob,) = collect_mail(sub, ["B2"])
        assert blob.is_binary() and blob.binary_data() == b"\x00\x01\xff" and blob.time() == 77.0


def test_default_time_is_moos_time_now(db_port: int) -> None:
    with connected_comms(db_port, "sub", ["T_NOW"]) as sub, connected_comms(db_port, "pub") as pub:
        before = time.time()
        pub.notify("T_NOW", 1.0)
        (msg,) = collect_mail(sub, ["T_NOW"])
        assert before - 1.0 <= msg.time() <= time.time() + 1.0


def test_many_messages_arrive_once_and_in_order(db_port: int) -> None:
    with connected_comms(db_port, "sub", ["SEQ"]) as sub, connected_comms(db_port, "pub") as pub:
        for i in range(2000):
            assert pub.notify("SEQ", float(i))
        got = collect_mail(sub, ["SEQ"], until=2000, timeout=30)
        assert values(got) == [float(i) for i in range(2000)]


def test_registering_delivers_the_current_value(db_port: int) -> None:
    with connected_comms(db_port, "pub") as pub, connected_comms(db_port, "sub") as sub:
        pub.notify("EXISTING", "was here", 42.0)
        pub.notify("FLUSH", 1.0)
        time.sleep(0.2)  # let EXISTING reach the DB before sub registers
        sub.register("EXISTING", 0)
        (msg,) = collect_mail(sub, ["EXISTING"])
        assert msg.string() == "was here" and msg.source() == "pub" and msg.time() == 42.0


def test_interval_decimates_by_dropping(db_port: int) -> None:
    with connected_comms(db_port, "pub") as pub, connected_comms(db_port, "sub") as sub:
        sub.register("FAST", 0.5)
        sub.register("FAST_DONE", 0)
        time.sleep(0.2)
        for i in range(20):
            pub.notify("FAST", float(i))
            time.sleep(0.05)
        pub.notify("FAST_DONE", 1.0)
        got = collect_mail(sub, ["FAST", "FAST_DONE"], until=lambda ms: any(m.key() == "FAST_DONE" for m in ms))
        fast = [m.double() for m in got if m.key() == "FAST"]
        assert fast and fast[0] == 0.0
        assert 1 <= len(fast) < 10, fast
        assert fast == sorted(fast)


def test_unregister_stops_delivery(db_port: int) -> None:
    with connected_comms(db_port, "pub") as pub, connected_comms(db_port, "sub", ["U_VAR", "U_MARK"]) as sub:
        pub.notify("U_VAR", 1.0)
        assert values(collect_mail(sub, ["U_VAR"])) == [1.0]
        assert sub.unregister("U_VAR")
        assert not sub.is_registered_for("U_VAR")
        time.sleep(0.2)  # let the U reach the DB before the next write
        pub.notify("U_VAR", 2.0)
        pub.notify("U_MARK", 1.0)
        got = collect_mail(sub, ["U_VAR", "U_MARK"], until=lambda ms: any(m.key() == "U_MARK" for m in ms))
        assert [m.key() for m in got] == ["U_MARK"]


def test_wildcard_register_and_unregister_quirk(db_port: int) -> None:
    with connected_comms(db_port, "wpub") as pub, connected_comms(db_port, "wsub") as sub:
        pub.notify("W_A", 1.0)
        pub.notify("V_OTHER", 1.0)
        time.sleep(0.2)
        assert sub.register("W_*", "*", 0)
        got = collect_mail(sub, ["W_A", "V_OTHER"], until=1)
        assert [m.key() for m in got] == ["W_A"]
        pub.notify("W_B", 2.0)  # a new variable: the stored filter matches on its first write
        assert [m.key() for m in collect_mail(sub, ["W_B"])] == ["W_B"]
        assert sub.unregister("W_*", "*")
        time.sleep(0.2)
        pub.notify("W_A", 3.0)
        pub.notify("W_NEW", 4.0)  # quirk kept from MOOSDB: the filter survives the wildcard unregister
        got = collect_mail(sub, ["W_A", "W_NEW"], until=lambda ms: any(m.key() == "W_NEW" for m in ms))
        assert [m.key() for m in got] == ["W_NEW"]


def test_wildcard_app_pattern_filters_by_writer(db_port: int) -> None:
    with connected_comms(db_port, "pNav") as nav, connected_comms(db_port, "pOther") as other, \
            connected_comms(db_port, "app_sub") as sub:
        sub.register("*", "pNav", 0)
        time.sleep(0.2)
        other.notify("AP_OTHER", 1.0)
        nav.notify("AP_NAV_X", 2.0)
        got = collect_mail(sub, ["AP_OTHER", "AP_NAV_X"], until=1)
        time.sleep(0.2)
        got += collect_mail(sub, ["AP_OTHER"], until=lambda _: True, timeout=0.1)
        assert [m.key() for m in got] == ["AP_NAV_X"]


def test_type_is_locked_by_the_first_write(db_port: int) -> None:
    with connected_comms(db_port, "tsub", ["TYPED"]) as sub, connected_comms(db_port, "tpub") as pub:
        pub.notify("TYPED", 1.0)
        pub.notify("TYPED", "a string is refused")
        pub.notify("TYPED", 2.0)
        got = collect_mail(sub, ["TYPED"], until=2)
        time.sleep(0.2)
        got += collect_mail(sub, ["TYPED"], until=lambda _: True, timeout=0.05)
        assert values(got) == [1.0, 2.0]


def test_own_notifications_come_back_when_registered(db_port: int) -> None:
    with connected_comms(db_port, "self", ["ECHO"]) as c:
        c.notify("ECHO", 5.0)
        (msg,) = collect_mail(c, ["ECHO"])
        assert msg.source() == "self" and msg.double() == 5.0


def test_duplicate_name_is_poisoned(db_port: int) -> None:
    with connected_comms(db_port, "twin"):
        second = comms()
        try:
            second.run("127.0.0.1", db_port, "twin")
            wait_until(lambda: second.get_fatal_error() is not None, 10, "second.get_fatal_error() is not None")
            assert isinstance(second.get_fatal_error(), PoisonedError)
            assert "already exists" in str(second.get_fatal_error())
            assert not second.is_connected()
        finally:
            second.close()


def test_callbacks_run_on_the_io_thread_and_fetch_gets_mail(db_port: int) -> None:
    threads: dict[str, str] = {}
    woke = threading.Event()
    client = comms()

    def on_connect() -> bool:
        threads["connect"] = threading.current_thread().name
        return client.register("CB_VAR", 0)

    def on_mail() -> bool:
        threads["mail"] = threading.current_thread().name
        woke.set()
        return True

    client.set_on_connect_callback(on_connect)
    client.set_on_mail_callback(on_mail)
    client.run("127.0.0.1", db_port, "cb")
    try:
        assert client.wait_until_connected(10_000)
        with connected_comms(db_port, "cbpub") as pub:
            pub.notify("CB_VAR", 7.0)
            assert woke.wait(10)
            assert values(collect_mail(client, ["CB_VAR"])) == [7.0]
        assert threads["connect"] == threads["mail"] == "moos-comms-cb"
    finally:
        client.close(True)


def test_active_queue_gets_routed_mail_on_the_io_thread(db_port: int) -> None:
    seen: list[tuple[str, float, str]] = []
    done = threading.Event()

    def on_queue(msg: MoosMessage) -> bool:
        seen.append((msg.key(), msg.double(), threading.current_thread().name))
        if len(seen) == 3:
            done.set()
        return True

    with connected_comms(db_port, "aq", ["AQ_VAR", "AQ_OTHER"]) as c, connected_comms(db_port, "aqpub") as pub:
        assert c.add_active_queue("q1", on_queue)
        assert c.add_message_route_to_active_queue("q1", "AQ_VAR")
        assert not c.add_message_route_to_active_queue("missing", "AQ_VAR")
        assert c.has_active_queue("q1")
        for i in range(3):
            pub.notify("AQ_VAR", float(i))
        pub.notify("AQ_OTHER", 9.0)
        assert done.wait(10)
        assert [(k, v) for k, v, _ in seen] == [("AQ_VAR", 0.0), ("AQ_VAR", 1.0), ("AQ_VAR", 2.0)]
        assert all(name == "moos-comms-aq" for _, _, name in seen)  # the client's I/O thread, in order
        assert [m.key() for m in collect_mail(c, ["AQ_VAR", "AQ_OTHER"], until=1)] == ["AQ_OTHER"]
        assert c.remove_active_queue("q1") and not c.has_active_queue("q1")


def test_synchronous_client_exchanges_mail(db_port: int) -> None:
    with connected_comms(db_port, "syncer", ["SY_IN"], asynchronous=False) as sync_client, \
            connected_comms(db_port, "asyncer", ["SY_OUT"]) as async_client:
        assert not sync_client.is_asynchronous()
        async_client.notify("SY_IN", 1.0)
        sync_client.notify("SY_OUT", "from sync")
        assert values(collect_mail(sync_client, ["SY_IN"])) == [1.0]
        assert values(collect_mail(async_client, ["SY_OUT"])) == ["from sync"]


def test_server_requests(db_port: int) -> None:
    with connected_comms(db_port, "qpub") as pub, connected_comms(db_port, "q") as q:
        pub.notify("REQ_VAR", 11.0)
        time.sleep(0.2)
        summary = q.server_request("VAR_SUMMARY")
        assert len(summary) == 1 and "REQ_VAR" in summary[0].string().split(",")
        everything = {m.key(): m for m in q.server_request("ALL")}
        assert everything["REQ_VAR"].double() == 11.0 and everything["REQ_VAR"].source() == "qpub"
        procs = [m.string() for m in q.server_request("PROC_SUMMARY")]
        assert any(p.startswith("qpub:") and "REQ_VAR" in p.split("PUBLISHED=")[1] for p in procs)


def test_db_variables_are_published(db_port: int) -> None:
    with connected_comms(db_port, "dbwatch", ["DB_CLIENTS", "DB_TIME", "DB_UPTIME"]) as c:
        deadline = time.monotonic() + 15
        got: dict[str, MoosMessage] = {}
        while len(got) < 3 and time.monotonic() < deadline:
            c.notify("POKE_THE_DB", 1.0)  # the DB updates its variables when packets arrive
            for m in collect_mail(c, ["DB_CLIENTS", "DB_TIME", "DB_UPTIME"], until=lambda _: True, timeout=0.2):
                got[m.key()] = m
        assert "dbwatch" in got["DB_CLIENTS"].string().split(",")
        assert abs(got["DB_TIME"].double() - time.time()) < 5
        assert got["DB_UPTIME"].double() >= 0
        assert got["DB_TIME"].source().startswith("MOOSDB")


def test_db_event_reports_connections(db_port: int) -> None:
    with connected_comms(db_port, "evwatch", ["DB_EVENT"]) as watcher:
        collect_mail(watcher, ["DB_EVENT"], timeout=1)
        with connected_comms(db_port, "newcomer"):
            pass
        events: list[str] = []
        deadline = time.monotonic() + 15
        while "disconnected=newcomer" not in events and time.monotonic() < deadline:
            watcher.notify("POKE_THE_DB", 1.0)  # the C++ DB pushes held mail only after a notification
            events += [m.string() for m in collect_mail(watcher, ["DB_EVENT"], until=lambda _: True, timeout=0.1)]
        assert "connected=newcomer" in events and "disconnected=newcomer" in events


def test_time_warp_scales_timestamps(db_port: int) -> None:
    clock = MoosClock(10.0)
    client = comms(clock=clock)
    client.do_local_time_correction(False)
    client.set_on_connect_callback(lambda: client.register("WARPED", 0))
    client.run("127.0.0.1", db_port, "warped")
    try:
        assert client.wait_until_connected(10_000)
        client.notify("WARPED", 1.0)
        (msg,) = collect_mail(client, ["WARPED"])
        assert msg.time() == pytest.approx(time.time() * 10.0, rel=1e-6)
    finally:
        client.close()


def test_idle_async_client_stays_alive_on_timing_messages() -> None:
    """The timing message goes out at least once a second, so a DB with a short timeout keeps an idle client."""
    from gateway.moos.testing import running_moosdb

    with running_moosdb(client_timeout=1.5) as db, connected_comms(db.port, "idler", ["DB_QOS"]) as idler:
        deadline = time.monotonic() + 3.5
        while time.monotonic() < deadline:
            assert idler.is_connected() and "idler" in db.client_names()
            time.sleep(0.1)
        assert not db.dropped
        with connected_comms(db.port, "poker") as poker:
            qos = collect_mail(idler, ["DB_QOS"], until=lambda ms: bool(poker.notify("P", 1.0)) and bool(ms),
                               timeout=10)
        assert "idler=" in qos[-1].string()


def test_warped_db_publishes_warped_time() -> None:
    """MOOSTimeWarp multiplies absolute unix time, for the DB's DB_TIME as for client stamps."""
    from gateway.moos.testing import running_moosdb

    with running_moosdb(warp=10.0) as db:
        clock = MoosClock(10.0)
        client = comms(clock=clock)
        client.set_on_connect_callback(lambda: client.register("DB_TIME", 0))
        client.run("127.0.0.1", db.port, "warp10")
        try:
            assert client.wait_until_connected(10_000)
            assert client.welcome is not None and abs(client.welcome.skew) < 5.0  # same warp: tiny skew
            got: list[MoosMessage] = []
            deadline = time.monotonic() + 10
            while not got and time.monotonic() < deadline:
                client.notify("TICK", 1.0)  # 2 s of DB time pass in 0.2 s of real time
                got = collect_mail(client, ["DB_TIME"], until=1, timeout=0.2)
            assert got and got[0].double() == pytest.approx(time.time() * 10.0, rel=1e-6)
        finally:
            client.close()


class AheadClock(MoosClock):
    """Test double: a clock running 100 s ahead, standing in for a DB host whose clock is off."""

    def local_time(self, apply_warp: bool = True) -> float:
        return super().local_time(apply_warp) + 100.0


def test_skew_is_learned_from_the_welcome_and_kept_by_timing_replies() -> None:
    from gateway.moos.server import MoosDB

    db = MoosDB(community="skewed")
    db.clock = db.db.clock = AheadClock()
    with db:
        clock = MoosClock()
        client = comms(clock=clock)
        client.set_quiet(True)  # a quiet client corrects its time even when the DB runs on the same host
        client.set_on_connect_callback(lambda: client.register("SKEWED", 0))
        client.run("127.0.0.1", db.port, "skewer")
        try:
            assert client.wait_until_connected(10_000)
            assert clock.skew == pytest.approx(100.0, abs=0.5)  # from the WELCOME
            welcome_skew = clock.skew
            wait_until(lambda: clock.skew != welcome_skew, 5, "a new skew")  # timing replies blend in new measurements
            assert clock.skew == pytest.approx(100.0, abs=0.5)
            client.notify("SKEWED", 1.0)
            (msg,) = collect_mail(client, ["SKEWED"])
            assert msg.time() == pytest.approx(time.time() + 100.0, abs=1.0)  # stamped in the DB's time
        finally:
            client.close()


def test_response_option_slows_a_client_down() -> None:
    """MOOSDB's --response: the DB asks a client (by name or pattern) to batch its writes; nothing is lost."""
    from gateway.apps.moos_db import parse_response
    from gateway.moos.testing import running_moosdb

    assert parse_response("x_app:20, *_inst:0") == {"x_app": 0.02, "*_inst": 0.0}
    with pytest.raises(ValueError, match="not name:milliseconds"):
        parse_response("oops")

    def arrival_spread(db_port: int, name: str) -> float:
        with connected_comms(db_port, "watch_" + name, [name + "_V"]) as watcher, \
                connected_comms(db_port, name) as writer:
            time.sleep(1.3)  # a timing round trip tells the writer its delay

            def write_spaced() -> None:
                for i in range(5):
                    writer.notify(name + "_V", float(i))
                    time.sleep(0.05)

            sender = threading.Thread(target=write_spaced, name="spaced-writer")
            sender.start()
            arrivals: dict[float, float] = {}
            deadline = time.monotonic() + 10
            while len(arrivals) < 5 and time.monotonic() < deadline:
                for m in watcher.fetch():
                    arrivals[m.double()] = time.monotonic()
                time.sleep(0.002)
            sender.join(10)
            assert sorted(arrivals) == [0.0, 1.0, 2.0, 3.0, 4.0]
            return arrivals[3.0] - arrivals[1.0]

    with running_moosdb(response={"slow*": 0.3}) as db:
        assert arrival_spread(db.port, "slowpoke") < 0.05  # 1..3 waited for the same batch
        assert arrival_spread(db.port, "quick") >= 0.08  # sent as they came, 50 ms apart
