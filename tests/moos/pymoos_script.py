"""A pymoos-style script, run as a child process by test_interop.py with either ``pymoos`` or ``gateway.moos``.

Only the import differs between the two runs, which is the drop-in promise. It prints one JSON line of results.
Usage: ``python pymoos_script.py MODULE PORT NAME``
"""

from __future__ import annotations

import importlib
import json
import sys
import threading
import time


def main() -> int:
    moos = importlib.import_module(sys.argv[1])  # "import pymoos" vs "import gateway.moos"
    port, name = int(sys.argv[2]), sys.argv[3]
    results: dict[str, object] = {}
    mail: list[tuple[str, str, object, str]] = []
    queued: list[float] = []
    lock = threading.Lock()
    got_mail = threading.Event()
    queue_done = threading.Event()

    listener = moos.comms()
    talker = moos.comms()

    def on_connect() -> bool:
        listener.register("PY_DOUBLE", 0)
        listener.register("PY_STRING", 0)
        listener.register("PY_BINARY", 0)
        listener.register("PY_Q", 0)
        listener.register("PYW_*", "*", 0)
        return True

    def on_mail() -> bool:
        for msg in listener.fetch():  # pymoos scripts fetch inside the callback
            if msg.is_binary():
                value: object = list(msg.binary_data())
            elif msg.is_double():
                value = msg.double()
            else:
                value = msg.string()
            with lock:
                mail.append((msg.key(), msg.source(), value, msg.community()))
        got_mail.set()
        return True

    def on_queue(msg) -> bool:
        queued.append(msg.double())
        if len(queued) == 3:
            queue_done.set()
        return True

    listener.set_on_connect_callback(on_connect)
    listener.set_on_mail_callback(on_mail)
    listener.add_active_queue("pyq", on_queue)
    listener.add_message_route_to_active_queue("pyq", "PY_Q")
    listener.run("127.0.0.1", port, name + "_listener")
    talker.run("127.0.0.1", port, name + "_talker")
    results["connected"] = listener.wait_until_connected(5000) and talker.wait_until_connected(5000)
    time.sleep(0.5)  # the listener's registrations reach the DB
    results["community"] = talker.get_community_name()
    results["registered"] = sorted(listener.get_registered())
    t0 = moos.time()
    talker.notify("PY_DOUBLE", 1.25)
    talker.notify("PY_STRING", "hello pymoos")
    talker.notify("PY_DOUBLE", 2.5, t0)
    talker.notify_binary("PY_BINARY", bytes([0, 1, 2, 255]))
    talker.notify("PYW_ANY", 9.0)
    for i in range(3):
        talker.notify("PY_Q", float(i))
    deadline = time.time() + 10
    while time.time() < deadline:
        with lock:
            if len(mail) >= 5:
                break
        time.sleep(0.01)
    queue_done.wait(10)
    results["mail"] = mail[:]
    results["queued"] = queued[:]
    results["time_ok"] = abs(moos.time() - time.time()) < 5
    talker.close(True)
    listener.close(True)
    print(json.dumps(results), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
