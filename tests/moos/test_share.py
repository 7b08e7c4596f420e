"""moos-share (pShare's role): configuration parsing, the datagram codec, two of our DBs sharing through two of our
moos-share processes, malformed datagrams, and the real pShare exchanging variables with ours.

The real pShare and MOOSDB listen on every address, so they run only inside a private network namespace, e.g.::

    unshare -n bash -c 'ip link set lo up && exec "$@"' _ \\
        env PATH=/work/cpp/moos-ivp/bin:$PATH .venv/bin/python -m pytest -q tests/moos/test_share.py
"""

from __future__ import annotations

import re
import socket
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest

from gateway.moos.codec import encode_message
from gateway.moos.message import DOUBLE, NOTIFY, REGISTER, STRING, MoosMessage
from gateway.moos.share import (
    MAX_UDP_SIZE,
    ShareError,
    ShareSettings,
    ShareTable,
    decode_datagram,
    encode_datagram,
    parse_route,
)
from gateway.moos.testing import collect_mail, connected_comms, moosdb_process, real_moos_skip_reason
from util.process import ChildProcess


# ---- pure parts -------------------------------------------------------------------------------------------
def test_datagram_round_trip_keeps_every_field() -> None:
    msg = MoosMessage(NOTIFY, STRING, 17, b"uSimMarine", b"aux", b"alpha", b"NODE_REPORT_LOCAL", 1234.5, -1.0, -1.0,
                      b"NAME=alpha,X=1")
    data = encode_datagram(msg, "NODE_REPORT")
    assert data == encode_message(MoosMessage(NOTIFY, STRING, 17, b"uSimMarine", b"aux", b"alpha", b"NODE_REPORT",
                                              1234.5, -1.0, -1.0, b"NAME=alpha,X=1"))
    back = decode_datagram(data)
    assert (back.key(), back.source(), back.source_aux(), back.community(), back.time(), back.string()) == (
        "NODE_REPORT", "uSimMarine", "aux", "alpha", 1234.5, "NAME=alpha,X=1")


def test_datagram_limits_and_malformed() -> None:
    with pytest.raises(ShareError, match="payload limit"):
        encode_datagram(MoosMessage(NOTIFY, STRING, key=b"BIG", sval=b"x" * MAX_UDP_SIZE))
    good = encode_message(MoosMessage(NOTIFY, DOUBLE, 1, b"src", key=b"X", msg_time=1.0, dval=2.0))
    bad = [b"", b"garbage", good[:-1], good + b"\0",
           encode_message(MoosMessage(REGISTER, DOUBLE, 1, b"src", key=b"X", msg_time=1.0)),
           encode_message(MoosMessage(NOTIFY, b"Z", 1, b"src", key=b"X", msg_time=1.0)),
           encode_message(MoosMessage(NOTIFY, DOUBLE, 1, b"src", key=b"", msg_time=1.0)),
           encode_message(MoosMessage(NOTIFY, DOUBLE, 1, b"src", key=b"X", msg_time=float("nan"))),
           b"\xff\xff\xff\x7f" + good[4:]]
    for data in bad:
        with pytest.raises(ShareError):
            decode_datagram(data)
    assert decode_datagram(good).double() == 2.0


def test_config_long_short_and_wildcard_forms() -> None:
    table = ShareTable()
    table.add_config_line("src_name = X, dest_name = Y, route = localhost:9201 & multicast_8, frequency=2", True)
    table.add_config_line("Z->localhost:9202", True)
    table.add_config_line("P->Q:localhost:9203@4.0 & multicast_3 & R:multicast_4", True)
    table.add_config_line("src_name=V*:GPS,dest_name=shared_,route=localhost:9204", True)
    table.add_config_line("route = localhost:9301 & multicast_9, white_list = A*&B", False)
    assert [(r.dest_name, str(r.address), r.frequency) for r in table.routes["X"]] == [
        ("Y", "localhost:9201", 2.0), ("Y", "224.1.1.11:24468", 2.0)]
    assert [(r.dest_name, str(r.address)) for r in table.routes["Z"]] == [("Z", "localhost:9202")]
    assert [(r.dest_name, str(r.address), r.frequency) for r in table.routes["P"]] == [
        ("Q", "localhost:9203", 4.0), ("P", "224.1.1.11:24463", 0.0), ("R", "224.1.1.11:24464", 0.0)]
    assert table.registrations() == (["P", "X", "Z"], [("V*", "GPS")])
    assert table.input_summary() == "224.1.1.11:24469:multicast_9,localhost:9301"
    assert "X->Y:localhost:9201 & Y:224.1.1.11:24468:multicast_8" in table.output_summary()
    gps = MoosMessage(NOTIFY, DOUBLE, src=b"GPS", key=b"VX")
    assert [r.dest_name for r in table.routes_for(gps)] == ["shared_VX"]
    assert table.routes_for(MoosMessage(NOTIFY, DOUBLE, src=b"other", key=b"VY")) == []
    white = table.inputs[parse_route("localhost:9301", table.settings)]
    assert white.wants(b"AB") and white.wants(b"B") and not white.wants(b"C")


def test_config_caret_rename_rate_and_errors() -> None:
    table = ShareTable(ShareSettings("224.1.1.12", 9000))
    table.add_config_line("src_name=*_LOCAL,dest_name=^,route=multicast_1", True)
    routes = table.routes_for(MoosMessage(NOTIFY, DOUBLE, src=b"a", key=b"NODE_REPORT_LOCAL"))
    assert [(r.dest_name, str(r.address)) for r in routes] == [("NODE_REPORT", "224.1.1.12:9001")]
    table.add_config_line("src_name=F,route=localhost:9205,frequency=0.001", True)
    f = MoosMessage(NOTIFY, DOUBLE, src=b"a", key=b"F")
    assert len(table.routes_for(f)) == 1 and table.routes_for(f) == []  # second one inside 1/frequency
    table.add_config_line("src_name=M,route=localhost:9206,max_shares=1", True)
    m = MoosMessage(NOTIFY, DOUBLE, src=b"a", key=b"M")
    assert len(table.routes_for(m)) == 1 and table.routes_for(m) == []
    for text, is_output in [("dest_name=Y,route=localhost:1", True), ("src_name=X", True),
                            ("src_name=X,route=localhost:0", True), ("src_name=X,route=localhost:70000", True),
                            ("src_name=X,route=multicast_256", True), ("src_name=X,route=multicast_x", True),
                            ("X->a:b:c:d", True), ("X", True), ("route=nohost", False),
                            ("src_name=X,route=localhost:1,frequency=fast", True)]:
        with pytest.raises(ShareError):
            table.add_config_line(text, is_output)
    table.add_config_line("route=localhost:9301", False)
    with pytest.raises(ShareError, match="already listening"):
        table.add_config_line("route=localhost:9301", False)


# ---- processes --------------------------------------------------------------------------------------------
def udp_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
        sock.bind(("127.0.0.1", 0))
        port: int = sock.getsockname()[1]
        return port


def write_mission(path: Path, db_port: int, community: str, lines: list[str], block: str = "pShare") -> Path:
    body = "\n".join(f"  {line}" for line in lines)
    path.write_text(f"ServerHost = localhost\nServerPort = {db_port}\nCommunity = {community}\n\n"
                    f"ProcessConfig = {block}\n{{\n  AppTick = 40\n{body}\n}}\n")
    return path


@contextmanager
def share_process(workdir: Path, mission: Path, program: str | None = None) -> Iterator[ChildProcess]:
    """Our moos-share (``program=None``) or the real pShare on ``mission``."""
    args = [program, str(mission)] if program else [sys.executable, "-m", "gateway.apps.moos_share", str(mission),
                                                      "-v"]
    child = ChildProcess(args, workdir / f"{mission.stem}.log", name=program or "moos-share", cwd=workdir)
    child.start()
    try:
        yield child
    finally:
        child.stop(grace=5.0)


def wait_summary(port: int, var: str, name: str) -> None:
    """Wait for the share on the DB at ``port`` to post ``var``: its registrations were processed before it."""
    with connected_comms(port, name, [var]) as watcher:
        got = collect_mail(watcher, [var], timeout=20.0)
        assert got, f"no {var} on the DB at port {port}: the share did not connect"


def share_one_way(db_a: int, db_b: int, tag: str) -> None:
    """Post a double and a string in DB A (source ``poster_<tag>``); they must reach DB B under their new names."""
    with connected_comms(db_b, f"reader_{tag}", [f"SPEED_{tag}", f"REPORT_{tag}"]) as reader, \
            connected_comms(db_a, f"poster_{tag}") as poster:
        poster.notify(f"SPEED_{tag}_OUT", 3.25, "aux_" + tag)
        poster.notify(f"REPORT_{tag}_OUT", f"NAME={tag},X=1.5")
        got = {m.key(): m for m in collect_mail(reader, [f"SPEED_{tag}", f"REPORT_{tag}"], timeout=20.0)}
    assert set(got) == {f"SPEED_{tag}", f"REPORT_{tag}"}, f"{tag}: got only {sorted(got)}"
    speed, report = got[f"SPEED_{tag}"], got[f"REPORT_{tag}"]
    assert speed.is_double() and speed.double() == 3.25
    assert report.is_string() and report.string() == f"NAME={tag},X=1.5"
    assert speed.source() == report.source() == f"poster_{tag}"  # pShare posts keeping the source
    assert speed.source_aux() == "aux_" + tag


def outputs_for(tag: str, port: int) -> list[str]:
    return [f"Output = src_name = SPEED_{tag}_OUT, dest_name = SPEED_{tag}, route = localhost:{port}",
            f"Output = REPORT_{tag}_OUT->REPORT_{tag}:localhost:{port}"]


def test_two_dbs_share_through_two_moos_share(tmp_path: Path) -> None:
    port_a, port_b = udp_port(), udp_port()
    with moosdb_process(tmp_path, "alpha") as db_a, moosdb_process(tmp_path, "usv") as db_b:
        m_a = write_mission(tmp_path / "share_a.moos", db_a.port, "alpha",
                            [*outputs_for("AB", port_b), f"Input = route = localhost:{port_a}"])
        m_b = write_mission(tmp_path / "share_b.moos", db_b.port, "usv",
                            [*outputs_for("BA", port_a), f"Input = route = localhost:{port_b}"])
        with share_process(tmp_path, m_a) as share_a, share_process(tmp_path, m_b) as share_b:
            for port, name in ((db_a.port, "wa"), (db_b.port, "wb")):
                wait_summary(port, "PSHARE_OUTPUT_SUMMARY", name)
            share_one_way(db_a.port, db_b.port, "AB")
            share_one_way(db_b.port, db_a.port, "BA")
            with connected_comms(db_b.port, "summary", ["PSHARE_OUTPUT_SUMMARY", "PSHARE_INPUT_SUMMARY"]) as c:
                summaries = {m.key(): m.string() for m in collect_mail(c, ["PSHARE_OUTPUT_SUMMARY",
                                                                          "PSHARE_INPUT_SUMMARY"])}
            assert summaries == {"PSHARE_INPUT_SUMMARY": f"localhost:{port_b}",
                                 "PSHARE_OUTPUT_SUMMARY": f"REPORT_BA_OUT->REPORT_BA:localhost:{port_a}, "
                                                          f"SPEED_BA_OUT->SPEED_BA:localhost:{port_a}"}
        for child in (share_a, share_b):
            assert "Traceback" not in child.output()
            assert "0 malformed dropped" in child.output()


def test_malformed_datagrams_are_dropped_and_counted(tmp_path: Path) -> None:
    port = udp_port()
    with moosdb_process(tmp_path, "usv") as db:
        mission = write_mission(tmp_path / "share.moos", db.port, "usv", [f"Input = route = localhost:{port}"])
        with share_process(tmp_path, mission) as share:
            wait_summary(db.port, "PSHARE_INPUT_SUMMARY", "w")
            good = encode_message(MoosMessage(NOTIFY, DOUBLE, 5, b"injector", b"", b"x", b"INJECTED", 10.0, 7.0))
            bad = [b"garbage", good[:-3], good + b"xx", b"\0" * 200,
                   encode_message(MoosMessage(REGISTER, DOUBLE, 5, b"injector", key=b"INJECTED", msg_time=1.0))]
            with connected_comms(db.port, "reader", ["INJECTED"]) as reader, \
                    socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sender:
                for data in bad:
                    sender.sendto(data, ("127.0.0.1", port))
                sender.sendto(good, ("127.0.0.1", port))
                got = collect_mail(reader, ["INJECTED"])
            assert [(m.double(), m.source()) for m in got] == [(7.0, "injector")]
        text = share.output()
    assert "6 datagrams received, 1 posted, 5 malformed dropped" in text
    lines = [line for line in text.splitlines() if "dropping a malformed datagram" in line]
    assert 1 <= len(lines) <= 2  # rate-limited: the first at once, the rest in one summary line
    assert "Traceback" not in text


# ---- the real pShare ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("db_program", [None, "MOOSDB"], ids=["our-moos-db", "real-MOOSDB"])
def test_real_pshare_and_ours_exchange_both_ways(tmp_path: Path, db_program: str | None) -> None:
    reason = real_moos_skip_reason("pShare", *([db_program] if db_program else []))
    if reason:
        pytest.skip(reason)
    port_real, port_ours = udp_port(), udp_port()
    with moosdb_process(tmp_path, "alpha", program=db_program) as db_a, \
            moosdb_process(tmp_path, "usv", program=db_program) as db_b:
        m_real = write_mission(tmp_path / "real.moos", db_a.port, "alpha",
                               [*outputs_for("RO", port_ours), f"Input = route = localhost:{port_real}"])
        m_ours = write_mission(tmp_path / "ours.moos", db_b.port, "usv",
                               [*outputs_for("OR", port_real), f"Input = route = localhost:{port_ours}"])
        with share_process(tmp_path, m_real, "pShare") as real, share_process(tmp_path, m_ours) as ours:
            wait_summary(db_a.port, "PSHARE_OUTPUT_SUMMARY", "wa")
            wait_summary(db_b.port, "PSHARE_OUTPUT_SUMMARY", "wb")
            share_one_way(db_a.port, db_b.port, "RO")  # real pShare -> ours
            share_one_way(db_b.port, db_a.port, "OR")  # ours -> real pShare
            names = ["PSHARE_OUTPUT_SUMMARY", "PSHARE_INPUT_SUMMARY"]
            summaries = []
            for port in (db_a.port, db_b.port):
                with connected_comms(port, "summary", names) as c:
                    summaries.append(sorted((m.key(), m.string()) for m in collect_mail(c, names)))
            real_summary, our_summary = summaries

            def neutral(text: str) -> str:  # the same format, ports and tags aside
                text = re.sub(r"(SPEED|REPORT)_(RO|OR)", r"\1_X", text)
                return text.replace(str(port_real), "P").replace(str(port_ours), "P")

            assert [(k, neutral(v)) for k, v in real_summary] == [(k, neutral(v)) for k, v in our_summary]
        assert "0 malformed dropped" in ours.output(), ours.output()[-2000:]
        assert real.returncode is not None
