"""``goby-coroner``: ask every process of the platform for its health and publish the vehicle's, as Goby3's
``goby_coroner`` (src/apps/zeromq/coroner/coroner.cpp).

Every ``request_interval`` seconds it publishes a ``HealthRequest`` on ``goby::health::request``; ``response_timeout``
seconds later it publishes a ``VehicleHealth`` on ``goby::health::report``: each tracked name (``expected_name``, and
with ``auto_add_new_apps`` every name that ever answered) with its ``ProcessHealth``, or, when it did not answer,
``HEALTH__FAILED`` with ``ERROR__PROCESS_DIED``; the vehicle's state is the worst of them.  With ``report_file`` each
report is also appended there as one line, in goby_coroner's format.  Both periods are simulated seconds under warp.
Timers on the main thread's reactor: nothing runs between a request and its report.
"""

from __future__ import annotations

import logging
import sys
import time
from typing import IO

from google.protobuf import text_format

from gateway.goby.portal import SingleThreadApplication, run_application
from gateway.goby.portal.errors import StartError
from gateway.goby.portal.health import HEALTH_REPORT, HEALTH_REQUEST, HEALTH_RESPONSE
from gateway.goby.portal.protobuf.coroner_config_pb2 import CoronerConfig
from gateway.goby.portal.protobuf.coroner_pb2 import (
    ERROR__PROCESS_DIED,
    HEALTH__FAILED,
    HEALTH__OK,
    HealthRequest,
    HealthState,
    ProcessHealth,
    VehicleHealth,
)
from util.reactor import Timer

log = logging.getLogger(__name__)


def ptime_text(micro: int) -> str:
    """A time as Boost's ``ptime`` prints it (``2024-Oct-10 17:09:48.123456``; no fraction when it is zero)."""
    seconds, fraction = divmod(int(micro), 1_000_000)
    text = time.strftime("%Y-%b-%d %H:%M:%S", time.gmtime(seconds))
    return f"{text}.{fraction:06d}" if fraction else text


class Coroner(SingleThreadApplication):
    """Requests health, collects the answers by process name, reports the vehicle's health."""

    def __init__(self, cfg: CoronerConfig) -> None:
        if not cfg.request_interval > 0 or not cfg.response_timeout > 0:
            raise StartError("request_interval and response_timeout must be positive")
        super().__init__(cfg)
        self._tracked: set[str] = set(cfg.expected_name)
        self._responses: dict[str, ProcessHealth] = {}
        self._report_timer: Timer | None = None
        self._report_file: IO[str] | None = None
        if cfg.response_timeout >= cfg.request_interval:
            log.warning("response_timeout (%g s) >= request_interval (%g s): no report is ever published "
                        "(each request starts over, as goby_coroner)", cfg.response_timeout, cfg.request_interval)
        if cfg.HasField("report_file"):
            try:
                self._report_file = open(cfg.report_file, "a", buffering=1)  # noqa: SIM115 - closed in finalize
            except OSError as exc:
                raise StartError(f"cannot open report_file {cfg.report_file}: {exc.strerror}") from None
            log.info("Opening: %s", cfg.report_file)
        self.interprocess().subscribe(HEALTH_RESPONSE, ProcessHealth, self._on_response)

    def _warped(self, seconds: float) -> float:
        return seconds / self.context.clock.effective_warp

    def initialize(self) -> None:
        self._request()
        self.reactor.call_every(lambda: self._warped(self.cfg().request_interval), self._request, align=False)

    def finalize(self) -> None:
        if self._report_file is not None:
            self._report_file.close()
            self._report_file = None

    def _on_response(self, response: ProcessHealth) -> None:
        log.debug("Received response: %s", text_format.MessageToString(response, as_one_line=True))
        self._responses[response.name] = response
        if self.cfg().auto_add_new_apps and response.name not in self._tracked:
            log.info("Tracking new process name: %s", response.name)
            self._tracked.add(response.name)

    def _request(self) -> None:
        self.interprocess().publish(HEALTH_REQUEST, HealthRequest())
        self._responses.clear()
        if self._report_timer is not None:
            self._report_timer.cancel()
        self._report_timer = self.reactor.call_later(self._warped(self.cfg().response_timeout), self._report)

    def _report(self) -> None:
        self._report_timer = None
        report = self.build_report()
        level = logging.DEBUG if report.state == HEALTH__OK else logging.WARNING
        log.log(level, "Vehicle report: %s", text_format.MessageToString(report, as_one_line=True))
        self.interprocess().publish(HEALTH_REPORT, report)
        if self._report_file is not None:
            self._report_file.write(self.report_line(report) + "\n")

    def build_report(self) -> VehicleHealth:
        """The ``VehicleHealth`` from the answers received since the last request."""
        report = VehicleHealth(time=self.context.clock.now_micro(), platform=self.cfg().interprocess.platform)
        state: HealthState.ValueType = HEALTH__OK
        for name in sorted(self._tracked):  # goby_coroner iterates a std::set: sorted by name
            answer = self._responses.get(name)
            if answer is None:
                log.warning("No response from: %s", name)
                state = HEALTH__FAILED
                process = report.process.add(name=name)
                process.main.name = name
                process.main.state = HEALTH__FAILED
                process.main.error = ERROR__PROCESS_DIED
                process.main.error_message = f"Process {name} has died"
            else:
                state = max(state, answer.main.state)
                report.process.add().CopyFrom(answer)
        report.state = state
        return report

    def report_line(self, report: VehicleHealth) -> str:
        """One line of ``report_file``: ``<app>/<platform>`` padded to 30, the time, the state, then failures."""
        who = f"{self.app_name()}/{report.platform}"
        line = f"{who:<30}[{ptime_text(self.context.clock.now_micro())}]: {HealthState.Name(report.state)}"
        if report.state != HEALTH__OK:
            for process in report.process:
                if process.main.state != HEALTH__OK:
                    line += f'; {process.main.name}: "{process.main.error_message}"'
        return line


def main(argv: list[str] | None = None) -> int:
    return run_application(Coroner, CoronerConfig, argv, prog="goby-coroner")


if __name__ == "__main__":
    sys.exit(main())
