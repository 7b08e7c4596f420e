"""What every mission runner shares: choosing real or our MOOS programs, how processes ended, error lines in logs."""

from __future__ import annotations

import re
import shutil
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

from launch.errors import MissionConfigError
from launch.process_group import ManagedProcess

# Lines that count as an unexpected error in a process log.
ERROR_PATTERN = re.compile(r"Traceback|\bERROR\b|\bCRITICAL\b|\bFATAL\b|Segmentation fault|core dumped", re.I)
# Errors that are part of a normal run (add with a comment saying why).
EXPECTED_ERRORS: tuple[re.Pattern[str], ...] = (
    # goby-coroner's warning for a vehicle report that is not HEALTH__OK prints the report, whose processes carry an
    # `error:` field: at start-up its first requests go out before every application has subscribed (goby_coroner
    # does the same). A process that dies later shows in the mission's process outcomes.
    re.compile(r"goby_coroner WARNING: Vehicle report: "),
)


def choose_program(choice: str, real: str, ours: str) -> str:
    """``auto``: the real MOOS-IvP program when it is on PATH, else ours; ``real``/``ours`` force one."""
    if choice == "ours":
        return ours
    found = shutil.which(real)
    if choice == "real":
        if not found:
            raise MissionConfigError(f"{real} was asked for but is not on PATH")
        return real
    if choice != "auto":
        raise MissionConfigError(f"choose auto, real or ours, not {choice!r}")
    return real if found else ours


@dataclass
class ProcessOutcome:
    """How one process ended."""

    name: str
    returncode: int | None
    clean: bool
    log_path: Path


def outcomes(processes: Iterable[ManagedProcess]) -> list[ProcessOutcome]:
    return [ProcessOutcome(p.name, p.returncode, p.exited_cleanly, p.log_path) for p in processes]


def scan_log_files(logs: Iterable[tuple[str, Path]]) -> list[str]:
    """Unexpected error lines, as ``name: line``, from each (name, log path)."""
    found = []
    for name, path in logs:
        try:
            lines = path.read_text(errors="replace").splitlines()
        except OSError as exc:
            found.append(f"{name}: log unreadable: {exc}")
            continue
        for line in lines:
            if ERROR_PATTERN.search(line) and not any(p.search(line) for p in EXPECTED_ERRORS):
                found.append(f"{name}: {line.strip()}")
    return found


def scan_logs(processes: Iterable[ManagedProcess]) -> list[str]:
    """Unexpected error lines from every process log."""
    return scan_log_files((p.name, p.log_path) for p in processes)


def ending_lines(outcomes: Iterable[ProcessOutcome], log_errors: list[str], failure: str | None,
                 what: str = "processes") -> list[str]:
    """The end of a mission summary: how the processes (or launchers) ended, error lines in their logs, failure."""
    outcomes = list(outcomes)
    clean = [o for o in outcomes if o.clean]
    lines = [f"{what}: {len(clean)}/{len(outcomes)} exited cleanly"
             + "".join(f"\n  NOT clean: {o.name} (exit status {o.returncode}, log {o.log_path})"
                       for o in outcomes if not o.clean)]
    if log_errors:
        lines.append(f"unexpected error lines in the logs ({len(log_errors)}):")
        lines.extend(f"  {line}" for line in log_errors[:20])
    else:
        lines.append("logs: no unexpected errors")
    if failure:
        lines.append(f"FAILED: {failure}")
    return lines
