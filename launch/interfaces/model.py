"""The data of an interface file: publications and subscriptions per layer, and the threads that make them."""

from __future__ import annotations

from dataclasses import dataclass, field

LAYERS = ("intervehicle", "intermodule", "interprocess", "interthread")
"""Layers, outermost first: the order Goby writes them in."""

NECESSITIES = ("required", "recommended", "optional")

INNER_LAYERS = {
    "intervehicle": ("interprocess", "interthread"),
    "intermodule": ("interthread",),
    "interprocess": ("interthread",),
    "interthread": (),
}
"""The layers a publication is copied to: Goby's usual stack is intervehicle > interprocess > interthread."""


@dataclass(frozen=True, order=True)
class PubSubEntry:
    """One publish or subscribe call as Goby's interface YAML records it.

    ``type`` is the C++-style name (``goby::middleware::frontseat::protobuf::NodeStatus``) because that is what
    Goby's files contain and what the connection rules compare; ``thread`` is the most-derived thread class.
    """

    layer: str
    thread: str
    group: str
    scheme: str
    type: str
    direction: str  # "publishes" | "subscribes"
    necessity: str = "optional"
    inner: bool = False
    is_regex: bool = False

    def __post_init__(self) -> None:
        if self.layer not in LAYERS:
            raise ValueError(f"unknown layer {self.layer!r}; expected one of {', '.join(LAYERS)}")
        if self.direction not in ("publishes", "subscribes"):
            raise ValueError(f"direction must be 'publishes' or 'subscribes', not {self.direction!r}")
        if self.necessity not in NECESSITIES:
            raise ValueError(f"unknown necessity {self.necessity!r}; expected one of {', '.join(NECESSITIES)}")


@dataclass
class ThreadInfo:
    """A thread class of an application: its name, whether it is known to be a thread, and its bases."""

    name: str
    known: bool = True
    bases: list[str] = field(default_factory=list)


@dataclass
class ApplicationInterface:
    """Everything an application publishes and subscribes, on every layer."""

    application: str
    entries: set[PubSubEntry] = field(default_factory=set)
    threads: dict[str, ThreadInfo] = field(default_factory=dict)

    def add(self, entry: PubSubEntry) -> None:
        """Record ``entry``, and its copies on inner layers (Goby publishes outer-layer data on inner layers too)."""
        self.entries.add(entry)
        self.threads.setdefault(entry.thread, ThreadInfo(entry.thread))
        if entry.direction != "publishes":
            return
        for inner_layer in INNER_LAYERS[entry.layer]:
            if inner_layer == "interthread":
                schemes = ["CXX_OBJECT"]
            elif entry.layer == "intervehicle":
                schemes = ["DCCL", "PROTOBUF"]  # Goby republishes intervehicle data on interprocess both ways
            else:
                schemes = [entry.scheme]
            for scheme in schemes:
                self.entries.add(
                    PubSubEntry(inner_layer, entry.thread, entry.group, scheme, entry.type, "publishes", inner=True)
                )

    def layer_entries(self, layer: str, direction: str) -> list[PubSubEntry]:
        """Entries of one layer and direction, sorted as Goby sorts them (thread, group, scheme, type)."""
        chosen = [e for e in self.entries if e.layer == layer and e.direction == direction]
        return sorted(chosen, key=lambda e: (e.thread, e.group, e.scheme, e.type, e.inner, e.is_regex))

    def used_layers(self) -> list[str]:
        """Layers that have entries; interprocess implies interthread, intervehicle implies interprocess."""
        used = {e.layer for e in self.entries}
        if "intervehicle" in used:
            used.add("interprocess")
        if "interprocess" in used:
            used.add("interthread")
        return [layer for layer in LAYERS if layer in used]
