"""The goby_launch line format: comments, directives, errors that name the line."""

from __future__ import annotations

import signal

import pytest

from launch.errors import LaunchFileError
from launch.launchfile import expand_vars, parse_file, parse_lines


def test_comments_blank_lines_and_plain_commands():
    parsed = parse_lines(
        [
            "# a comment line",
            "",
            "   ",
            "goby-broker <(python -m launch.usv.config broker)   # trailing comment",
            "moos-db /tmp/usv.moos",
        ]
    )
    assert [e.command for e in parsed.entries] == [
        "goby-broker <(python -m launch.usv.config broker)",
        "moos-db /tmp/usv.moos",
    ]
    assert [e.line_number for e in parsed.entries] == [4, 5]
    assert parsed.entries[0].binary == "goby-broker"
    assert parsed.entries[0].kill == "SIGTERM"


def test_directives_split_on_comma_semicolon_and_space():
    (entry,) = parse_lines(["[env=A=1, kill=SIGINT;env=B=${A}:x name=custom] /usr/bin/prog arg"]).entries
    assert entry.env == (("A", "1"), ("B", "${A}:x"))
    assert entry.kill == "SIGINT"
    assert entry.kill_signal == signal.SIGINT
    assert entry.name == "custom"
    assert entry.command == "/usr/bin/prog arg"
    assert entry.binary == "prog"


def test_env_directives_expand_in_order_against_the_base_environment():
    (entry,) = parse_lines(["[env=LD_LIBRARY_PATH=${LD_LIBRARY_PATH}:/opt/lib, env=X=$LD_LIBRARY_PATH] prog"]).entries
    env = entry.environment({"LD_LIBRARY_PATH": "/usr/lib", "OTHER": "kept"})
    assert env["LD_LIBRARY_PATH"] == "/usr/lib:/opt/lib"
    assert env["X"] == "/usr/lib:/opt/lib"
    assert env["OTHER"] == "kept"


def test_goby_terminate_is_accepted_and_maps_to_sigterm():
    (entry,) = parse_lines(["[kill=goby_terminate] gobyd"]).entries
    assert entry.kill_signal == signal.SIGTERM


def test_expand_vars_like_bash():
    env = {"A": "x", "EMPTY": ""}
    assert expand_vars("$A/${A}/${UNSET}/${UNSET:-dflt}/${EMPTY:-d2}/${A:-no}", env) == "x/x//dflt/d2/x"


@pytest.mark.parametrize(
    ("line", "message"),
    [
        ("[kill=SIGHUP] prog", "invalid kill=SIGHUP"),
        ("[foo=bar] prog", "unknown directive key 'foo'"),
        ("[env=NOEQUALS] prog", "env directive 'NOEQUALS' is not NAME=value"),
        ("[env=1BAD=x] prog", "is not NAME=value"),
        ("[kill] prog", "is not key=value"),
        ("[kill=SIGTERM]", "directives without a command"),
        ("[kill=SIGTERM prog", "not closed"),
    ],
)
def test_bad_lines_name_the_file_and_line(line, message):
    with pytest.raises(LaunchFileError) as info:
        parse_lines(["# header", line], source="mission.launch")
    assert "mission.launch:2" in str(info.value)
    assert message in str(info.value)


def test_missing_and_empty_files_are_clear_errors(tmp_path):
    with pytest.raises(LaunchFileError, match="cannot read launch file .*nope.launch"):
        parse_file(tmp_path / "nope.launch")
    empty = tmp_path / "empty.launch"
    empty.write_text("# only comments\n\n")
    with pytest.raises(LaunchFileError, match="no commands to launch"):
        parse_file(empty)
