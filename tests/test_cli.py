"""util.cli's help formatter, and what the long-running processes keep out of memory at start-up."""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from gateway.apps.moos_db import build_parser
from util.cli import terminal_columns

REPO = Path(__file__).resolve().parents[1]

# Modules that cost private memory in every process and that none of the vehicle's processes needs to start:
# shutil (argparse's default formatter imports it, with bz2 and lzma), subprocess (only where a child is started),
# hashlib (OpenSSL; only for a plugin loaded from a file).
HEAVY = ["shutil", "subprocess", "hashlib"]

STARTUP = """
import json, sys
from gateway.apps.moos_db import build_parser
from gateway.apps.moos_tool_args import parse_moos_app_args
from gateway.goby.portal.config import build_parser as portal_parser
from gateway.goby.protobuf.app_config_pb2 import AppConfig
import frontseat.apps.frontseat_sim, frontseat.errors
build_parser().format_help()
portal_parser(AppConfig, "x").format_help()
parse_moos_app_args(["m.moos"], "ivp-helm", "helm", "pHelmIvP")
print(json.dumps(sorted(m for m in %r if m in sys.modules)))
"""


def test_the_vehicle_processes_start_without_shutil_subprocess_or_hashlib() -> None:
    out = subprocess.run([sys.executable, "-c", STARTUP % HEAVY], capture_output=True, text=True, cwd=REPO,
                         env={**os.environ, "PYTHONPATH": str(REPO)}, timeout=60, check=True)
    assert json.loads(out.stdout.splitlines()[-1]) == []


def test_help_is_laid_out_as_argparse_lays_it_out(monkeypatch: pytest.MonkeyPatch) -> None:
    for columns in ("50", "200"):
        monkeypatch.setenv("COLUMNS", columns)
        assert terminal_columns() == int(columns)
        ours = build_parser()
        theirs = build_parser()
        theirs.formatter_class = argparse.HelpFormatter
        assert ours.format_help() == theirs.format_help()
    assert _help_at(monkeypatch, "200") != _help_at(monkeypatch, "50")


def _help_at(monkeypatch: pytest.MonkeyPatch, columns: str) -> str:
    monkeypatch.setenv("COLUMNS", columns)
    return build_parser().format_help()


def test_columns_fall_back_when_unset_or_bad(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("COLUMNS", "not a number")
    assert terminal_columns(fallback=77) in (77, *range(1, 10_000))  # a terminal on stdout, if any, wins
    monkeypatch.setattr(sys, "__stdout__", None)
    assert terminal_columns(fallback=77) == 77


def test_moos_db_starts_without_the_client_engine_or_dataclasses() -> None:
    """moos-db only serves: the client's engine and dataclasses (which imports inspect) stay out of it."""
    script = ("import json, sys; from gateway.apps.moos_db import build_parser; build_parser().format_help(); "
              "print(json.dumps(sorted(m for m in ('gateway.moos.client', 'gateway.moos.engine', 'dataclasses', "
              "'inspect') if m in sys.modules)))")
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, cwd=REPO,
                         env={**os.environ, "PYTHONPATH": str(REPO)}, timeout=60, check=True)
    assert json.loads(out.stdout.splitlines()[-1]) == []
