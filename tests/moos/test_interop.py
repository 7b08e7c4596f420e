"""Interoperability with the real MOOS: pymoos, uPokeDB and uXMS against our DB and the real MOOSDB.

Skipped (with the reason) when the real programs are absent. Run by hand inside a private network namespace:
``/opt/moos/bin/netns-run env PATH=/opt/moos/bin:$PATH PYTHONPATH=/opt/moos/pysite .venv/bin/python -m pytest tests/moos``
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest

from gateway.moos import choose_client
from gateway.moos.errors import MoosError
from gateway.moos.factory import pymoos_available
from gateway.moos.testing import collect_mail, connected_comms
from util.process import ChildProcess

pytestmark = pytest.mark.interop
SCRIPT = Path(__file__).with_name("pymoos_script.py")
REPO = Path(__file__).resolve().parents[2]


def _module_or_skip(module: str) -> str:
    if module == "pymoos" and not pymoos_available():
        pytest.skip("the real pymoos is not importable (PYTHONPATH=/opt/moos/pysite)")
    return module


@pytest.mark.parametrize("module", ["gateway.moos", "pymoos"])
def test_the_same_pymoos_script_runs_with_either_import(module: str, db_port: int, tmp_path: Path) -> None:
    _module_or_skip(module)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, [str(REPO), os.environ.get("PYTHONPATH")])))
    run = subprocess.run([sys.executable, str(SCRIPT), module, str(db_port), "py" + module.replace(".", "_")],
                         capture_output=True, text=True, timeout=60, env=env, cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    results = json.loads(run.stdout.strip().splitlines()[-1])
    assert results["connected"] is True
    assert results["community"] == "moos"
    assert results["time_ok"] is True
    assert "PY_DOUBLE" in results["registered"]
    talker = "py" + module.replace(".", "_") + "_talker"
    mail = [tuple(m) for m in results["mail"]]
    assert ("PY_DOUBLE", talker, 1.25, "moos") in mail
    assert ("PY_DOUBLE", talker, 2.5, "moos") in mail
    assert ("PY_STRING", talker, "hello pymoos", "moos") in mail
    assert ("PY_BINARY", talker, [0, 1, 2, 255], "moos") in mail
    assert ("PYW_ANY", talker, 9.0, "moos") in mail
    if module == "gateway.moos":
        # Routed mail leaves the inbox. libMOOS means to do the same but stops routing a packet at its first
        # message that has no queue (DispatchInBoxToActiveThreads returns early), so pymoos may show it too.
        assert [m[0] for m in mail].count("PY_Q") == 0
        assert results["queued"] == [0.0, 1.0, 2.0]
    else:
        assert sorted(results["queued"] + [m[2] for m in mail if m[0] == "PY_Q"]) == [0.0, 1.0, 2.0]


def test_choose_client_kinds(monkeypatch: pytest.MonkeyPatch) -> None:
    from gateway.moos import comms

    ours = choose_client("ours")
    assert isinstance(ours.comms, comms) and ours.kind == "ours"
    monkeypatch.setenv("GOBY_MOOS_CLIENT", "ours")
    assert isinstance(choose_client().comms, comms)
    with pytest.raises(MoosError, match="unknown MOOS client kind"):
        choose_client("bogus")
    if pymoos_available():
        import pymoos

        for kind in ("pymoos", "auto"):
            real = choose_client(kind)
            assert isinstance(real.comms, pymoos.comms) and real.kind == "pymoos" and real.moos_time is pymoos.time
    else:
        assert isinstance(choose_client("auto").comms, comms)
        with pytest.raises(MoosError, match="cannot be imported"):
            choose_client("pymoos")


def _tool_or_skip(name: str) -> str:
    path = shutil.which(name)
    if path is None:
        pytest.skip(f"the real {name} is not on PATH")
    return path


def test_upokedb_pokes_our_db(db_port: int) -> None:
    upoke = _tool_or_skip("uPokeDB")
    with connected_comms(db_port, "watcher", ["POKED_D", "POKED_S"]) as watcher:
        run = subprocess.run([upoke, "POKED_D=3.5", "POKED_S=hello", "--host=127.0.0.1", f"--port={db_port}"],
                             capture_output=True, text=True, timeout=30)
        assert run.returncode == 0, run.stdout + run.stderr
        got = {m.key(): m for m in collect_mail(watcher, ["POKED_D", "POKED_S"])}
        assert got["POKED_D"].double() == 3.5 and got["POKED_S"].string() == "hello"
        assert got["POKED_D"].source() == "uPokeDB"
        assert abs(got["POKED_D"].time() - time.time()) < 5


def test_uxms_scopes_our_db(db_port: int, tmp_path: Path) -> None:
    uxms = _tool_or_skip("uXMS")
    with connected_comms(db_port, "poster") as poster:
        poster.notify("SCOPED_VAR", "visible-value")
        with ChildProcess([uxms, "SCOPED_VAR", "--serverhost=127.0.0.1", f"--serverport={db_port}",
                           "--mode=streaming", "--show=source"], tmp_path / "uxms.out") as proc:
            deadline = time.monotonic() + 15
            while time.monotonic() < deadline and "visible-value" not in proc.output():
                poster.notify("KEEP_BUSY", 1.0)  # the C++ DB pushes held mail after notifications
                time.sleep(0.1)
            text = proc.output()
        assert "visible-value" in text and "poster" in text


def test_a_real_moos_app_runs_against_our_db(tmp_path: Path) -> None:
    """uTimerScript (a C++ CMOOSApp: async comms, mission file, app tick) publishes through our DB."""
    _tool_or_skip("uTimerScript")
    from gateway.moos.testing import running_moosdb

    with running_moosdb(community="tsx") as db, connected_comms(db.port, "watch_ts", ["TS_HELLO", "TS_NUM"]) as w:
        mission = tmp_path / "ts.moos"
        mission.write_text(
            f"ServerHost = localhost\nServerPort = {db.port}\nCommunity = tsx\n\n"
            "ProcessConfig = uTimerScript\n{\n  AppTick = 4\n  CommsTick = 4\n"
            '  event = var=TS_HELLO, val="world", time=0.2\n  event = var=TS_NUM, val=42, time=0.4\n}\n'
        )
        # argv[0] must be the bare name: a MOOSApp looks up "ProcessConfig = <argv[0]>"
        with ChildProcess(["uTimerScript", str(mission)], tmp_path / "uTimerScript.log", cwd=tmp_path):
            got = {m.key(): m for m in collect_mail(w, ["TS_HELLO", "TS_NUM"], timeout=20)}
        assert got["TS_HELLO"].string() == "world" and got["TS_HELLO"].source() == "uTimerScript"
        assert got["TS_NUM"].is_double() and got["TS_NUM"].double() == 42.0
        assert got["TS_NUM"].community() == "tsx"
