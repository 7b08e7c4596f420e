"""The MOOSDB's sliced jobs (``db_jobs.py``) on their own: the merge of sorted runs, the queue, DB_CLEAR's steps."""

from __future__ import annotations

import random
import time
from collections.abc import Generator

from gateway.moos import db_jobs
from gateway.moos.clock import MoosClock
from gateway.moos.codec import decode_packet, frame_packet
from gateway.moos.database import DBVar, MoosDatabase
from gateway.moos.db_jobs import JOB_SLICE_S, SORT_RUN, JobQueue, Steps, drain
from gateway.moos.message import DOUBLE, NOTIFY, REGISTER, SERVER_REQUEST, STRING, UNREGISTER, MoosMessage


def steps_of(gen: Generator[None, None, object]) -> tuple[int, object]:
    """(how many times the job yielded, its result)."""
    count = 0
    while True:
        try:
            next(gen)
        except StopIteration as done:
            return count, done.value
        count += 1


def reply(key: bytes) -> MoosMessage:
    return MoosMessage(NOTIFY, STRING, -2, key=key, sval=b"x")


def job(replies: list[MoosMessage], n_steps: int) -> Steps:
    for _ in range(n_steps):
        yield
    return replies


def slow_job(replies: list[MoosMessage], n_steps: int) -> Steps:
    for _ in range(n_steps):
        time.sleep(JOB_SLICE_S * 1.5)
        yield
    return replies


def test_names_are_sorted_a_run_at_a_time_and_merged() -> None:
    names = [b"V%06d" % i for i in range(3 * SORT_RUN + 17)]
    random.Random(1).shuffle(names)
    n_steps, merged = steps_of(db_jobs.sorted_names(names))
    assert list(merged) == sorted(names)  # type: ignore[call-overload]
    assert n_steps == 4  # one step per run: no step sorts them all


def test_a_few_names_are_sorted_in_one_go() -> None:
    n_steps, merged = steps_of(db_jobs.sorted_names([b"b", b"a", b"c"]))
    assert n_steps == 0 and list(merged) == [b"a", b"b", b"c"]  # type: ignore[call-overload]


def test_sorted_vars_skips_a_variable_removed_during_the_walk() -> None:
    variables = {name: DBVar(name, DOUBLE) for name in (b"c", b"a", b"b")}
    walk = drain(db_jobs.sorted_vars(variables))
    del variables[b"b"]
    assert [v.name for v in walk] == [b"a", b"c"]


def test_small_jobs_reply_inline_in_the_order_cxx_sends() -> None:
    delivered: list[tuple[bytes, list[bytes]]] = []
    queue = JobQueue(lambda owner, wire: delivered.append((owner, wire)))
    queue.add(b"a", job([reply(b"FIRST")], 0))
    queue.add(b"a", job([reply(b"SECOND")], 1))
    assert queue.pending and queue.has_new and queue.in_progress(b"a") == 2 and queue.in_progress(b"b") == 0
    got = queue.run_new()
    assert [m.raw_key for m in got] == [b"SECOND", b"FIRST"]  # each request's replies pushed to the front
    assert not queue.pending and not delivered


def test_late_replies_are_encoded_and_delivered_together() -> None:
    delivered: list[tuple[bytes, list[bytes]]] = []
    queue = JobQueue(lambda owner, wire: delivered.append((owner, wire)))
    replies = [reply(b"R%d" % i) for i in range(3)]
    queue.add(b"a", slow_job(replies, 3))
    assert queue.run_new() == []  # a step outlasts the slice: the rest is left for run()
    while queue.pending:
        queue.run(0.001)
    (owner, wire), = delivered
    assert owner == b"a" and [m.raw_key for m in decode_packet(frame_packet(wire))] == [b"R0", b"R1", b"R2"]


def test_jobs_of_the_db_itself_deliver_nothing() -> None:
    delivered: list[tuple[bytes, list[bytes]]] = []
    queue = JobQueue(lambda owner, wire: delivered.append((owner, wire)))
    queue.add(None, job([reply(b"X")], 3))
    queue.run(1.0)
    assert not queue.pending and not delivered


def test_db_clear_spares_variables_written_after_the_request() -> None:
    variables = {name: DBVar(name, DOUBLE) for name in (b"OLD", b"NEW")}
    variables[b"OLD"].seq, variables[b"NEW"].seq = 5, 9
    forgotten: list[bytes] = []
    assert drain(db_jobs.clear_steps(variables, 7, lambda var: forgotten.append(var.name))) is None
    assert forgotten == [b"OLD"]


def test_rw_summary_names_subscriptions_and_writes_in_name_order_and_its_cache_follows_changes() -> None:
    db = MoosDatabase("c", MoosClock())
    for name in (b"x", b"y"):
        db.connect(name, True)
    db.process([MoosMessage(REGISTER, DOUBLE, 1, src=b"x", key=b"B"), MoosMessage(REGISTER, DOUBLE, 2, src=b"x", key=b"A"),
                MoosMessage(NOTIFY, DOUBLE, 3, src=b"x", key=b"C", dval=1.0)], b"x")
    assert drain(db_jobs.rw_summary_steps(db)) == b"x=A:B&C,y=&"
    db.process([MoosMessage(NOTIFY, DOUBLE, 4, src=b"x", key=b"C", dval=2.0)], b"x")  # nothing new: cached
    assert db.rw_cache is not None and db.rw_cache[0] == db.rw_version
    db.process([MoosMessage(REGISTER, DOUBLE, 5, src=b"y", key=b"C")], b"y")
    assert drain(db_jobs.rw_summary_steps(db)) == b"x=A:B&C,y=C&"
    db.process([MoosMessage(NOTIFY, DOUBLE, 6, src=b"y", key=b"A", dval=1.0)], b"y")
    db.process([MoosMessage(UNREGISTER, DOUBLE, 7, src=b"x", key=b"B")], b"x")
    assert drain(db_jobs.rw_summary_steps(db)) == b"x=A&C,y=C&A"
    db.disconnect(b"y")
    procs = [m.string() for m in db.server_request(MoosMessage(SERVER_REQUEST, STRING, -2, key=b"PROC_SUMMARY"))]
    assert procs == ["x:SUBSCRIBED=,A,PUBLISHED=,C"]


def test_summary_line_shortens_long_strings() -> None:
    var = DBVar(b"LONG", STRING)
    var.sval = b"s" * 40
    line = db_jobs.summary_line(var)
    assert "s" * 22 + "..." in line and "s" * 23 not in line and "(write pending)" in line
