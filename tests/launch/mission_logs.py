"""Checks of a mission run's logs shared by the mission tests: a .goby per platform and an .alog per MOOS community
where the demo says they are, and the demo's printed MCAP command run for real, its output read back with the mcap
library's reader (CRCs validated): every platform's groups, every protobuf channel with its schema."""

from __future__ import annotations

import subprocess
from pathlib import Path

from mcap.reader import make_reader

from gateway.goby.log import LogReader
from launch.recorder import mcap_command


def assert_logs_per_platform(logs: dict[str, list[Path]], log_dirs: dict[str, Path], moos: set[str]) -> None:
    """``logs`` (platform -> the files its record was read from) holds one .goby per platform in its log directory
    and one .alog per platform in ``moos`` (in moos-logger's session directory there), each non-empty."""
    assert set(logs) == set(log_dirs), logs
    for platform, paths in logs.items():
        suffixes = sorted(p.suffix for p in paths)
        assert suffixes == ([".alog", ".goby"] if platform in moos else [".goby"]), (platform, paths)
        for path in paths:
            assert path.stat().st_size > 1000, path
            assert log_dirs[platform] in path.parents, (platform, path)
            if path.suffix == ".goby":
                assert path.name.startswith(f"{platform}_"), path


def assert_mcap_export_has_every_group(log_root: Path, gobys: list[Path]) -> dict[Path, set[str]]:
    """Run the demo's MCAP command; each .goby's .mcap must hold every group the .goby holds, every channel with a
    schema (no type left as bytes). Returns each .mcap's topics."""
    done = subprocess.run(mcap_command(log_root), shell=True, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-2000:]
    assert "Traceback" not in done.stderr and "kept as bytes" not in done.stderr, done.stderr[-2000:]
    topics: dict[Path, set[str]] = {}
    for goby in gobys:
        with LogReader(goby) as log:
            groups = {entry.group for entry in log}
        mcap = goby.with_suffix(".mcap")
        with open(mcap, "rb") as f:
            reader = make_reader(f, validate_crcs=True)
            summary = reader.get_summary()
            assert summary is not None
            channels = list(summary.channels.values())
            topics[mcap] = {c.topic for c in channels}
            assert all(c.schema_id != 0 for c in channels), [c.topic for c in channels if c.schema_id == 0]
            assert sum(1 for _ in reader.iter_messages()) > 0
        assert topics[mcap] == groups, (mcap, groups ^ topics[mcap])
    return topics
