"""The helm's copy of the MOOSDB: last value per variable plus what arrived since the last iteration."""

from __future__ import annotations

from collections import defaultdict

Value = float | str


class InfoBuffer:
    """Last value and the per-iteration list of new values (``updates`` needs every post)."""

    def __init__(self) -> None:
        self._values: dict[str, Value] = {}
        self._deltas: dict[str, list[Value]] = defaultdict(list)

    def set(self, var: str, value: Value) -> None:
        """Record a new value; strings and floats keep their MOOS type."""
        if isinstance(value, bool):
            value = "true" if value else "false"
        if isinstance(value, int):
            value = float(value)
        self._values[var] = value
        self._deltas[var].append(value)

    def get(self, var: str) -> Value | None:
        return self._values.get(var)

    def get_double(self, var: str) -> float | None:
        value = self._values.get(var)
        return value if isinstance(value, float) else None

    def is_known(self, var: str) -> bool:
        return var in self._values

    def deltas(self, var: str) -> list[Value]:
        """Values posted to ``var`` since the last :meth:`clear_deltas`, oldest first."""
        return list(self._deltas.get(var, ()))

    def clear_deltas(self) -> None:
        self._deltas.clear()
