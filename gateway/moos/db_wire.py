"""The MOOSDB's hot path: a packet's messages applied straight from its bytes, runs of notifications in one step.

A client that publishes fast sends packets of many notifications, mostly runs of the same variable from the same
source with the same field lengths. Decoding each into a ``MoosMessage`` and encoding it again for every subscriber
is most of the DB's work in Python, so here a packet is walked in place: each message's fixed fields are read with
one compiled ``struct`` layout (the one of the previous message, checked field by field, as ``decode_packet_body``
does); consecutive notifications of one variable from one source (same aux and community) form a *run*, applied at once (the variable keeps
the last value; counts, write sequence and frequency as if applied one by one) and forwarded to subscribers as the
received bytes, one slice per run. A message that carries no community gets the DB's spliced in (CMOOSDB does the
same), per message. Anything else -- registrations, server requests, the first write of a variable, a type
mismatch, caps about to be reached, names over ``max_name_bytes`` -- goes message by message through
:meth:`MoosDatabase.notify` and friends, so the semantics are those of ``database.py`` exactly.

Strictness is the codec's: a length that disagrees with the fields, a field that overruns, or a count that
disagrees with the header is a ProtocolError (the messages before it in the packet have been applied, as MOOSDB
applies what it read before it stops reading a packet). Not thread-safe: the server's one I/O thread calls it.
"""

from __future__ import annotations

from collections.abc import Callable
from struct import Struct
from typing import TYPE_CHECKING, Any

from .codec import _head_struct, _head_structs, decode_message
from .errors import ProtocolError
from .message import DOUBLE, NOTIFY, MoosMessage

if TYPE_CHECKING:
    from .database import MoosDatabase

_I32 = Struct("<i")
_pack_i32 = _I32.pack
_unpack_i32 = _I32.unpack_from

# field positions in a layout's tuple: length, id, type, data type, n_src, src, n_aux, aux, n_com, com, n_key, key,
# time, val, val2, n_sval (the string payload follows the fixed part)
LENGTH, TYPE, DTYPE, SRC, AUX, COM, KEY, TIME, VAL, NSVAL = 0, 2, 3, 5, 7, 9, 11, 12, 13, 15


def process_wire(db: MoosDatabase, buf: bytes, pos: int, end: int, count: int, client: bytes
                 ) -> tuple[list[MoosMessage], bool]:
    """Apply the ``count`` messages in ``buf[pos:end]`` (a packet's body, its leading timing message already
    taken) from ``client``; returns (server-request replies, had a notification), as ``MoosDatabase.process``."""
    now = db.clock.time()
    max_name = db.limits.max_name_bytes
    layout: Struct | None = None
    lengths = (-1, -1, -1, -1)
    names_ok = False
    run_start = run_stop = run_n = 0
    run_f: tuple[Any, ...] | None = None  # the run's first message's fields
    last_f: tuple[Any, ...] = ()  # and its last's
    seen = 0
    had_notify = False
    p = pos
    while p < end:
        f = None
        if layout is not None and p + layout.size <= end:
            f = layout.unpack_from(buf, p)
            if not ((f[4], f[6], f[8], f[10]) == lengths and f[NSVAL] >= 0 and f[LENGTH] == layout.size + f[NSVAL]
                    and p + f[LENGTH] <= end):
                f = None
        if f is None:
            msg, stop = decode_message(buf, p, end)
            lengths = (len(msg.raw_src), len(msg.raw_aux), len(msg.raw_community), len(msg.raw_key))
            layout = _head_structs.get(lengths) or _head_struct(*lengths)
            names_ok = max(lengths[:3]) <= max_name
            f = layout.unpack_from(buf, p)
        stop = p + f[LENGTH]
        seen += 1
        if f[TYPE] != NOTIFY or not names_ok:
            had_notify |= f[TYPE] == NOTIFY
            if run_f is not None:
                _apply_run(db, buf, run_start, run_stop, run_n, run_f, last_f, now, client)
                run_f = None
            db.process_one(decode_message(buf, p, stop)[0], now, client)
            p = stop
            continue
        had_notify = True
        if (run_f is not None and f[KEY] == run_f[KEY] and f[SRC] == run_f[SRC] and f[DTYPE] == run_f[DTYPE]
                and f[COM] == run_f[COM] and f[AUX] == run_f[AUX]):
            run_stop = stop
            run_n += 1
            last_f = f
        else:
            if run_f is not None:
                _apply_run(db, buf, run_start, run_stop, run_n, run_f, last_f, now, client)
            run_f = last_f = f
            run_start, run_stop, run_n = p, stop, 1
        if f[DTYPE] == DOUBLE and f[NSVAL] == 0:
            # a stream of one double: the next messages differ from this one only in id, time and values, so
            # compare their bytes at once instead of unpacking their fields
            assert layout is not None
            size = layout.size
            scan = _scanners.get(size) or _scanner(size)
            header = buf[p + 8:stop - 28]
            q = stop
            while q + size <= end:
                length, same, n_sval = scan(buf, q)
                if length != size or n_sval or same != header:
                    break
                q += size
            if q > stop:
                more = (q - stop) // size
                run_n += more
                seen += more
                run_stop = stop = q
                last_f = layout.unpack_from(buf, q - size)
        p = stop
    if run_f is not None:
        _apply_run(db, buf, run_start, run_stop, run_n, run_f, last_f, now, client)
    if seen != count:
        raise ProtocolError(f"packet header says {count} messages but its body holds {seen}")
    return db.end_of_packet(now), had_notify


_scanners: dict[int, Callable[[bytes, int], tuple[Any, ...]]] = {}


def _scanner(size: int) -> Callable[[bytes, int], tuple[Any, ...]]:
    """Unpacks (length, the bytes from type to key, string length) of a message of ``size`` bytes without string."""
    unpack = Struct(f"<i4x{size - 36}s24xi").unpack_from
    if len(_scanners) < 4096:
        _scanners[size] = unpack
    return unpack


def _apply_run(db: MoosDatabase, buf: bytes, start: int, stop: int, n: int, first: tuple[Any, ...],
               last: tuple[Any, ...], now: float, client: bytes) -> None:
    """``n`` notifications of one variable from one source in ``buf[start:stop]``: at once when the variable
    exists with this type and the caps are far, else one by one through ``MoosDatabase.notify``."""
    key: bytes = first[KEY]
    dtype: bytes = first[DTYPE]
    limits = db.limits
    var = db.vars.get(key)
    if (var is None or not var.written or var.data_type != dtype or client == db.name
            or limits.stored_bytes + (stop - start) > limits.max_stored_bytes):
        # the first write (type, filters, caps), a type mismatch, or near the caps: exactly as one by one
        p = start
        while p < stop:
            msg, p = decode_message(buf, p, stop)
            db.notify(msg, now, client)
            var = db.vars.get(key)
            n -= 1
            if n and var is not None and var.written and var.data_type == dtype and client != db.name and \
                    limits.stored_bytes + (stop - p) <= limits.max_stored_bytes:
                start = p
                first = _fields_at(buf, p, first)
                break
        else:
            return
    src: bytes = last[SRC]
    com: bytes = last[COM]
    limits.stored_bytes -= len(var.aux) + len(var.writer) + len(var.community) + len(var.sval)
    var.written_time = now
    var.msg_time = last[TIME]
    var.writer = src
    var.aux = last[AUX]
    var.community = com or db.community
    if dtype == DOUBLE:
        var.dval = last[VAL]
    else:
        nsval: int = last[NSVAL]
        var.sval = buf[stop - nsval:stop]
    limits.stored_bytes += len(var.aux) + len(var.writer) + len(var.community) + len(var.sval)
    if src not in var.writers:
        var.writers.add(src)
        db.rw_version += 1
    db.count_writes(var, n, now)
    if not var.subscribers:
        return
    first_len: int = first[LENGTH]
    if com:
        db.fan_out(var, buf[start:stop], n, buf[start:start + first_len], now)
        return
    # no community: splice the DB's in after each message's aux (the same offset in every message of the run)
    community = db.community
    at = 14 + len(first[SRC]) + 4 + len(first[AUX])
    middle = _pack_i32(len(community)) + community
    grow = len(community)
    parts: list[bytes | memoryview] = []
    view = memoryview(buf)
    p = start
    while p < stop:
        (length,) = _unpack_i32(buf, p)
        parts += (_pack_i32(length + grow), view[p + 4:p + at], middle, view[p + at + 4:p + length])
        p += length
    first_wire = b"".join(parts[:4])
    db.fan_out(var, b"".join(parts) if n > 1 else first_wire, n, first_wire, now)


def _fields_at(buf: bytes, p: int, like: tuple[Any, ...]) -> tuple[Any, ...]:
    """The fields of the message at ``p``, which has the same layout as ``like``."""
    lengths = (len(like[SRC]), len(like[AUX]), len(like[COM]), len(like[KEY]))
    layout = _head_structs.get(lengths) or _head_struct(*lengths)
    return layout.unpack_from(buf, p)
