"""Goby's hold handshake, as the primary portal of a process runs it: a ``PROVIDE_HOLD_STATE`` request every
``HOLD_REQUEST_PERIOD_S`` until the manager answers ``hold: false``, then the release after the settle time.

Pure logic, no sockets: the interprocess portal sends the request frames it returns, hands in the responses it
receives and releases the process's hold when told; all on the primary portal's owning thread.
"""

from __future__ import annotations

from gateway.goby.portal.endpoints import MANAGER_REQUEST_GROUP, MANAGER_RESPONSE_GROUP
from gateway.goby.portal.identifier import encode_frame, make_identifier, type_prefix
from gateway.goby.portal.marshalling import Scheme
from gateway.goby.protobuf.interprocess_zeromq_pb2 import PROVIDE_HOLD_STATE, ManagerRequest, ManagerResponse

HOLD_REQUEST_PERIOD_S = 0.1


class HoldHandshake:
    """When the next request is due, and when the hold is released once the manager has said so."""

    def __init__(self, client_name: str, pid: int, thread_hex: str, settle_s: float) -> None:
        self._client_name = client_name
        self._pid = pid
        self._settle_s = settle_s
        self._request_ident = make_identifier(
            MANAGER_REQUEST_GROUP, Scheme.PROTOBUF, ManagerRequest.DESCRIPTOR.full_name, pid, thread_hex
        )
        #: The subscription prefix of the manager's responses.
        self.response_prefix = type_prefix(
            MANAGER_RESPONSE_GROUP, Scheme.PROTOBUF, ManagerResponse.DESCRIPTOR.full_name
        ).encode()
        self._next_request = 0.0
        self._release_at: float | None = None

    def request_due(self, now: float, ready: bool) -> bytes | None:
        """The request frame to send now, if one is due (none once the manager has released the hold)."""
        if self._release_at is not None or now < self._next_request:
            return None
        self._next_request = now + HOLD_REQUEST_PERIOD_S
        request = ManagerRequest(request=PROVIDE_HOLD_STATE, client_name=self._client_name, client_pid=self._pid,
                                 ready=ready)
        return encode_frame(self._request_ident, request.SerializeToString())

    def on_response(self, response: ManagerResponse, now: float) -> None:
        """A manager response (to any client): ours with ``hold: false`` starts the settle time."""
        if (response.request == PROVIDE_HOLD_STATE and response.client_pid == self._pid
                and response.client_name == self._client_name and not response.hold
                and self._release_at is None):
            self._release_at = now + self._settle_s

    def released(self, now: float) -> bool:
        """True once the settle time after the manager's release has passed."""
        return self._release_at is not None and now >= self._release_at

    def deadline(self) -> float:
        """When :meth:`released` or :meth:`request_due` next has something."""
        return self._release_at if self._release_at is not None else self._next_request
