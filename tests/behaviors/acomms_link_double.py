"""Test double of the USV -> AUV acomms link: the USV's node report reaches each AUV's MOOSDB once per slot.

In the course the USV's navigation goes out as a DCCL NavigationReport in the USV's acomms slot, and each AUV's
gateway posts it as ``NODE_REPORT`` (``NAME=USV,TYPE=USV,...``). This double stands in for that whole chain
(manager, DCCL, modem, gateway) until the real link exists: every ``slot`` seconds of MOOS time it takes the latest
``NODE_REPORT_LOCAL`` from the USV's MOOSDB, rounds the values as NavigationReport's DCCL fields do (0.1 m, 1 m
depth, 1 degree, 0.1 m/s), and posts the course's line to every AUV's MOOSDB. Runs on its own thread.
"""

from __future__ import annotations

import math
import threading
import time

from gateway.moos import MoosClock, comms
from translators.node_report_codec import NodeReport, angle360, format_course_report, parse_node_report


def _dccl(value: float, decimals: int) -> float:
    """DCCL's quantisation: ``floor(v * 10^p + 0.5) / 10^p``."""
    scale = 10.0**decimals
    return math.floor(value * scale + 0.5) / scale


def course_contact_line(local_report: str, name: str = "USV", vehicle_type: str = "USV") -> str:
    """The NODE_REPORT the course's gateway would post for this NODE_REPORT_LOCAL (values DCCL-rounded, and
    DEPTH written as ``-z``, so a surface vehicle reads ``DEPTH=-0`` as in the course)."""
    src = parse_node_report(local_report)
    z = _dccl(-(src.depth or 0.0), 0)
    report = NodeReport(name=name, type=vehicle_type, time=src.time, x=_dccl(src.x or 0.0, 1),
                        y=_dccl(src.y or 0.0, 1), depth=-z, heading=_dccl(angle360(src.heading or 0.0), 0) % 360,
                        speed=_dccl(src.speed or 0.0, 1))
    return format_course_report(report)


class AcommsLinkDouble:
    """Forwards the source DB's latest NODE_REPORT_LOCAL to the destination DBs once per ``slot`` (MOOS s)."""

    def __init__(self, source_port: int, dest_ports: list[int], clock: MoosClock, slot: float = 20.0) -> None:
        self.clock, self.slot = clock, slot
        self.delivered: list[tuple[float, str]] = []
        self._source = comms(clock=clock)
        self._dests = [comms(clock=clock) for _ in dest_ports]
        self._ports = (source_port, dest_ports)
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    def __enter__(self) -> AcommsLinkDouble:
        source_port, dest_ports = self._ports
        self._source.set_on_connect_callback(lambda: self._source.register("NODE_REPORT_LOCAL", 0))
        self._source.run("127.0.0.1", source_port, "acomms_link_double")
        for client, port in zip(self._dests, dest_ports, strict=True):
            client.run("127.0.0.1", port, "acomms_link_double")
        for client in (self._source, *self._dests):
            if not client.wait_until_connected(10000):
                self.__exit__()
                raise TimeoutError("the acomms link double could not connect")
        self._thread = threading.Thread(target=self._run, name="acomms-link-double", daemon=True)
        self._thread.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(10)
        for client in (self._source, *self._dests):
            client.close(True)

    def _run(self) -> None:
        latest = ""
        next_slot = self.clock.time() + self.slot
        while not self._stop.is_set():
            for msg in self._source.fetch():
                if msg.key() == "NODE_REPORT_LOCAL" and msg.is_string():
                    latest = msg.string()
            now = self.clock.time()
            if now >= next_slot:
                next_slot += self.slot
                if latest:
                    line = course_contact_line(latest)
                    for client in self._dests:
                        client.notify("NODE_REPORT", line)
                    self.delivered.append((now, line))
            time.sleep(0.01)
