"""DB restart: clients reconnect and re-register by themselves (the moos-db process killed and restarted)."""

from __future__ import annotations

import threading
import time
from pathlib import Path

from gateway.moos import comms
from gateway.moos.testing import collect_mail, connected_comms, moosdb_process, running_moosdb
from util.process import wait_until


def test_clients_reconnect_and_reregister_after_a_db_crash(tmp_path: Path) -> None:
    with moosdb_process(tmp_path) as db:
        sub = comms()
        connects = []
        disconnected = threading.Event()
        sub.set_on_connect_callback(lambda: connects.append(True))  # registers nothing itself
        sub.set_on_disconnect_callback(disconnected.set)
        sub.register("AFTER_CRASH", 0)  # before run(): remembered and applied on every connection
        sub.register("W_*", "*", 0)
        sub.run("127.0.0.1", db.port, "survivor")
        try:
            with connected_comms(db.port, "writer") as pub:
                assert sub.wait_until_connected(10_000)
                wait_until(lambda: sub.is_registered_for("AFTER_CRASH"), 5, "sub.is_registered_for('AFTER_CRASH')")
                pub.notify("AFTER_CRASH", 1.0)
                assert [m.double() for m in collect_mail(sub, ["AFTER_CRASH"])] == [1.0]

                db.restart()  # SIGKILL, then a new moos-db on the same port
                assert disconnected.wait(10)
                wait_until(lambda: len(connects) >= 2 and sub.is_connected() and pub.is_connected(), 20, "len(connects) >= 2 and sub.is_connected() and p...")
                time.sleep(0.3)  # let the re-registration reach the new DB
                pub.notify("AFTER_CRASH", 2.0)
                pub.notify("W_NEW", 3.0)
                got = collect_mail(sub, ["AFTER_CRASH", "W_NEW"])
                assert sorted((m.key(), m.double()) for m in got) == [("AFTER_CRASH", 2.0), ("W_NEW", 3.0)]
        finally:
            sub.close()


def test_on_connect_registration_is_not_doubled_by_the_automatic_one() -> None:
    """A remembered registration plus the same one from on-connect gives one R, so one current value."""
    with running_moosdb() as db, connected_comms(db.port, "w") as pub:
        pub.notify("ONCE", 1.0)
        sub = comms()
        sub.register("ONCE", 0)  # remembered: applied automatically on connect
        sub.set_on_connect_callback(lambda: sub.register("ONCE", 0))  # ... and again, pymoos style
        sub.run("127.0.0.1", db.port, "reader")
        try:
            got = collect_mail(sub, ["ONCE"])
            time.sleep(0.3)
            got += collect_mail(sub, ["ONCE"], until=lambda _: True, timeout=0.05)
            assert [m.double() for m in got] == [1.0]
            assert sub.register("ONCE", 0.5)  # a new interval is sent as usual
        finally:
            sub.close()
