"""Replay in the page: the vehicles' NodeStatus of a recorded ``.goby`` log (goby-logger's), served by position.

The page only names a log the server listed (a file name under a configured ``replay_dir``, never a path) and asks
for the picture at a time; the server reads the log, not the page.  Bounded: a log is read once into compact
columns (``array('d')``), at most ``max_samples`` NodeStatus samples in all (later ones are counted and dropped, and
the page is told), at most one sample per vehicle per :data:`MIN_SPACING_S` of log time; a frame carries each
vehicle's last :data:`FRAME_TRAIL_POINTS` trail points at most.  Opened logs are cached by (path, size, mtime),
:data:`CACHE_LOGS` at most, so many pages on the same log cost one copy.

Threads: :func:`load` runs on a worker thread of the web loop's executor (a large log must not stall the pages);
:class:`ReplayLog` is immutable once loaded and read from the web thread.
"""

from __future__ import annotations

import bisect
import logging
import math
import os
import threading
from array import array
from collections import OrderedDict
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from frontseat.protobuf.frontseat_data_pb2 import NodeStatus, VehicleType
from gateway.goby.log.errors import LogFormatError
from gateway.goby.log.reader import LogReader
from gateway.goby.portal.marshalling import Scheme
from launch.liaison.map_model import MAX_COORDINATE_M, MAX_NAME_CHARS, MAX_VEHICLES, NODE_STATUS_TYPE

log = logging.getLogger(__name__)

LOG_SUFFIX = ".goby"
MAX_LISTED = 500  # logs listed to a page
MAX_DEPTH = 3  # folders below a replay_dir searched for logs (goby-logger writes <run>/logs/<platform>/...)
MIN_SPACING_S = 0.5  # log seconds between two samples kept of one vehicle
FRAME_TRAIL_POINTS = 300
CACHE_LOGS = 2


class ReplayError(ValueError):
    """A log that cannot be replayed; the text says why (shown in the page)."""


@dataclass(eq=False)
class _Track:
    name: str
    type: str = ""
    t: array = field(default_factory=lambda: array("d"))
    x: array = field(default_factory=lambda: array("d"))
    y: array = field(default_factory=lambda: array("d"))
    heading: array = field(default_factory=lambda: array("d"))
    speed: array = field(default_factory=lambda: array("d"))

    def at(self, when: float, trail_s: float) -> dict[str, Any] | None:
        """The vehicle at log time ``when`` (its last sample at or before it) with the trail of ``trail_s`` s."""
        i = bisect.bisect_right(self.t, when) - 1
        if i < 0:
            return None
        first = bisect.bisect_left(self.t, when - trail_s, 0, i + 1)
        step = max(1, (i + 1 - first) // FRAME_TRAIL_POINTS)
        trail = [[self.x[k], self.y[k]] for k in range(first, i + 1, step)]
        return {"name": self.name, "type": self.type, "x": self.x[i], "y": self.y[i], "heading": self.heading[i],
                "speed": self.speed[i], "time": self.t[i], "trail": trail}


@dataclass(eq=False)
class ReplayLog:
    """The NodeStatus tracks of one log."""

    name: str
    tracks: dict[str, _Track]
    t0: float
    t1: float
    samples: int
    dropped: int  # samples beyond max_samples
    skipped: int  # spans of the file the reader could not use

    def summary(self) -> dict[str, Any]:
        return {"name": self.name, "t0": self.t0, "t1": self.t1, "samples": self.samples, "dropped": self.dropped,
                "skipped": self.skipped, "vehicles": sorted(self.tracks)}

    def frame(self, when: float, trail_s: float) -> dict[str, Any]:
        when = min(max(when, self.t0), self.t1)
        vehicles = [v for track in self.tracks.values() if (v := track.at(when, trail_s)) is not None]
        return {"t": when, "vehicles": vehicles}


def list_logs(folders: list[Path]) -> list[dict[str, Any]]:
    """The ``.goby`` logs under the folders (newest first): name (relative to its folder, prefixed by the
    folder's index when there are several), size."""
    found: list[tuple[float, str, int]] = []
    for index, folder in enumerate(folders):
        if not folder.is_dir():
            continue
        base_depth = len(folder.parts)
        for root, dirs, files in os.walk(folder):
            if len(Path(root).parts) - base_depth >= MAX_DEPTH:
                dirs[:] = []
            for name in files:
                if not name.endswith(LOG_SUFFIX):
                    continue
                path = Path(root) / name
                try:
                    stat = path.stat()
                except OSError:
                    continue
                shown = str(path.relative_to(folder))
                found.append((stat.st_mtime, f"{index}:{shown}" if len(folders) > 1 else shown, stat.st_size))
    found.sort(reverse=True)
    return [{"name": name, "size": size} for _, name, size in found[:MAX_LISTED]]


def resolve(folders: list[Path], name: str) -> Path:
    """The file a listed name stands for; ReplayError for anything the listing would not have given."""
    listed = {entry["name"] for entry in list_logs(folders)}
    if name not in listed:
        raise ReplayError(f"no log {name!r} in the replay folders (ask for the list again)")
    index, _, rest = name.partition(":") if len(folders) > 1 else ("0", "", name)
    return folders[int(index)] / rest


class ReplayCache:
    """Loaded logs by (path, size, mtime); thread-safe (loads run on executor threads)."""

    def __init__(self, max_samples: int) -> None:
        self.max_samples = max_samples
        self._lock = threading.Lock()
        self._logs: OrderedDict[tuple[str, int, float], ReplayLog] = OrderedDict()

    def load(self, path: Path, name: str) -> ReplayLog:
        try:
            stat = path.stat()
        except OSError as exc:
            raise ReplayError(f"cannot read {name}: {exc.strerror or exc}") from None
        key = (str(path), stat.st_size, stat.st_mtime)
        with self._lock:
            cached = self._logs.get(key)
            if cached is not None:
                self._logs.move_to_end(key)
                return cached
        replay = load(path, name, self.max_samples)
        with self._lock:
            self._logs[key] = replay
            while len(self._logs) > CACHE_LOGS:
                self._logs.popitem(last=False)
        return replay


def load(path: Path, name: str, max_samples: int) -> ReplayLog:
    """Read a log's NodeStatus entries into tracks (bounded: see the module's docstring)."""
    tracks: dict[str, _Track] = {}
    samples = dropped = 0
    skipped: list[object] = []
    try:
        with LogReader(path, on_skip=skipped.append) as reader:
            for entry in reader:
                if entry.scheme != Scheme.PROTOBUF or entry.type_name != NODE_STATUS_TYPE:
                    continue
                if samples >= max_samples:
                    dropped += 1
                    continue
                status = NodeStatus()
                try:
                    status.ParseFromString(entry.data)
                except Exception:  # noqa: BLE001 - a bad entry is counted, the rest is replayed
                    skipped.append(entry.offset)
                    continue
                if not status.HasField("local_fix"):
                    continue
                t = entry.timestamp_micro / 1e6
                values = (t, status.local_fix.x, status.local_fix.y, status.pose.heading % 360.0,
                          status.speed.over_ground)
                if not all(math.isfinite(v) for v in values) or max(abs(values[1]), abs(values[2])) > MAX_COORDINATE_M:
                    skipped.append(entry.offset)
                    continue
                vehicle = (status.name or entry.group)[:MAX_NAME_CHARS]
                track = tracks.get(vehicle)
                if track is None:
                    if len(tracks) >= MAX_VEHICLES:
                        dropped += 1
                        continue
                    track = tracks[vehicle] = _Track(vehicle)
                if track.t and (t - track.t[-1] < MIN_SPACING_S):
                    continue  # also drops a sample out of time order (the arrays stay sorted)
                track.type = VehicleType.Name(status.type) if status.HasField("type") else track.type
                for column, value in zip((track.t, track.x, track.y, track.heading, track.speed), values,
                                         strict=True):
                    column.append(round(value, 2))
                samples += 1
    except LogFormatError as exc:
        raise ReplayError(str(exc)) from None
    if not tracks:
        raise ReplayError(f"{name} holds no NodeStatus with a local fix (nothing to draw)")
    t0 = min(track.t[0] for track in tracks.values())
    t1 = max(track.t[-1] for track in tracks.values())
    if dropped:
        log.warning("replay %s: %d NodeStatus samples beyond %d were not loaded", name, dropped, max_samples)
    return ReplayLog(name, tracks, t0, t1, samples, dropped, len(skipped))
