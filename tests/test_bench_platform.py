"""bench/bench_platform.py's machinery, not its timings: which launch lines make each vehicle, the C++ lines on the
same generated configs, the /proc readers, the importtime parser, and one short run of the Python vehicle (and of
the C++ one when Goby3 and MOOS-IvP are there, inside a private network namespace)."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from google.protobuf import text_format

from bench.bench_platform import RoleFigures, SideResult, main, measure_run, table
from bench.platform_imports import describe, parse_importtime, self_time_by_package, total_us
from bench.platform_proc import ProcSample, cpu_between, parse_smaps_rollup, parse_stat, sample, sample_tree
from bench.platform_vehicle import (
    CPP,
    PYTHON,
    ROLES,
    cpp_entry,
    find_cpp_programs,
    vehicle_entries,
    vehicle_settings,
)
from gateway.goby.portal.protobuf.gobyd_config_pb2 import GobyDaemonConfig
from gateway.moos.testing import private_netns
from launch.process_group import ProcessGroup, child_environment
from launch.usv.mission import LAUNCH_FILE

FAKE_PROGRAMS = {
    "gobyd": "/opt/goby/bin/gobyd",
    "goby_basic_frontseat_simulator": "/opt/goby/bin/goby_basic_frontseat_simulator",
    "goby_frontseat_interface": "/opt/goby/bin/goby_frontseat_interface",
    "MOOSDB": "/opt/moos/bin/MOOSDB",
    "pHelmIvP": "/opt/moos/bin/pHelmIvP",
}


def test_the_python_vehicle_is_the_launch_files_five_lines_in_launch_order(tmp_path: Path) -> None:
    env = child_environment() | vehicle_settings(tmp_path / "run", 10, PYTHON).to_env()
    selected = vehicle_entries(LAUNCH_FILE, env)
    assert [role.key for role, _ in selected] == ["simulator", "broker", "moosdb", "helm", "interface"]
    commands = {role.key: entry.command for role, entry in selected}
    assert commands["broker"].startswith("goby-broker <(python -m launch.usv.config broker)")
    assert "--frontseat_cfg" in commands["interface"]
    assert dict(selected[-1][1].env)["FRONTSEAT_DRIVER_LIBRARY"] == "basic_simulator"


def test_the_cpp_vehicle_runs_goby_and_moos_programs_on_the_same_configs(tmp_path: Path) -> None:
    env = child_environment() | vehicle_settings(tmp_path / "run", 10, CPP).to_env()
    lines = {role.key: cpp_entry(role, entry, FAKE_PROGRAMS) for role, entry in vehicle_entries(LAUNCH_FILE, env)}
    assert lines["broker"].command == "/opt/goby/bin/gobyd <(python -m launch.usv.config broker)"
    assert lines["simulator"].command.startswith("/opt/goby/bin/goby_basic_frontseat_simulator $(")
    # our driver's tuning is an extension Goby's driver would refuse; Goby's own driver library is named
    assert lines["interface"].command == "/opt/goby/bin/goby_frontseat_interface <(python -m launch.usv.config " \
                                         "frontseat_interface)"
    assert dict(lines["interface"].env)["FRONTSEAT_DRIVER_LIBRARY"].startswith("libgoby_frontseat_basic_simulator.so")
    # MOOSDB and pHelmIvP come from the launch file's own USV_MOOSDB / USV_HELM choice
    assert lines["moosdb"].command.startswith("${USV_MOOSDB:-moos-db} ")
    assert env["USV_MOOSDB"] == "MOOSDB" and env["USV_HELM"] == "pHelmIvP"


def test_the_cpp_broker_line_feeds_gobyd_the_generated_config(tmp_path: Path) -> None:
    """The rewritten line, run by the launcher with `cat` standing in for gobyd, prints the USV broker's config."""
    settings = vehicle_settings(tmp_path / "run", 7, CPP)
    env = child_environment() | settings.to_env()
    role, entry = next((r, e) for r, e in vehicle_entries(LAUNCH_FILE, env) if r.key == "broker")
    line = cpp_entry(role, entry, FAKE_PROGRAMS | {"gobyd": "cat"})
    settings.run_dir.mkdir(parents=True)
    group = ProcessGroup([line], tmp_path / "logs", base_env=env, cwd=settings.run_dir, report=lambda _: None,
                         startup_check_s=0.0)
    group.start()
    try:
        assert group.processes[0].child.wait(30) == 0
    finally:
        group.stop()
    cfg = text_format.Parse(group.processes[0].log_path.read_text(), GobyDaemonConfig())
    assert cfg.app.simulation.time.warp_factor == 7
    assert cfg.interprocess.socket_name == settings.ipc_base


def test_missing_cpp_programs_name_the_program_and_the_variable(tmp_path: Path) -> None:
    programs, why = find_cpp_programs({"PATH": str(tmp_path), "GOBY_BIN_DIR": str(tmp_path)})
    assert programs == {}
    assert why is not None and "gobyd" in why and "GOBY_BIN_DIR" in why


def test_stat_and_smaps_rollup_parsing() -> None:
    ppid, cpu, start = parse_stat("42 (a (weird) name) S 7 42 42 0 -1 4194560 1 0 0 0 250 50 0 0 20 0 3 0 "
                                  "12345 0 0")
    assert (ppid, start) == (7, 12345)
    assert cpu == pytest.approx(300 / os.sysconf("SC_CLK_TCK"))
    rollup = textwrap.dedent("""\
        55d0c4b1a000-7ffd5a1f4000 ---p 00000000 00:00 0                          [rollup]
        Rss:               18392 kB
        Pss:               12034 kB
        Private_Clean:       512 kB
        Private_Dirty:     10936 kB
        Swap:                  0 kB
        """)
    assert parse_smaps_rollup(rollup) == ((512 + 10936) * 1024, 18392 * 1024)


def test_cpu_between_counts_a_busy_child_and_memory_is_read() -> None:
    code = "import time, sys\nend = time.process_time() + 0.3\nwhile time.process_time() < end: pass\n" \
           "print(flush=True)\nsys.stdin.read()"
    child = subprocess.Popen([sys.executable, "-c", code], stdin=subprocess.PIPE, stdout=subprocess.PIPE)
    try:
        me = sample_tree(os.getpid())
        before = [s for s in me if s.pid == child.pid]
        assert child.stdout is not None
        child.stdout.readline()
        after = sample(child.pid)
        assert after is not None
        assert after.private_bytes > 0 and after.rss_bytes >= after.private_bytes
        assert cpu_between(before, [after]) >= 0.25  # at least its busy loop, in ns from schedstat
        # a thread that ended in between: the ticks from stat are used instead
        gone = ProcSample(after.pid, after.cpu_s - 0.2, 0, 0, after.start_ticks, {**after.thread_ns, 1: 5})
        assert cpu_between([gone], [after]) == pytest.approx(0.2)
    finally:
        child.communicate()


def test_importtime_records_link_each_module_to_its_importer() -> None:
    lines = [
        "import time: self [us] | cumulative | imported package",
        "import time:        50 |         50 |     google.protobuf.internal",
        "import time:       100 |        150 |   google.protobuf",
        "import time:       200 |        350 | frontseat.interface",
        "a log line of the program",
        "import time:        30 |         30 |   email.message",
        "import time:        70 |        100 | importlib.metadata",
    ]
    records = {r.name: r for r in parse_importtime(lines)}
    assert records["google.protobuf.internal"].chain() == ["frontseat.interface", "google.protobuf",
                                                           "google.protobuf.internal"]
    assert records["importlib.metadata"].parent is None and records["email.message"].parent is records[
        "importlib.metadata"]
    assert total_us(records.values()) == 450
    assert self_time_by_package(records.values())["google"] == 150
    assert describe(records["google.protobuf"]).endswith("<- frontseat.interface")


def test_importtime_of_a_real_interpreter_is_parsed() -> None:
    out = subprocess.run([sys.executable, "-X", "importtime", "-c", "import json"], capture_output=True, text=True,
                         check=True)
    records = {r.name: r for r in parse_importtime(out.stderr.splitlines())}
    assert records["json"].level == 0
    assert records["json.decoder"].chain()[0] == "json"


def test_the_table_gives_medians_ranges_and_ratios() -> None:
    def side(cpu: float, private_mib: int) -> SideResult:
        roles = {r.key: RoleFigures(cpu, private_mib * 2**20, 2 * private_mib * 2**20) for r in ROLES}
        return SideResult(roles, 1.0, 1.0, 10.0, "DRIVE")

    runs = [{PYTHON: side(0.002, 10), CPP: side(0.001, 2)}, {PYTHON: side(0.004, 10), CPP: side(0.001, 2)}]
    lines = table(runs).splitlines()
    broker = next(line for line in lines if line.startswith("| goby-broker / gobyd"))
    cells = [c.strip() for c in broker.strip("|").split("|")]
    assert cells[1:4] == ["3.0 (2.0-4.0)", "1.0 (1.0-1.0)", "3.00 (2.00-4.00)"]  # CPU ms/sim s, C++, ratio
    assert cells[4:7] == ["10.0 (10.0-10.0)", "2.0 (2.0-2.0)", "5.00 (5.00-5.00)"]  # private MiB
    total = next(line for line in lines if line.startswith("| total"))
    assert "50.0 (50.0-50.0)" in total
    python_only = table([{PYTHON: side(0.002, 10)}])
    assert "C++" not in python_only and "| total" in python_only


def test_bad_flags_stop_at_parse_time(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    for argv in (["--warp", "0"], ["--warp", "ten"], ["--seconds", "-1"], ["--python-root", str(tmp_path)]):
        with pytest.raises(SystemExit) as stop:
            main(argv)
        assert stop.value.code == 2
    assert "holds no launch/usv/usv.launch" in capsys.readouterr().err


def _check_runs(result: dict[str, SideResult], sides: tuple[str, ...]) -> None:
    for side in sides:
        figures = result[side]
        assert figures.runs, f"{side}: {figures}"
        assert set(figures.roles) == {r.key for r in ROLES}
        assert all(f.private_bytes > 0 and f.rss_bytes >= f.private_bytes for f in figures.roles.values()), figures
        assert figures.figures().cpu_per_sim_s > 0


def test_a_short_run_of_the_python_vehicle_measures_five_processes_that_run() -> None:
    result = measure_run(warp=10, seconds=2.0, settle=0.5, python_root=None, cpp_programs=None, keep=False)
    assert set(result) == {PYTHON}
    _check_runs(result, (PYTHON,))


def test_a_short_run_of_both_vehicles() -> None:
    programs, why = find_cpp_programs()
    if why is not None:
        pytest.skip(why)
    if not private_netns():
        pytest.skip("the real MOOSDB listens on all addresses: run inside a private network namespace "
                    "(unshare -n; loopback up with multicast and a 224.0.0.0/4 route for gobyd's link)")
    result = measure_run(warp=10, seconds=2.0, settle=0.5, python_root=None, cpp_programs=programs, keep=False)
    _check_runs(result, (PYTHON, CPP))
