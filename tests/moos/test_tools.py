"""The console scripts: moos-db (flags and mission file), moos-poke and moos-scope."""

from __future__ import annotations

import subprocess
import sys
import time
from pathlib import Path

import pytest

from gateway.apps import moos_poke as poke
from gateway.apps import moos_scope as scope
from gateway.apps.moos_tool_args import adopt_db_time_warp
from gateway.moos.testing import MoosDBProcess, collect_mail, connected_comms, running_moosdb
from util.process import ChildProcess, free_port

BIN = Path(sys.executable).parent


def test_moos_db_reads_the_mission_file_and_flags_win(tmp_path: Path) -> None:
    port = free_port()
    mission = tmp_path / "m.moos"
    mission.write_text(f"ServerPort = {port}\nCommunity = fromfile\nMOOSTimeWarp = 4\n")
    db = MoosDBProcess(tmp_path, community="fromflag", warp=4.0, port=0)
    db.extra_args = [str(mission)]
    # the flags MoosDBProcess passes (--moos_port=0, --moos_community) override the file
    with db:
        assert db.port != port
        with connected_comms(db.port, "probe") as probe:
            assert probe.get_community_name() == "fromflag"


def test_moos_db_console_script_uses_the_mission_file(tmp_path: Path) -> None:
    port = free_port()
    mission = tmp_path / "m.moos"
    mission.write_text(f"ServerPort = {port}\nCommunity = fromfile\n")
    with ChildProcess([str(BIN / "moos-db"), str(mission)], tmp_path / "moos-db.out", cwd=tmp_path,
                      stderr_path=tmp_path / "moos-db.log") as proc:
        ready = proc.wait_ready(r"^MOOSDB .*$", timeout=30)
        assert ready is not None and ready.group(0) == f"MOOSDB fromfile listening on 127.0.0.1:{port}"
        with connected_comms(port, "probe") as probe:
            assert probe.get_community_name() == "fromfile"
    assert proc.returncode == 0


@pytest.mark.parametrize("text, where", [
    (None, "No such file"),
    ("ServerPort = 9x\n", "m.moos:1: ServerPort = '9x' is not a number"),
    ("// warp\n\nMOOSTimeWarp = -2\n", "m.moos:3: MOOSTimeWarp = '-2'"),
    ("ServerPort = 0\nProcessConfig = a\n{\n  x = 1\n", "m.moos:2: block 'ProcessConfig = a' has no closing"),
])
def test_moos_db_exits_2_on_a_bad_mission_file_naming_file_and_line(tmp_path: Path, text: str | None,
                                                                     where: str) -> None:
    mission = tmp_path / "m.moos"
    if text is not None:
        mission.write_text(text)
    run = subprocess.run([str(BIN / "moos-db"), str(mission)], capture_output=True, text=True, timeout=30,
                         cwd=tmp_path)
    assert run.returncode == 2
    assert where in run.stderr and "listening" not in run.stdout


def test_moos_db_refuses_a_taken_port(tmp_path: Path) -> None:
    with running_moosdb() as db:
        run = subprocess.run([str(BIN / "moos-db"), f"--moos_port={db.port}"], capture_output=True, text=True,
                             timeout=30, cwd=tmp_path)
        assert run.returncode == 1
        assert "cannot start the MOOSDB" in run.stderr


def test_moos_db_accepts_the_cpp_options_it_ignores(tmp_path: Path) -> None:
    run = subprocess.run([str(BIN / "moos-db"), "--moos_print_version", "-s", "--response=x:20", "--tcpnodelay"],
                         capture_output=True, text=True, timeout=30, cwd=tmp_path)
    assert run.returncode == 0 and "MOOS v10" in run.stdout


def test_poke_sends_doubles_and_strings_and_confirms(capsys: pytest.CaptureFixture[str]) -> None:
    with running_moosdb() as db, connected_comms(db.port, "watch", ["P_D", "P_S", "P_F"]) as watch:
        assert poke.main(["P_D=3.5", "P_S=hello world", "P_F:=12", f"--port={db.port}", "--host=127.0.0.1"]) == 0
        got = {m.key(): m for m in collect_mail(watch, ["P_D", "P_S", "P_F"])}
        assert got["P_D"].is_double() and got["P_D"].double() == 3.5
        assert got["P_S"].string() == "hello world" and got["P_F"].string() == "12"
        assert got["P_D"].source() == "uPokeDB"
        out = capsys.readouterr().out
        assert out.count(" ok") == 3
        # a write the DB refuses (type lock) is reported and fails the exit code
        assert poke.main(["P_D=not a number", f"--port={db.port}"]) == 1
        assert "NOT CONFIRMED" in capsys.readouterr().out


def test_poke_reports_an_unreachable_db(capsys: pytest.CaptureFixture[str]) -> None:
    assert poke.main(["X=1", f"--port={free_port()}", "--connect_timeout=0.5"]) == 1
    assert "cannot connect" in capsys.readouterr().err


def test_poke_parses_assignments() -> None:
    assert poke.parse_assignment("A=1e3") == ("A", 1000.0)
    assert poke.parse_assignment("A=nan") == ("A", "nan")
    assert poke.parse_assignment("A:=1") == ("A", "1")
    assert poke.parse_assignment("A=b=c") == ("A", "b=c")
    with pytest.raises(ValueError):
        poke.parse_assignment("novalue")


def test_scope_once_prints_the_table(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    with running_moosdb() as db, connected_comms(db.port, "pNav") as nav:
        nav.notify("NAV_X", 12.5)
        nav.notify("NAV_NAME", "alpha")
        mission = tmp_path / "s.moos"
        mission.write_text(f"ServerHost = 127.0.0.1\nServerPort = {db.port}\n")
        assert scope.main([str(mission), "NAV_X", "NAV_NAME", "--once"]) == 0
        out = capsys.readouterr().out
        rows = {line.split()[0]: line for line in out.splitlines()[2:]}
        assert "pNav" in rows["NAV_X"] and rows["NAV_X"].rstrip().endswith("12.5")
        assert rows["NAV_NAME"].rstrip().endswith('"alpha"') and "moos" in rows["NAV_NAME"]
        assert scope.main(["NAV_X", "NEVER_WRITTEN", "--once", "--timeout=0.5", f"--port={db.port}"]) == 2
        assert "n/a" in capsys.readouterr().out


def test_scope_all_for_a_duration(capsys: pytest.CaptureFixture[str]) -> None:
    with running_moosdb() as db, connected_comms(db.port, "pub") as pub:
        pub.notify("ANY_ONE", 1.0)
        assert scope.main(["--all", "--duration=0.6", "--refresh=0.2", f"--port={db.port}"]) == 0
        assert "ANY_ONE" in capsys.readouterr().out


def test_console_scripts_run(tmp_path: Path) -> None:
    with running_moosdb() as db:
        run = subprocess.run([str(BIN / "moos-poke"), "CS_X=2", f"--port={db.port}"], capture_output=True,
                             text=True, timeout=30)
        assert run.returncode == 0, run.stderr
        run = subprocess.run([str(BIN / "moos-scope"), "CS_X", "--once", f"--port={db.port}"], capture_output=True,
                             text=True, timeout=30)
        assert run.returncode == 0 and "uPokeDB" in run.stdout


def test_moos_db_timeout_flag_drops_silent_clients(tmp_path: Path) -> None:
    import socket

    from gateway.moos.codec import PROTOCOL_BYTES, encode_packet
    from gateway.moos.message import DATA, STRING, MoosMessage

    with MoosDBProcess(tmp_path, extra_args=["--moos_timeout=1"]) as db:
        with socket.create_connection(("127.0.0.1", db.port), timeout=10) as sock:
            hello = MoosMessage(DATA, STRING, key=b"asynchronous", msg_time=1.0, sval=b"mute")
            sock.sendall(PROTOCOL_BYTES + encode_packet([hello]))
            start = time.monotonic()
            while sock.recv(4096):  # the WELCOME, then nothing until the DB hangs up
                pass
            assert 0.5 < time.monotonic() - start < 8
        assert "seconds of silence" in db.log_path.read_text()


def _scope_rows(out: str) -> dict[str, str]:
    return {line.split()[0]: line for line in out.splitlines()[2:] if line.strip()}


def test_scope_times_follow_the_db_time_warp(capsys: pytest.CaptureFixture[str]) -> None:
    # the DB at warp 10 and no --moos_time_warp: scope (like poke) must run its clock at the DB's warp,
    # otherwise its start time is unix time and a message's time shows as ~1.6e10 s
    with running_moosdb(warp=10.0) as db, connected_comms(db.port, "watch", ["W_X"]) as watch:
        assert poke.main(["W_X=1", f"--port={db.port}"]) == 0
        sent = collect_mail(watch, ["W_X"])[0]
        assert abs(sent.time() - 10 * time.time()) < 60  # poke stamps in the DB's (warped) time
        capsys.readouterr()
        assert scope.main(["W_X", "--once", f"--port={db.port}"]) == 0
        stamp = float(_scope_rows(capsys.readouterr().out)["W_X"].split()[2])
        assert -60.0 < stamp <= 0.5  # written a moment (x10) before the scope started
        # an explicit warp still wins over the DB's
        assert scope.main(["W_X", "--once", f"--port={db.port}", "--moos_time_warp=1"]) == 0
        stamp = float(_scope_rows(capsys.readouterr().out)["W_X"].split()[2])
        assert stamp > 1e9


def test_adopt_db_time_warp_rebases_a_skew() -> None:
    from gateway.moos.client import comms
    from gateway.moos.clock import MoosClock

    with running_moosdb(warp=4.0) as db:
        clock = MoosClock(1.0)
        client = comms(clock=clock)
        client.set_quiet(True)  # quiet: the client takes the DB's skew even on the same host
        client.run("127.0.0.1", db.port, "warp-probe")
        try:
            assert client.wait_until_connected(10_000)
            assert abs(clock.skew) > 1e9  # measured at warp 1 against a warp-4 DB
            assert adopt_db_time_warp(client, clock) == 4.0 and clock.warp == 4.0
            assert abs(clock.time() - 4 * time.time()) < 5
        finally:
            client.close(True)


def test_options_may_come_between_the_positionals(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    with running_moosdb() as db:
        mission = tmp_path / "m.moos"
        mission.write_text(f"ServerHost = 127.0.0.1\nServerPort = {db.port}\n")
        assert poke.main([str(mission), "--name=pokerA", "IM_A=1", "--confirm_timeout=5", "IM_B:=two"]) == 0
        assert capsys.readouterr().out.count(" ok") == 2
        assert scope.main([str(mission), "--once", "IM_A", "--timeout=5", "IM_B"]) == 0
        rows = _scope_rows(capsys.readouterr().out)
        assert "pokerA" in rows["IM_A"] and rows["IM_B"].rstrip().endswith('"two"')


def test_scope_columns_fit_long_names_and_sources(capsys: pytest.CaptureFixture[str]) -> None:
    long_source = "goby::moos::Translator::10335"
    long_name = "A_RATHER_LONG_VARIABLE_NAME_INDEED"
    with running_moosdb() as db, connected_comms(db.port, long_source) as pub:
        pub.notify(long_name, "x")
        pub.notify("S", 1.0)
        assert scope.main([long_name, "S", "--once", f"--port={db.port}"]) == 0
        lines = capsys.readouterr().out.splitlines()
        header, rows = lines[0], _scope_rows("\n".join(lines))
        assert set(rows) == {long_name, "S"}
        for row in rows.values():
            fields = row.split()
            assert fields[1] == long_source  # nothing ran into its neighbour
            assert row.index(long_source) == header.index("(S)ource")
            assert row.index(" moos ") + 1 == header.index("(C)ommunity")
            time_end = row.index(fields[2]) + len(fields[2])
            assert time_end == header.index("(T)ime") + len("(T)ime")  # right-aligned under its heading
        assert rows[long_name].rstrip().endswith('"x"') and rows["S"].rstrip().endswith(" 1")
        assert rows[long_name].index('"x"') == rows["S"].index("1", header.index("VarValue")) == \
            header.index("VarValue")


def test_console_scripts_against_a_warped_db_process(tmp_path: Path) -> None:
    # the reviewer's repro: moos-db at warp 10, moos-poke, then moos-scope with a mission file and --once between
    with MoosDBProcess(tmp_path, warp=10.0) as db:
        mission = tmp_path / "mission.moos"
        mission.write_text(f"ServerHost = 127.0.0.1\nServerPort = {db.port}\n")
        run = subprocess.run([str(BIN / "moos-poke"), "--port", str(db.port), "FOO=1"], capture_output=True,
                             text=True, timeout=30)
        assert run.returncode == 0, run.stderr
        run = subprocess.run([str(BIN / "moos-scope"), str(mission), "--once", "FOO"], capture_output=True,
                             text=True, timeout=30)
        assert run.returncode == 0, run.stderr
        stamp = float(_scope_rows(run.stdout)["FOO"].split()[2])
        assert -60.0 < stamp <= 0.5
