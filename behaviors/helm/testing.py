"""Helpers for tests and benchmarks of the helm core (no MOOS): a :class:`Helm` built from .bhv text."""

from __future__ import annotations

import tempfile
from collections.abc import Iterable
from pathlib import Path

from .config import HelmConfig
from .helm import Helm

DOMAIN = ("course:0:359:360", "speed:0:4:41")


def helm_from_text(bhv_text: str, domains: Iterable[str] = DOMAIN, *, directory: Path | None = None,
                   ownship: str = "alpha", where: str = "test.moos: ProcessConfig = pHelmIvP",
                   **params: str) -> Helm:
    """A helm reading ``bhv_text`` as its one behaviour file, plus ``domain`` and other block parameters.

    The file is written to ``directory`` (``test.bhv``, kept for the caller to inspect), or to a temporary
    directory that is removed once the helm has read it.
    """
    if directory is None:
        with tempfile.TemporaryDirectory(prefix="helm-") as tmp:
            return helm_from_text(bhv_text, domains, directory=Path(tmp), ownship=ownship, where=where, **params)
    path = directory / "test.bhv"
    path.write_text(bhv_text)
    pairs = [("behaviors", str(path))] + [("domain", d) for d in domains] + list(params.items())
    return Helm(HelmConfig.from_pairs(pairs, where), ownship=ownship)
