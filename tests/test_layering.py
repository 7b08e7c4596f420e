"""The import layering that docs/ARCHITECTURE.md states: no package imports one above it, and the MOOS and Goby
sides of the gateway do not know each other.

Every ``import`` statement of every module counts, including imports inside functions (a lazy import is still a
dependency). The check reads source with ``ast``; it runs nothing.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]

# Bottom to top. A module may import its own package and any package listed before it.
LAYERS = ("util", "gateway", "frontseat", "translators", "behaviors", "launch")

# Inside gateway: the two sides are independent; the gateway process and the apps sit on both.
GATEWAY_SIDES = {"gateway.moos": {"gateway.goby", "gateway.moos_gateway", "gateway.apps"},
                 "gateway.goby": {"gateway.moos", "gateway.moos_gateway", "gateway.apps"}}


def _module_name(path: Path) -> str:
    parts = path.relative_to(REPO).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imports(path: Path) -> list[tuple[int, str]]:
    """(line, absolute module name) of every import in the file; relative imports resolved."""
    tree = ast.parse(path.read_text(), filename=str(path))
    package = _module_name(path).rsplit(".", 1)[0] if path.name != "__init__.py" else _module_name(path)
    found: list[tuple[int, str]] = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found.extend((node.lineno, alias.name) for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[: len(base) - (node.level - 1)]
                name = ".".join(base + ([node.module] if node.module else []))
            else:
                name = node.module or ""
            found.append((node.lineno, name))
    return found


def _sources() -> list[Path]:
    return sorted(p for layer in LAYERS for p in (REPO / layer).rglob("*.py") if ".venv" not in p.parts)


def _violations() -> list[str]:
    problems: list[str] = []
    for path in _sources():
        here = _module_name(path)
        rank = LAYERS.index(here.split(".")[0])
        for line, name in _imports(path):
            top = name.split(".")[0]
            if top in LAYERS and LAYERS.index(top) > rank:
                problems.append(f"{path.relative_to(REPO)}:{line}: {here} imports {name}, a layer above it")
            for side, forbidden in GATEWAY_SIDES.items():
                if (here == side or here.startswith(side + ".")) and any(
                        name == f or name.startswith(f + ".") for f in forbidden):
                    problems.append(f"{path.relative_to(REPO)}:{line}: {here} imports {name} "
                                    f"(the MOOS and Goby sides must not depend on each other or on the gateway process)")
    return problems


def test_no_package_imports_one_above_it() -> None:
    problems = _violations()
    assert not problems, "layering broken:\n" + "\n".join(problems)


@pytest.mark.parametrize("source, expected", [
    ("from translators.base import Translator\n", "imports translators.base, a layer above it"),
    ("import launch\n", "imports launch, a layer above it"),
])
def test_the_check_catches_an_upward_import(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, source: str,
                                            expected: str) -> None:
    """The checker itself: a frontseat module importing upward is reported with its file and line."""
    fake_repo = tmp_path
    (fake_repo / "frontseat").mkdir()
    (fake_repo / "frontseat" / "bad.py").write_text(source)
    monkeypatch.setattr(__import__(__name__, fromlist=["REPO"]), "REPO", fake_repo)
    problems = _violations()
    assert len(problems) == 1 and "frontseat/bad.py:1" in problems[0] and expected in problems[0]
