"""Small socket helpers shared by the reactor-driven servers (the MOOSDB and the frontseat simulator)."""

from __future__ import annotations

import logging
import socket

log = logging.getLogger(__name__)


def accept_client(listener: socket.socket) -> tuple[socket.socket, str] | None:
    """Accept one connection on a non-blocking ``listener``: ``(socket, "host:port")``, the socket non-blocking with
    TCP_NODELAY; None when no connection is waiting or accept failed (logged; the server keeps serving)."""
    try:
        sock, addr = listener.accept()
    except (BlockingIOError, InterruptedError):
        return None
    except OSError as exc:
        log.warning("accept failed: %s", exc)
        return None
    sock.setblocking(False)
    sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    return sock, f"{addr[0]}:{addr[1]}"
