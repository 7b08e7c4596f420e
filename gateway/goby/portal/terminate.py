"""Clean termination on request, as Goby3's ``terminate::Application`` (src/middleware/terminate/terminate.h).

goby-terminate publishes a ``TerminateRequest`` on ``goby::terminate::request`` naming an application by name or
pid; the application it names publishes a ``TerminateResponse`` (its name and pid) on ``goby::terminate::response``
and quits cleanly.  The callback runs on the application's main thread.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Callable
from typing import TYPE_CHECKING

from gateway.goby.portal.group import Group
from gateway.goby.portal.protobuf.terminate_pb2 import TerminateRequest, TerminateResponse

if TYPE_CHECKING:
    from gateway.goby.portal.thread import SimpleThread

log = logging.getLogger(__name__)

#: Goby3's ``goby::middleware::groups::terminate_request`` / ``terminate_response`` / ``terminate_result``
#: (src/middleware/terminate/groups.h).
TERMINATE_REQUEST = Group("goby::terminate::request")
TERMINATE_RESPONSE = Group("goby::terminate::response")
TERMINATE_RESULT = Group("goby::terminate::result")


def check_terminate(request: TerminateRequest, app_name: str) -> tuple[bool, TerminateResponse]:
    """Does ``request`` name this application (by name, else by pid)?  And the response to send if it does."""
    pid = os.getpid()
    response = TerminateResponse(target_name=app_name, target_pid=pid)
    if request.HasField("target_name") and request.target_name == app_name:
        return True, response
    return request.HasField("target_pid") and request.target_pid == pid, response


def subscribe_terminate(app: SimpleThread, app_name: Callable[[], str], quit_app: Callable[[], None]) -> None:
    """Answer and ``quit_app()`` on a ``TerminateRequest`` naming this application (``app``'s main thread)."""

    def on_request(request: TerminateRequest) -> None:
        match, response = check_terminate(request, app_name())
        if match:
            log.info("goby-terminate asked %s (pid %d) to quit", response.target_name, response.target_pid)
            app.interprocess().publish(TERMINATE_RESPONSE, response)
            quit_app()

    app.interprocess().subscribe(TERMINATE_REQUEST, TerminateRequest, on_request)
