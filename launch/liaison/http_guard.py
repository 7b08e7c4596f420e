"""Which browsers may talk to the page: the Host and Origin checks (DNS rebinding) and the security headers.

Why the Host header and not only Origin: a page of ``evil.example`` whose name is made to resolve to 127.0.0.1
(DNS rebinding) sends ``Host: evil.example`` and ``Origin: http://evil.example``, which agree with each other.
So the server only answers names it is served under: ``http_address``; the loopback names when it listens on
loopback or on every interface; the machine's host name when it listens on every interface; the configured
``allowed_host`` names; and an address literal equal to the address the connection arrived on (a rebinding
page can only send its own name, never an address).  Ports are not compared: an SSH tunnel
(``ssh -L 8080:localhost:50001``) changes the port the browser sees.  Pure functions and values: any thread.
"""

from __future__ import annotations

import ipaddress
import socket
from urllib.parse import urlsplit

LOOPBACK_NAMES = frozenset({"localhost", "127.0.0.1", "::1"})
WILDCARD_ADDRESSES = frozenset({"", "0.0.0.0", "::"})

#: Every page is our own static files: scripts and styles from /static only (no inline code), the WebSocket
#: back to the page's own origin, and no framing (clickjacking of the commander's Send button).
CONTENT_SECURITY_POLICY = ("default-src 'none'; script-src 'self'; style-src 'self'; img-src 'self'; "
                           "connect-src 'self'; base-uri 'none'; form-action 'self'; frame-ancestors 'none'")
SECURITY_HEADERS = {
    "Content-Security-Policy": CONTENT_SECURITY_POLICY,
    "X-Frame-Options": "DENY",
    "X-Content-Type-Options": "nosniff",
    "Referrer-Policy": "no-referrer",
}


def _normal(name: str) -> str:
    """A host name or address as compared: lower case, no brackets, an address in its canonical form."""
    name = name.strip().lower().strip("[]")
    try:
        address = ipaddress.ip_address(name)
    except ValueError:
        return name.rstrip(".")
    if isinstance(address, ipaddress.IPv6Address) and address.ipv4_mapped is not None:
        address = address.ipv4_mapped
    return str(address)


def host_of(authority: str) -> str | None:
    """The host part of a ``Host`` header value (``name``, ``name:port``, ``[::1]:port``), or None if malformed."""
    try:
        parts = urlsplit(f"//{authority}")
        _ = parts.port  # raises ValueError for a port that is not a number in range
    except ValueError:
        return None
    return _normal(parts.hostname) if parts.hostname else None


class HostGuard:
    """The names this server answers to, derived once from where it listens."""

    def __init__(self, http_address: str, allowed_hosts: list[str]) -> None:
        address = _normal(http_address)
        names = {_normal(h) for h in allowed_hosts}
        if address in WILDCARD_ADDRESSES:
            names |= LOOPBACK_NAMES | {_normal(socket.gethostname())}
        else:
            names.add(address)
            if address == "localhost" or _is_loopback(address):
                names |= LOOPBACK_NAMES
        self.names = frozenset(names)

    def host_allowed(self, host: str | None, local_address: str | None) -> bool:
        """Whether a request's ``Host`` header names this server (``local_address``: where it arrived)."""
        name = host_of(host) if host else None
        if name is None:
            return False
        return name in self.names or (local_address is not None and name == _normal(local_address))

    def origin_allowed(self, origin: str, local_address: str | None) -> bool:
        """Whether an ``Origin`` header is one of this server's own pages (``null`` and other sites are not)."""
        try:
            parts = urlsplit(origin)
        except ValueError:
            return False
        return parts.scheme in ("http", "https") and self.host_allowed(parts.netloc, local_address)

    def describe(self) -> str:
        return ", ".join(sorted(self.names))


def _is_loopback(address: str) -> bool:
    try:
        return ipaddress.ip_address(address).is_loopback
    except ValueError:
        return False
