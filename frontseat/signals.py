"""A minimal signal (boost::signals2 style): drivers emit, the host application connects.

Slots run synchronously on the thread that calls :meth:`Signal.emit` (for drivers: the interface's main
thread, in ``loop()`` or in the driver's I/O callbacks on that thread's reactor). A slot that raises is logged and the remaining slots still run, so one broken
subscriber cannot stop the others from hearing from the frontseat.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from typing import Generic, TypeVar

T = TypeVar("T")
Slot = Callable[[T], None]

log = logging.getLogger(__name__)


class Signal(Generic[T]):
    """An ordered list of slots called with one argument on :meth:`emit`."""

    def __init__(self, name: str) -> None:
        self.name = name
        self._slots: list[Slot[T]] = []

    def connect(self, slot: Slot[T]) -> Slot[T]:
        """Add ``slot``; it runs on the emitting thread. Returns ``slot`` (usable as a decorator)."""
        self._slots.append(slot)
        return slot

    def disconnect(self, slot: Slot[T]) -> None:
        """Remove ``slot`` if connected."""
        if slot in self._slots:
            self._slots.remove(slot)

    def emit(self, value: T) -> None:
        """Call every slot with ``value``, in connection order."""
        for slot in list(self._slots):
            try:
                slot(value)
            except Exception:
                log.exception("slot %r of signal %s raised; continuing with the other slots", slot, self.name)

    def __len__(self) -> int:
        return len(self._slots)
