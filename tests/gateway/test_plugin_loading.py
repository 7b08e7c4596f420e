"""Plugin resolution (GOBY_MOOS_GATEWAY_PLUGINS) in-process, and every failure through the real console script:
exit status 1 and one line naming the plugin and the cause (the traceback only at -vv)."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
from gateway_plugin_sources import ECHO_PLUGIN, IMPORT_ERROR_PLUGIN, NO_LOAD_PLUGIN, RAISING_LOAD_PLUGIN

from gateway.goby.portal.testing import broker_process
from gateway.moos.testing import running_moosdb
from gateway.moos_gateway.plugins import (
    ENV_VAR,
    PLUGIN_POINT,
    plugin_entries_from_env,
    resolve_plugin,
    resolve_plugins,
    split_plugin_list,
)
from util.extensions import ExtensionError


def test_split_on_any_delimiter_keeping_empty_entries():
    assert split_plugin_list("a;b:c,d") == ["a", "b", "c", "d"]
    assert split_plugin_list("a::b,") == ["a", "", "b", ""]


def test_unset_variable_is_an_error():
    with pytest.raises(ExtensionError, match=f"Must define at least one plugin library in {ENV_VAR}"):
        plugin_entries_from_env({})
    assert plugin_entries_from_env({ENV_VAR: "x.py;y"}) == ["x.py", "y"]


def test_resolve_file_and_dotted_module(tmp_path, monkeypatch):
    path = tmp_path / "echo_plugin.py"
    path.write_text(ECHO_PLUGIN)
    by_path = resolve_plugin(str(path))
    assert by_path.entry == str(path) and callable(by_path.load) and callable(by_path.unload)
    assert hasattr(by_path.module, "EchoTranslator")
    (tmp_path / "dotted_gateway_plugin_mod.py").write_text("def load(gateway):\n    gateway.loaded = True\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    by_name = resolve_plugin("dotted_gateway_plugin_mod")
    assert by_name.unload is None
    holder = type("Holder", (), {})()
    by_name.load(holder)
    assert holder.loaded is True
    monkeypatch.delitem(sys.modules, "dotted_gateway_plugin_mod")


def test_entry_points_are_selected_by_name_only():
    names = PLUGIN_POINT.names()
    assert {"frontseat", "usv_command", "node_report"} <= set(names)
    assert PLUGIN_POINT.entry_point("frontseat").value == "translators.frontseat.translation"
    # Goby's library file name is an alias of ours
    alias = PLUGIN_POINT.entry_point("libgoby_ivp_frontseat_moos_gateway_plugin.so")
    assert alias.value == "translators.frontseat.translation"
    # a dotted name is a module, not an entry point
    assert PLUGIN_POINT.entry_point("translators.frontseat.translation") is None


def test_goby_library_path_loads_our_frontseat_plugin():
    plugin = resolve_plugin("/usr/lib/x86_64-linux-gnu/libgoby_ivp_frontseat_moos_gateway_plugin.so.30")
    assert plugin.module.__name__ == "translators.frontseat.translation" and callable(plugin.load)


@pytest.mark.parametrize(
    ("source", "entry", "cause"),
    [
        (None, "no_such_gateway_plugin_abc", "Failed to open plugin: no_such_gateway_plugin_abc, reason: ModuleNotFoundError"),
        (None, "/nonexistent/dir/plugin.py", "Failed to open plugin: /nonexistent/dir/plugin.py, reason: no such file"),
        (NO_LOAD_PLUGIN, "{dir}/no_load.py", "Function load in plugin: {dir}/no_load.py does not exist"),
        (IMPORT_ERROR_PLUGIN, "{dir}/import_error.py", "reason: ModuleNotFoundError: No module named 'no_such_dependency_xyz'"),
        (ECHO_PLUGIN, "{dir}/echo.py:", "Failed to open plugin: '', reason: empty entry"),
        (ECHO_PLUGIN, "{dir}/echo.py,{dir}/echo.py", "is already loaded as {dir}/echo.py (listed twice"),
    ],
    ids=["missing-module", "missing-file", "no-load", "import-error", "empty-entry", "listed-twice"],
)
def test_resolution_errors_name_the_plugin(tmp_path, source, entry, cause):
    entry = entry.format(dir=tmp_path)
    if source is not None:
        Path(re.split("[:,]", entry)[0]).write_text(source)
    with pytest.raises(ExtensionError) as info:
        resolve_plugins(split_plugin_list(entry))
    assert cause.format(dir=tmp_path) in str(info.value)


def _run_gateway(tmp_path: Path, plugins: str | None, config: str, timeout: float = 60,
                 extra_args: tuple[str, ...] = ()) -> subprocess.CompletedProcess:
    env = dict(os.environ)
    env.pop(ENV_VAR, None)
    if plugins is not None:
        env[ENV_VAR] = plugins
    cfg = tmp_path / "gateway.pb.cfg"
    cfg.write_text(config)
    return subprocess.run([sys.executable, "-m", "gateway.apps.moos_gateway", str(cfg), *extra_args], env=env,
                          capture_output=True, text=True, timeout=timeout, cwd=tmp_path)


@pytest.mark.parametrize(
    ("source", "plugins", "cause"),
    [
        (None, None, f"Must define at least one plugin library in {ENV_VAR} environmental variable"),
        (None, "no_such_gateway_plugin_abc", "Failed to open plugin: no_such_gateway_plugin_abc, reason: ModuleNotFoundError"),
        (NO_LOAD_PLUGIN, "{dir}/no_load.py", "Function load in plugin: {dir}/no_load.py does not exist"),
        (IMPORT_ERROR_PLUGIN, "{dir}/import_error.py", "No module named 'no_such_dependency_xyz'"),
    ],
    ids=["unset", "missing-module", "no-load", "import-error"],
)
def test_console_script_exits_1_before_anything_runs(tmp_path, source, plugins, cause):
    if plugins is not None:
        plugins = plugins.format(dir=tmp_path)
        if source is not None:
            Path(plugins).write_text(source)
    # the config points at nothing: resolution must fail before any connection is attempted
    result = _run_gateway(tmp_path, plugins, 'moos { server: "127.0.0.1" port: 1 }')
    assert result.returncode == 1, result.stderr
    assert cause.format(dir=tmp_path) in result.stderr


def test_exception_in_load_stops_what_earlier_plugins_started(tmp_path):
    """One line names the plugin and the cause; no traceback unless asked for with -vv."""
    (tmp_path / "echo.py").write_text(ECHO_PLUGIN)
    (tmp_path / "raising.py").write_text(RAISING_LOAD_PLUGIN)
    with running_moosdb() as db, broker_process(tmp_path, platform="gwload") as broker:
        config = (f"interprocess {{ {broker.interprocess_text()} }} "
                  f'moos {{ server: "127.0.0.1" port: {db.port} }}')
        plugins = f"{tmp_path}/echo.py;{tmp_path}/raising.py"
        result = _run_gateway(tmp_path, plugins, config)
        verbose = _run_gateway(tmp_path, plugins, config, extra_args=("-vv",))
    assert result.returncode == 1, result.stderr
    cause = f"plugin {tmp_path}/raising.py: load(gateway) raised ValueError: the plugin refuses to start"
    lines = [line for line in result.stderr.splitlines() if "raising.py" in line or "refuses" in line]
    assert len(lines) == 1 and cause in lines[0], result.stderr
    assert "Traceback" not in result.stderr
    assert verbose.returncode == 1, verbose.stderr
    assert cause in verbose.stderr and "Traceback (most recent call last)" in verbose.stderr


def test_example_config_needs_no_plugins(tmp_path):
    env = {k: v for k, v in os.environ.items() if k != ENV_VAR}
    result = subprocess.run([sys.executable, "-m", "gateway.apps.moos_gateway", "--example_config"], env=env,
                            capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stderr
    assert "moos {" in result.stdout and "poll_frequency" in result.stdout
