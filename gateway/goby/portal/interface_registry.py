"""A per-process record of every publish/subscribe call, for the interface-file tool.

Each distinct (layer, direction, group, scheme, type, thread) is recorded once.  Every application records into
its own registry (``ProcessContext.registry``): read it in-process with ``context.registry.entries()``, or set
``GOBY_INTERFACE_REGISTRY=<path>`` and applications write it as JSON when they exit (see docs/portal.md).
"""

from __future__ import annotations

import json
import logging
import os
import threading
from dataclasses import asdict, dataclass
from pathlib import Path

log = logging.getLogger(__name__)

ENV_VAR = "GOBY_INTERFACE_REGISTRY"


@dataclass(frozen=True, slots=True, order=True)
class InterfaceEntry:
    """One kind of call: ``layer`` is interprocess/interthread, ``direction`` publish/subscribe."""

    layer: str
    direction: str
    group: str
    scheme: str
    type: str
    thread: str
    application: str = ""


class InterfaceRegistry:
    """Thread-safe set of :class:`InterfaceEntry`."""

    def __init__(self) -> None:
        self._entries: set[InterfaceEntry] = set()
        self._lock = threading.Lock()

    def record(self, entry: InterfaceEntry) -> None:
        if entry in self._entries:  # common case, no lock needed for a read of a set
            return
        with self._lock:
            self._entries.add(entry)

    def entries(self) -> list[InterfaceEntry]:
        """All entries, sorted."""
        with self._lock:
            return sorted(self._entries)

    def clear(self) -> None:
        with self._lock:
            self._entries.clear()

    def to_json(self) -> str:
        return json.dumps([asdict(e) for e in self.entries()], indent=1)

    def write(self, path: str | os.PathLike[str]) -> None:
        """Write the entries as a JSON list of objects."""
        Path(path).write_text(self.to_json())

    def write_if_requested(self) -> None:
        """Write to ``$GOBY_INTERFACE_REGISTRY`` if set (an error is logged, never raised).

        If it names a directory, each process writes ``<dir>/<pid>.json``, so one setting can serve a whole
        launch of many applications.
        """
        target = os.environ.get(ENV_VAR)
        if not target:
            return
        if os.path.isdir(target):
            target = os.path.join(target, f"{os.getpid()}.json")
        try:
            self.write(target)
        except OSError as exc:
            log.error("cannot write interface registry to %s: %s", target, exc)


def read_entries(path: str | os.PathLike[str]) -> list[InterfaceEntry]:
    """Entries written by :meth:`InterfaceRegistry.write`."""
    return [InterfaceEntry(**item) for item in json.loads(Path(path).read_text())]

