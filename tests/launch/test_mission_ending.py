"""The shared end of both missions' summaries: clean exits, log error lines, failure."""

from __future__ import annotations

from pathlib import Path

from launch.mission import ProcessOutcome, ending_lines


def test_all_clean_and_no_errors() -> None:
    outcomes = [ProcessOutcome("usv.moosdb", 0, True, Path("a.log")), ProcessOutcome("usv.helm", 0, True, Path("b.log"))]
    assert ending_lines(outcomes, [], None) == ["processes: 2/2 exited cleanly", "logs: no unexpected errors"]


def test_unclean_exit_error_lines_and_failure_are_named() -> None:
    outcomes = [ProcessOutcome("auv0", 0, True, Path("a.log")), ProcessOutcome("usv", -9, False, Path("/tmp/usv.log"))]
    errors = [f"usv.log: ERROR {i}" for i in range(25)]
    lines = ending_lines(outcomes, errors, "USV never reached COMMAND", "launchers")
    assert lines[0] == "launchers: 1/2 exited cleanly\n  NOT clean: usv (exit status -9, log /tmp/usv.log)"
    assert lines[1] == "unexpected error lines in the logs (25):"
    assert lines[2:22] == [f"  usv.log: ERROR {i}" for i in range(20)]  # the first 20 only
    assert lines[-1] == "FAILED: USV never reached COMMAND"
