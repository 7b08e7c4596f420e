"""bench/bench_trail_auv.py's machinery, not its timings: auv.launch's program variables (defaults ours, every C++
program when set), the configs the real programs need, the /proc readers, the table, one short run of the mission
with auv0 alone, and, when Goby3 and MOOS-IvP are there, a short run of auv0 (ours) beside auv1 (C++)."""

from __future__ import annotations

import os
import re
import subprocess
import sys
import time
from pathlib import Path

import pytest

from bench.bench_trail_auv import (
    CPP,
    LAUNCHER,
    PYTHON,
    ROLES,
    ZERO,
    Figures,
    SideResult,
    cpp_environment,
    find_programs,
    measure_run,
    missing_roles,
    mission_entries,
    table,
    wrong_programs,
)
from bench.platform_proc import machine_ticks, program_name, wakeups
from launch.launchfile import expand_vars, parse_file
from launch.process_group import child_environment
from launch.trail.config import generate
from launch.trail.settings import TRAIL_DIR, TrailSettings, Vehicle
from util.process import wait_until

REPO = Path(__file__).resolve().parents[1]
FAKE = {**{p: f"/opt/goby/bin/{p}" for p in ("gobyd", "goby_logger", "goby_basic_frontseat_simulator",
                                               "goby_frontseat_interface")},
        **{p: f"/opt/moos/bin/{p}" for p in ("MOOSDB", "pHelmIvP", "pNodeReporter", "pShare", "pLogger")}}


def _programs(env: dict[str, str]) -> list[str]:
    """The program each auv.launch line runs with ``env``."""
    return [os.path.basename(expand_vars(e.binary, e.environment(env))) for e in parse_file(TRAIL_DIR / "auv.launch").entries]


def test_auv_launch_runs_ours_by_default_and_each_cpp_program_when_its_variable_is_set() -> None:
    env = child_environment() | TrailSettings().to_env()
    ours = _programs(env)
    assert [r.python for r in ROLES if r.cpp] == [p for p in ours if p in {r.python for r in ROLES if r.cpp}]
    cpp = _programs(env | cpp_environment(FAKE))
    assert sorted(p for p in cpp if p not in ours) == sorted(r.cpp for r in ROLES if r.cpp)
    # the lines without a C++ original here run ours on both
    assert {"goby-liaison", "auv-manager", "moos-gateway"} <= set(cpp)


def test_cpp_environment_names_programs_and_puts_their_directories_after_this_interpreter() -> None:
    env = cpp_environment(FAKE)
    assert env["TRAIL_MOOSDB"] == "MOOSDB" and env["TRAIL_HELM"] == "pHelmIvP"  # names: MOOS apps read argv[0]
    assert env["TRAIL_FRONTSEAT_TUNING"] == "" and env["TRAIL_LINK_ADDRESS"] == "0.0.0.0"
    assert env["TRAIL_FRONTSEAT_DRIVER"].startswith("libgoby_frontseat_basic_simulator.so")
    path = env["PATH"].split(os.pathsep)
    assert path[0] == os.path.dirname(sys.executable) and path[-1] == "${PATH}"
    assert {"/opt/goby/bin", "/opt/moos/bin"} <= set(path)


def test_mission_entries_add_the_variables_to_one_platforms_line_only() -> None:
    entries = {e.name: e for e in mission_entries(3, {"auv1": {"TRAIL_HELM": "pHelmIvP"}})}
    assert ("TRAIL_HELM", "pHelmIvP") in entries["auv1"].env
    assert all(("TRAIL_HELM", "pHelmIvP") not in entries[n].env for n in ("topside", "usv", "auv0", "auv2"))


def test_the_interface_line_drops_our_tuning_when_told(tmp_path: Path) -> None:
    """The line as bash runs it, with printf standing in for the program: one argument per line."""
    line = next(e for e in parse_file(TRAIL_DIR / "auv.launch").entries if "frontseat_interface" in e.command)
    env = child_environment() | TrailSettings(run_dir=tmp_path).to_env() | {
        "goby3_course_n_auvs": "2", "goby3_course_auv_index": "1", "TRAIL_FRONTSEAT_INTERFACE": r"printf %s\n"}

    def args(extra: dict[str, str]) -> list[str]:
        done = subprocess.run(["bash", "-c", line.command], env=env | extra, cwd=REPO, capture_output=True,
                              text=True, check=True, timeout=60)
        return done.stdout.splitlines()

    assert "--frontseat_cfg" in args({})
    assert "--frontseat_cfg" not in args({"TRAIL_FRONTSEAT_TUNING": ""})


def test_goby_logger_gets_no_python_modules_and_moosdb_no_flags_for_the_real_programs(tmp_path: Path) -> None:
    auv = Vehicle("auv", 2, 1)
    ours = TrailSettings(run_dir=tmp_path)
    real = ours.replace(goby_logger="goby_logger", moosdb="MOOSDB")
    assert re.search(r"^load_shared_library", generate("auv", "goby_logger", ours, auv), re.M)
    assert not re.search(r"^load_shared_library", generate("auv", "goby_logger", real, auv), re.M)
    assert generate("auv", "moosdb_flags", ours, auv).startswith("--moos_address=")
    assert generate("auv", "moosdb_flags", real.replace(moosdb="/opt/moos/bin/MOOSDB"), auv) == ""


def test_program_names_and_wakeups_from_proc() -> None:
    child = subprocess.Popen([sys.executable, "-m", "code"], stdin=subprocess.PIPE, stdout=subprocess.DEVNULL,
                             stderr=subprocess.DEVNULL)
    sh = subprocess.Popen(["sh", "-c", "read x"], stdin=subprocess.PIPE)
    try:
        # until the child has exec'd, /proc shows the parent's command line
        wait_until(lambda: program_name(child.pid) == "code", what="python -m code's program name")
        wait_until(lambda: program_name(sh.pid) == "sh", what="sh's program name")
        before = wakeups(os.getpid())
        for _ in range(5):
            time.sleep(0.01)
        assert wakeups(os.getpid()) >= before + 5
    finally:
        child.communicate(b"")
        sh.communicate(b"\n")
    assert program_name(sh.pid) == "?" and wakeups(sh.pid) == 0
    busy, total = machine_ticks()
    assert 0 < busy <= total


def _side(cpu_ms: float, wake: float, mib: int, programs: dict[str, set[str]] | None = None) -> SideResult:
    roles = {r.python: Figures(cpu_ms / 1000, wake, mib * 2**20) for r in ROLES} | {LAUNCHER: ZERO}
    return SideResult(roles, programs or {}, 1.0, 1.0)


def test_the_table_gives_both_auvs_totals_and_ratios_and_the_launcher_apart() -> None:
    runs = [{PYTHON: _side(2.0, 20, 10), CPP: _side(1.0, 40, 2)}, {PYTHON: _side(4.0, 20, 10), CPP: _side(1.0, 40, 2)}]
    lines = table(runs).splitlines()
    broker = next(line for line in lines if line.startswith("| goby-broker / gobyd"))
    cells = [c.strip() for c in broker.strip("|").split("|")]
    assert cells[1:4] == ["3.00 (2.00-4.00)", "1.00 (1.00-1.00)", "3.00 (2.00-4.00)"]
    assert cells[4:7] == ["20 (20-20)", "40 (40-40)", "0.50 (0.50-0.50)"]
    total = next(line for line in lines if line.startswith("| **total**"))
    assert f"{3.0 * len(ROLES):.2f}" in total  # every AUV process, the launcher (zero here) left out
    assert any(line.startswith("| goby-liaison (ours on both)") for line in lines)
    assert "C++" not in table([{PYTHON: _side(2.0, 20, 10)}])


def test_missing_and_wrong_programs_are_named() -> None:
    result = _side(1.0, 1, 1, {"goby-broker": {"gobyd"}, "launch.trail.moos_gen": {"sh"}})
    assert missing_roles(result) == []
    assert wrong_programs(CPP, result) == []
    assert wrong_programs(PYTHON, result) == ["goby-broker ran gobyd, not goby-broker"]
    partial = SideResult({"goby-broker": ZERO, "bash": ZERO}, {}, 1.0, 1.0)
    assert "moos-db" in missing_roles(partial) and LAUNCHER in missing_roles(partial)
    assert "a process of no role: bash" in wrong_programs(PYTHON, partial)


def test_missing_cpp_programs_name_the_program(tmp_path: Path) -> None:
    programs, why = find_programs({"PATH": str(tmp_path), "GOBY_BIN_DIR": str(tmp_path)})
    assert programs == {} and why is not None and "gobyd" in why


def _check_measured(result: SideResult, side: str) -> None:
    assert result.runs, result
    assert missing_roles(result) == [], result.roles.keys()
    assert wrong_programs(side, result) == []
    assert result.total().cpu_per_sim_s > 0 and result.total().private_bytes > 0
    busy = [r.python for r in ROLES if r.python != "launch.trail.moos_gen"]  # it sleeps in a shell
    assert all(result.roles[role].cpu_per_sim_s > 0 for role in busy), result.roles


def test_a_short_run_of_one_auv_measures_each_of_its_processes() -> None:
    result = measure_run(warp=10, seconds=3.0, settle=1.0, n_auvs=1, cpp_env=None, keep=False)
    assert set(result) == {PYTHON}
    _check_measured(result[PYTHON], PYTHON)


def test_a_short_run_of_our_auv_beside_the_cpp_one() -> None:
    """The benchmark itself (it re-executes in a private network namespace): both AUVs under command, every
    process of each measured and of the expected program (its exit status), both keeping up."""
    _, why = find_programs()
    if why is not None:
        pytest.skip(why)
    done = subprocess.run([sys.executable, "-m", "bench.bench_trail_auv", "--seconds", "3", "--settle", "1"],
                          cwd=REPO, capture_output=True, text=True, timeout=900)
    if "C++ AUV skipped" in done.stderr:
        pytest.skip(next(line for line in done.stderr.splitlines() if "C++ AUV skipped" in line))
    assert done.returncode == 0, done.stderr[-3000:]
    rows = {line.split("|")[1].strip(): line for line in done.stdout.splitlines() if line.startswith("| ")}
    for role in ROLES:
        label = f"{role.python} / {role.cpp}" if role.cpp else f"{role.python} (ours on both)"
        assert label in rows, done.stdout
    assert re.search(r"\| auv0 \(ours\) +\| yes", done.stdout) and re.search(r"\| auv1 \(C\+\+\) +\| yes", done.stdout)
