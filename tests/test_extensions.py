"""The one extension loader (``util.extensions``): lookup order, Goby library names, files, and every failure
naming the spec and the cause.  Entry points come from a real ``.dist-info`` directory put on ``sys.path``, which
is how an installed distribution looks to ``importlib.metadata``."""

from __future__ import annotations

import sys
from collections.abc import Iterator
from pathlib import Path
from types import MappingProxyType, ModuleType

import pytest

from util.extensions import ExtensionError, ExtensionPoint, load_extension, load_module, module_function

GROUP = "goby_moos_py_tests.extensions"
ENTRY_POINTS = f"""\
[{GROUP}]
widgets = ext_widgets_mod
widget_class = ext_widgets_mod:Widget
broken = ext_broken_mod
ext_dotted_mod = ext_widgets_mod
"""
POINT = ExtensionPoint(group=GROUP, what="test extension", source="TEST_EXTENSIONS",
                       aliases=MappingProxyType({"goby_widgets_plugin": "widgets"}), library_prefix="goby_ext_")


@pytest.fixture
def installed(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Path]:
    """A distribution with entry points in GROUP, and its modules, on sys.path (removed afterwards)."""
    dist = tmp_path / "ext_test_dist-1.0.dist-info"
    dist.mkdir()
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: ext-test-dist\nVersion: 1.0\n")
    (dist / "entry_points.txt").write_text(ENTRY_POINTS)
    (tmp_path / "ext_widgets_mod.py").write_text("class Widget:\n    pass\n\ndef load(host):\n    host.append(1)\n")
    (tmp_path / "ext_broken_mod.py").write_text("raise RuntimeError('broken at import')\n")
    (tmp_path / "ext_dotted_mod.py").write_text("SOURCE = 'dotted'\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    yield tmp_path
    for name in ("ext_widgets_mod", "ext_broken_mod", "ext_dotted_mod"):
        sys.modules.pop(name, None)


def test_entry_points_by_name_and_by_goby_library_name(installed: Path) -> None:
    assert {"widgets", "widget_class", "broken"} <= set(POINT.names())
    module = load_module(POINT, "widgets")
    assert module.__name__ == "ext_widgets_mod"
    assert load_extension(POINT, "widget_class") is module.Widget
    for goby_name in ("libgoby_widgets_plugin.so", "/usr/lib/libgoby_widgets_plugin.so.30",  # alias table
                      "libgoby_ext_widgets.so.3.0", "libwidgets.so"):  # prefix dropped; plain stem
        assert load_module(POINT, goby_name) is module, goby_name


def test_an_entry_point_comes_before_a_module_of_the_same_name(installed: Path) -> None:
    assert load_module(POINT, "ext_dotted_mod").__name__ == "ext_widgets_mod"
    other = ExtensionPoint(group="goby_moos_py_tests.nothing", what="test extension")
    assert load_module(other, "ext_dotted_mod").SOURCE == "dotted"


def test_a_file_is_imported_once_under_a_private_name(tmp_path: Path) -> None:
    path = tmp_path / "my-plugin.py"
    path.write_text("COUNT = [0]\nCOUNT[0] += 1\n")
    first = load_module(POINT, str(path))
    assert load_module(POINT, f"{tmp_path}/./my-plugin.py") is first and first.COUNT == [1]
    assert first.__name__.startswith("_extension_my_plugin_") and sys.modules[first.__name__] is first
    sys.modules.pop(first.__name__)


@pytest.mark.parametrize(
    ("spec", "cause"),
    [
        ("", "empty entry in TEST_EXTENSIONS"),
        ("  ", "empty entry in TEST_EXTENSIONS"),
        ("broken", "entry point broken = ext_broken_mod: RuntimeError: broken at import"),
        ("no_such_ext_module_xyz", "ModuleNotFoundError: No module named 'no_such_ext_module_xyz' "
                                   f"(entry points in {GROUP}: broken, ext_dotted_mod, widget_class, widgets)"),
        ("/no/such/dir/plugin.py", "no such file"),
        ("libunknown_thing.so.1", "a shared library with no Python counterpart: no entry point unknown_thing in "
                                  f"group {GROUP}"),
    ],
    ids=["empty", "blank", "entry-point-import-fails", "no-module", "no-file", "unknown-goby-library"],
)
def test_failures_name_the_spec_and_the_cause(installed: Path, spec: str, cause: str) -> None:
    with pytest.raises(ExtensionError) as info:
        load_extension(POINT, spec)
    assert info.value.spec == spec.strip() and cause in info.value.cause
    assert str(info.value) == f"Failed to open test extension: {spec.strip() or repr('')}, reason: {info.value.cause}"


def test_a_file_that_fails_to_import_names_the_file_and_leaves_nothing_behind(tmp_path: Path) -> None:
    path = tmp_path / "needs_dep.py"
    path.write_text("import no_such_dependency_xyz\n")
    with pytest.raises(ExtensionError, match=r"needs_dep.py, reason: ModuleNotFoundError: No module named "
                                             r"'no_such_dependency_xyz'$"):
        load_extension(POINT, str(path))
    assert not [name for name in sys.modules if name.startswith("_extension_needs_dep_")]


def test_entry_points_only_points_refuse_files_and_modules(installed: Path) -> None:
    strict = ExtensionPoint(group=GROUP, what="strict extension", entry_points_only=True)
    assert load_module(strict, "widgets").__name__ == "ext_widgets_mod"
    for spec in ("json", str(installed / "ext_dotted_mod.py")):
        with pytest.raises(ExtensionError, match="no entry point of that name in group"):
            load_extension(strict, spec)


def test_module_checks(installed: Path) -> None:
    with pytest.raises(ExtensionError, match="the entry point names <class 'ext_widgets_mod.Widget'>, not a module"):
        load_module(POINT, "widget_class")
    module = load_module(POINT, "widgets")
    host: list[int] = []
    load = module_function(POINT, "widgets", module, "load")
    assert load is not None
    load(host)
    assert host == [1]
    assert module_function(POINT, "widgets", module, "unload", required=False) is None
    with pytest.raises(ExtensionError, match=r"^Function unload in test extension: widgets does not exist "
                                             r"\(module ext_widgets_mod\)$"):
        module_function(POINT, "widgets", module, "unload")
    not_callable = ModuleType("not_callable")
    not_callable.load = 3  # type: ignore[attr-defined]
    with pytest.raises(ExtensionError, match="Function load in test extension: x is not callable"):
        module_function(POINT, "x", not_callable, "load")


def test_builtin_names_are_the_installed_entry_points_and_load_without_package_metadata() -> None:
    """The project's own extensions are found without importlib.metadata (MiBs per process); the table must say
    exactly what pyproject.toml's entry points say."""
    import importlib.metadata
    import subprocess

    from frontseat.loading import DRIVER_POINT, HELM_INTERFACE_POINT
    from gateway.moos_gateway.plugins import PLUGIN_POINT

    for point in (DRIVER_POINT, HELM_INTERFACE_POINT, PLUGIN_POINT):
        installed = {ep.name: ep.value for ep in importlib.metadata.entry_points(group=point.group)}
        assert point.builtin, point.group
        for name, target in point.builtin.items():
            assert installed.get(name) == target, (point.group, name)
    code = ("import sys\nfrom frontseat.loading import load_driver_library, helm_interface_class\n"
            "load_driver_library('libgoby_frontseat_basic_simulator.so.30'); helm_interface_class()\n"
            "print('importlib.metadata' in sys.modules)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60, check=True)
    assert out.stdout.strip() == "False"


def test_a_broken_builtin_is_reported_naming_it() -> None:
    point = ExtensionPoint(group="test.none", what="widget", builtin=MappingProxyType({"w": "no_such_mod_xyz:W"}))
    with pytest.raises(ExtensionError, match="Failed to open widget: w, reason: entry point w = no_such_mod_xyz:W: ModuleNotFoundError"):
        load_extension(point, "w")
