"""``goby-terminate``: ask applications to quit cleanly and wait until they have, as Goby3's ``goby_terminate``
(src/apps/zeromq/terminate/terminate.cpp).

``--target_name NAME`` / ``--target_pid PID`` (repeatable): a ``TerminateRequest`` per target on
``goby::terminate::request``, sent again at goby_terminate's 10 Hz until the target answers.  Each
``TerminateResponse`` is published as a ``TerminateResult`` ``PROCESS_RESPONDED`` on ``goby::terminate::result``; when
the answering process has ended (a pidfd on the reactor, no polling) ``PROCESS_CLEANLY_QUIT``.  After
``response_timeout`` seconds (default 10, simulated under warp) every target still silent is ``TIMEOUT_RESPONSE`` and
every one still running ``TIMEOUT_RUNNING``.  Each result is also printed on stdout, one line in text format.
Exit status 0 once every target has quit, 1 on a timeout or without any target (as goby_terminate).
"""

from __future__ import annotations

import logging
import os
import sys

from google.protobuf import text_format

from gateway.goby.portal import SingleThreadApplication, run_application
from gateway.goby.portal.errors import StartError
from gateway.goby.portal.protobuf.terminate_config_pb2 import TerminateConfig
from gateway.goby.portal.protobuf.terminate_pb2 import TerminateRequest, TerminateResponse, TerminateResult
from gateway.goby.portal.terminate import TERMINATE_REQUEST, TERMINATE_RESPONSE, TERMINATE_RESULT
from util.reactor import Timer

log = logging.getLogger(__name__)

REQUEST_PERIOD_S = 0.1  # goby_terminate's loop: 10 Hz (warped)


class Terminate(SingleThreadApplication):
    """Sends the requests, tracks who answered and who has quit, publishes the results."""

    def __init__(self, cfg: TerminateConfig) -> None:
        if not cfg.target_name and not cfg.target_pid:
            raise StartError("Error, must specify at least one --target_name or --target_pid")
        if not cfg.response_timeout > 0:
            raise StartError("response_timeout must be positive")
        super().__init__(cfg)
        self._waiting_names: set[str] = set(cfg.target_name)
        self._waiting_pids: set[int] = set(cfg.target_pid)
        self._running: dict[int, str] = {}  # answered, not yet ended: pid -> name
        self._pidfds: dict[int, int] = {}
        self._request_timer: Timer | None = None
        self.interprocess().subscribe(TERMINATE_RESPONSE, TerminateResponse, self._on_response)

    def _warped(self, seconds: float) -> float:
        return seconds / self.context.clock.effective_warp

    def initialize(self) -> None:
        self._send_requests()
        self._request_timer = self.reactor.call_every(lambda: self._warped(REQUEST_PERIOD_S), self._send_requests,
                                                      align=False)
        self.reactor.call_later(self._warped(self.cfg().response_timeout), self._timeout)

    def finalize(self) -> None:
        for pid, fd in self._pidfds.items():
            self.reactor.remove_reader(fd)
            os.close(fd)
            log.debug("stopped watching pid %d", pid)
        self._pidfds.clear()

    def _send_requests(self) -> None:
        for name in sorted(self._waiting_names):
            self.interprocess().publish(TERMINATE_REQUEST, TerminateRequest(target_name=name))
        for pid in sorted(self._waiting_pids):
            self.interprocess().publish(TERMINATE_REQUEST, TerminateRequest(target_pid=pid))
        if not self._waiting_names and not self._waiting_pids and self._request_timer is not None:
            self._request_timer.cancel()

    def _result(self, result: TerminateResult.Result.ValueType, name: str | None = None,
                pid: int | None = None) -> None:
        message = TerminateResult(result=result)
        if name is not None:
            message.target_name = name
        if pid is not None:
            message.target_pid = pid
        self.interprocess().publish(TERMINATE_RESULT, message)
        print(text_format.MessageToString(message, as_one_line=True), flush=True)

    def _on_response(self, response: TerminateResponse) -> None:
        pid, name = response.target_pid, response.target_name
        self._result(TerminateResult.PROCESS_RESPONDED, name, pid)
        ours = False
        if pid in self._waiting_pids:
            self._waiting_pids.discard(pid)
            ours = True
        if name in self._waiting_names:
            self._waiting_names.discard(name)
            ours = True
        if ours and pid not in self._running:
            log.debug("terminate response from our target %s (pid %d)", name, pid)
            self._running[pid] = name
            self._watch(pid)

    def _watch(self, pid: int) -> None:
        try:
            fd = os.pidfd_open(pid)
        except ProcessLookupError:
            self._ended(pid)
            return
        except OSError as exc:  # e.g. another user's process: cannot watch it
            log.warning("cannot watch pid %d (%s); it counts as running", pid, exc.strerror)
            return
        self._pidfds[pid] = fd
        self.reactor.add_reader(fd, lambda: self._ended(pid))

    def _ended(self, pid: int) -> None:
        fd = self._pidfds.pop(pid, None)
        if fd is not None:
            self.reactor.remove_reader(fd)
            os.close(fd)
        name = self._running.pop(pid, "")
        log.debug("PID: %d (was %s) has quit.", pid, name)
        self._result(TerminateResult.PROCESS_CLEANLY_QUIT, name, pid)
        if not self._waiting_names and not self._waiting_pids and not self._running:
            log.debug("All processes have cleanly quit.")
            self.quit(0)

    def _timeout(self) -> None:
        for name in sorted(self._waiting_names):
            self._result(TerminateResult.TIMEOUT_RESPONSE, name=name)
        for pid in sorted(self._waiting_pids):
            self._result(TerminateResult.TIMEOUT_RESPONSE, pid=pid)
        if self._waiting_names or self._waiting_pids:
            log.warning("Timeout waiting for response from targets: %s",
                        ", ".join([*sorted(self._waiting_names), *map(str, sorted(self._waiting_pids))]))
        for pid, name in sorted(self._running.items()):
            self._result(TerminateResult.TIMEOUT_RUNNING, name, pid)
        if self._running:
            log.warning("Timeout waiting for targets that responded to our request but have not stopped running: %s",
                        ", ".join(f"{pid} (was {name})" for pid, name in sorted(self._running.items())))
        self.quit(1)


def main(argv: list[str] | None = None) -> int:
    return run_application(Terminate, TerminateConfig, argv, prog="goby-terminate")


if __name__ == "__main__":
    sys.exit(main())
