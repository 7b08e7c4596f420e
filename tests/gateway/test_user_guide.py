"""The examples of docs/writing_a_translator.md, run as written: the plugin is loaded from a file by path and
exercised by the guide's own test function."""

from __future__ import annotations

import re
from pathlib import Path

from gateway.moos_gateway.plugins import resolve_plugin

GUIDE = Path(__file__).resolve().parents[2] / "docs" / "writing_a_translator.md"


def _python_blocks() -> list[str]:
    return re.findall(r"```python\n(.*?)```", GUIDE.read_text(), flags=re.S)


def test_guide_plugin_and_test_work(tmp_path):
    plugin_source, test_source = _python_blocks()
    assert len(plugin_source.strip().splitlines()) <= 30  # "about twenty lines"
    plugin_path = tmp_path / "my_course_plugin.py"
    plugin_path.write_text(plugin_source)
    plugin = resolve_plugin(str(plugin_path))
    namespace = {"CourseTranslator": plugin.module.CourseTranslator,
                 "DesiredCourse": plugin.module.DesiredCourse}
    exec(compile(test_source, str(GUIDE), "exec"), namespace)  # noqa: S102 - our own documentation
    namespace["test_course"](tmp_path)
