"""The behaviour base class is abstract, and the core-helm helper leaves no files behind."""

from __future__ import annotations

import tempfile
from pathlib import Path

import pytest

from behaviors.helm.behavior import Behavior
from behaviors.helm.info_buffer import InfoBuffer
from behaviors.helm.ivp import IvPDomain
from behaviors.helm.registry import BEHAVIOR_TYPES, builtin_class
from behaviors.helm.testing import helm_from_text


def _domain() -> IvPDomain:
    return helm_from_text("").config.domain


def test_the_base_behaviour_cannot_be_instantiated() -> None:
    with pytest.raises(TypeError, match="abstract"):
        Behavior(_domain(), InfoBuffer())  # type: ignore[abstract]


def test_a_behaviour_missing_a_required_method_cannot_be_instantiated() -> None:
    class NoRunState(Behavior):
        def set_specific_param(self, param: str, value: str) -> bool:
            return False

    with pytest.raises(TypeError, match="on_run_state"):
        NoRunState(_domain(), InfoBuffer())  # type: ignore[abstract]


@pytest.mark.parametrize("type_name", sorted(BEHAVIOR_TYPES))
def test_every_registered_behaviour_implements_the_required_methods(type_name: str) -> None:
    cls = builtin_class(type_name)
    assert cls is not None and not cls.__abstractmethods__
    assert cls(_domain(), InfoBuffer()).TYPE == type_name


def test_helm_from_text_removes_its_temporary_directory(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))  # where TemporaryDirectory creates its directory
    helm = helm_from_text("Behavior = BHV_ConstantSpeed\n{\n  speed = 1\n}\n")
    assert [b.TYPE for b in helm.engine.behaviors] == ["BHV_ConstantSpeed"]
    assert list(tmp_path.iterdir()) == []
