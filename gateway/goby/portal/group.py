"""Goby groups: a name with an optional numeric id; ``str(group)`` is the form used on the wire."""

from __future__ import annotations

from dataclasses import dataclass

from gateway.goby.portal.errors import InvalidGroupError

BROADCAST_GROUP = 0
INVALID_NUMERIC_GROUP = 2**32 - 1
MAXIMUM_VALID_GROUP = 2**32 - 2


@dataclass(frozen=True, slots=True)
class Group:
    """A publish/subscribe group, e.g. ``Group("widget1", 1)`` which travels as ``widget1;1``.

    Equality follows Goby: when both sides have a name, names and numerics must match; otherwise
    only the numerics are compared.
    """

    name: str = ""
    numeric: int | None = None

    def __post_init__(self) -> None:
        if self.numeric is not None and not 0 <= self.numeric <= MAXIMUM_VALID_GROUP:
            raise InvalidGroupError(f"group numeric id {self.numeric} is outside 0..{MAXIMUM_VALID_GROUP}")

    def __str__(self) -> str:
        if self.name:
            return self.name if self.numeric is None else f"{self.name};{self.numeric}"
        return str(self.numeric if self.numeric is not None else INVALID_NUMERIC_GROUP)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Group):
            return NotImplemented
        if self.name and other.name:
            return self.name == other.name and self.numeric == other.numeric
        return self.numeric == other.numeric

    def __hash__(self) -> int:
        return hash(str(self))

    @classmethod
    def parse(cls, text: str) -> Group:
        """The group a wire string names: ``"a;3"`` -> ``Group("a", 3)``; a plain number -> numeric only."""
        name, sep, num = text.rpartition(";")
        if sep and num.isdigit():
            return cls(name, int(num))
        if text.isdigit():
            return cls("", int(text))
        return cls(text)


GroupLike = Group | str


def as_group(group: GroupLike) -> Group:
    """Accept a ``Group`` or its wire string (``"name"`` or ``"name;N"``)."""
    return group if isinstance(group, Group) else Group.parse(group)


def check_named(group: Group, layer: str) -> None:
    """Interprocess and interthread need a non-empty name (as Goby's ``check_validity``)."""
    if not group.name:
        raise InvalidGroupError(f"Group must have a non-empty string for use on {layer}")
