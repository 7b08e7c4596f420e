"""Logic conditions: pHelmIvP's grammar, typing and unknown-variable semantics, and the error messages."""

from __future__ import annotations

import pytest

from behaviors.helm.errors import ConditionError
from behaviors.helm.logic import LogicCondition, field_match

VALUES = {"DEPLOY": "true", "RETURN": "false", "N": 3.0, "NS": "7", "MODE": "ACTIVE:LOITERING", "OTHER": 3.0}


def ev(text: str) -> bool:
    return LogicCondition(text).evaluate(VALUES.get)


@pytest.mark.parametrize(("text", "expected"), [
    ("DEPLOY = true", True),
    ("DEPLOY=true", True),
    ("DEPLOY = TRUE", False),  # string comparison is case-sensitive
    ("DEPLOY != false", True),
    ("N = 3", True),
    ("N < 4", True),
    ("N <= 3", True),
    ("N > 3", False),
    ("N >= 3.0", True),
    ("NS > 5", True),  # a string that parses as a number compares numerically against a number
    ("DEPLOY > 5", False),  # a non-numeric string against a number is false
    ("DEPLOY = \"true\"", True),
    ("MODE == LOITERING", True),  # field match on ':'-separated parts
    ("MODE == ACTIVE:LOITERING", True),
    ("MODE = LOITERING", False),
    ("N = $(OTHER)", True),
    ("(DEPLOY = true) and (RETURN = false)", True),
    ("(DEPLOY = true) and (RETURN = true)", False),
    ("(DEPLOY = false) or (N = 3)", True),
    ("((DEPLOY = true) and (N < 10)) or (RETURN = true)", True),
    ("!(DEPLOY = true)", False),
    ("(DEPLOY = true) AND !(RETURN = true)", True),
    ("((DEPLOY = true))", True),
])
def test_relations_and_boolean_operators(text: str, expected: bool) -> None:
    assert ev(text) is expected


@pytest.mark.parametrize("text", ["UNKNOWN = 1", "UNKNOWN != 1", "UNKNOWN < 1", "N = $(UNKNOWN)",
                                  "N != $(UNKNOWN)"])
def test_every_relation_on_an_unknown_variable_is_false(text: str) -> None:
    assert ev(text) is False


def test_negation_of_an_unknown_relation_is_true() -> None:
    assert ev("!(UNKNOWN = 1)") is True


def test_variables_are_reported_for_registration() -> None:
    assert LogicCondition("((A = 1) and (B < $(C))) or !(D = x)").variables() == {"A", "B", "C", "D"}


@pytest.mark.parametrize(("text", "token", "reason"), [
    ("A = 1 and B = 2", "A = 1", "must be in parentheses"),
    ("(A = 1) and B = 2", "B = 2", "must be in parentheses"),
    ("DEPLOY", "DEPLOY", "no relation"),
    ("(A = 1", "(A = 1", "unbalanced parentheses"),
    ("A = (1", "A = (1", "unbalanced"),
    ("= 3", "=", "left side must be a MOOS variable"),
    ("A = ", "=", "right side"),
    ("", "", "empty"),
])
def test_bad_conditions_name_the_token(text: str, token: str, reason: str) -> None:
    with pytest.raises(ConditionError) as info:
        LogicCondition(text)
    assert token in info.value.token
    assert reason in str(info.value)
    assert text.strip() in str(info.value)


def test_field_match() -> None:
    assert field_match("alpha:bravo:charlie", "charlie")
    assert field_match("alpha", "alpha:bravo")
    assert field_match("alpha:bravo", "alpha:bravo:charlie")
    assert not field_match("pha:bra", "alpha:bravo:charlie")
    assert not field_match("delta", "alpha:bravo")
