"""Draw a deployment as Graphviz DOT with goby_clang_tool's structure (``-viz``).

Clusters nest platform > module (only for real modules) > application; nodes are threads. Edges join a
publication to every matching subscription on the layers where they can meet: interthread within one
application, interprocess and intermodule within one platform, intervehicle between different platforms.
Colours, edge styles by the subscriber's necessity, labels (``P0``, ``T1``, ...) and node ids follow Goby.
"""

from __future__ import annotations

import html
import re
from dataclasses import dataclass, field
from itertools import count

from launch.interfaces.deployment import NO_MODULE, Deployment
from launch.interfaces.model import PubSubEntry

VEHICLE_COLOR = "#006400"
MODULE_COLOR = "#cd8500"
PROCESS_COLOR = "#104e8b"
THREAD_COLOR = "#551a8b"
LAYER_COLOR = {
    "intervehicle": VEHICLE_COLOR,
    "intermodule": MODULE_COLOR,
    "interprocess": PROCESS_COLOR,
    "interthread": THREAD_COLOR,
}
LAYER_LETTER = {"interthread": "T", "interprocess": "P", "intermodule": "M", "intervehicle": "V"}
NECESSITY_STYLE = {"required": "bold", "recommended": "tapered", "optional": "solid"}
INTERNAL_GROUPS = {
    "goby::middleware::interprocess::to_portal",
    "goby::middleware::interprocess::from_portal",
    "goby::middleware::interprocess::regex",
    "goby::middleware::SerializationUnSubscribeAll",
    "goby::ThreadJoinable",
    "goby::ThreadShutdown",
    "goby::middleware::intervehicle::modem_data_in",
    "goby::middleware::intervehicle::modem_data_out",
    "goby::middleware::intervehicle::metadata_request",
    "goby::middleware::intervehicle::modem_ack_in",
    "goby::middleware::intervehicle::modem_expire_in",
    "goby::middleware::intervehicle::modem_subscription_forward_tx",
}
TERMINATE_GROUPS = {"goby::terminate::request", "goby::terminate::response"}
CORONER_GROUPS = {"goby::health::request", "goby::health::response"}
_ESCAPED = ":&<> ,-#)(/."


def escape_id(name: str) -> str:
    """Goby's node-id escaping: each special character becomes ``_<decimal ASCII>_``."""
    return "".join(f"_{ord(c)}_" if c in _ESCAPED else c for c in name)


@dataclass
class VizOptions:
    no_disconnected: bool = False
    omit_group_regex: str | None = None
    omit_node_regex: str | None = None
    include_terminate: bool = False
    include_coroner: bool = False
    include_all: bool = False
    splines: str = "ortho"


@dataclass(frozen=True)
class _Node:
    platform: str
    module: str
    application: str
    thread: str

    @property
    def id(self) -> str:
        return "_".join(escape_id(p) for p in (self.platform, self.module, self.application, self.thread))


@dataclass
class _Pub:
    node: _Node
    entry: PubSubEntry
    label: str


@dataclass
class Edge:
    """A drawn connection between a publishing thread and a subscribing thread."""

    publisher: _Node
    subscriber: _Node
    layer: str
    group: str
    scheme: str
    type: str
    label: str
    style: str


@dataclass
class Graph:
    """The connections of a deployment, before they are written as DOT."""

    name: str
    edges: list[Edge] = field(default_factory=list)
    disconnected_pubs: list[_Pub] = field(default_factory=list)
    disconnected_subs: list[tuple[_Node, PubSubEntry]] = field(default_factory=list)
    nodes: dict[str, tuple[_Node, list[str]]] = field(default_factory=dict)


def _connects(pub: PubSubEntry, sub: PubSubEntry) -> bool:
    if pub.layer != sub.layer or pub.group != sub.group:
        return False
    if sub.is_regex:
        return re.fullmatch(sub.group, pub.group) is not None
    return pub.type == sub.type and (pub.scheme == sub.scheme or "CXX_OBJECT" in (pub.scheme, sub.scheme))


def _regex_connects(pub: PubSubEntry, sub: PubSubEntry) -> bool:
    return (
        sub.is_regex
        and pub.layer == sub.layer
        and re.fullmatch(sub.group, pub.group) is not None
        and re.fullmatch(sub.type, pub.type) is not None
    )


def _group_included(group: str, options: VizOptions) -> bool:
    if options.omit_group_regex and re.fullmatch(options.omit_group_regex, group):
        return False
    if options.include_all:
        return True
    if group in INTERNAL_GROUPS:
        return False
    if group in TERMINATE_GROUPS and not options.include_terminate:
        return False
    return not (group in CORONER_GROUPS and not options.include_coroner)


def _node_included(node: _Node, options: VizOptions) -> bool:
    if not options.omit_node_regex:
        return True
    return not any(re.fullmatch(options.omit_node_regex, n) for n in (node.platform, node.module, node.application, node.thread))


def build_graph(deployment: Deployment, options: VizOptions | None = None) -> Graph:
    """Find every edge and every disconnected publication/subscription of a deployment."""
    options = options or VizOptions()
    graph = Graph(deployment.name)
    counters = {layer: count() for layer in LAYER_LETTER}
    pubs: list[_Pub] = []
    subs: list[tuple[_Node, PubSubEntry]] = []
    for platform in sorted(deployment.platforms.values(), key=lambda p: p.name):
        for module in sorted(platform.modules.values(), key=lambda m: m.name):
            for app in sorted(module.applications.values(), key=lambda a: a.application):
                for entry in sorted(app.entries):
                    node = _Node(platform.name, module.name, app.application, entry.thread)
                    if not _group_included(entry.group, options) or not _node_included(node, options):
                        continue
                    graph.nodes.setdefault(node.id, (node, []))
                    if entry.direction == "publishes":
                        label = f"{LAYER_LETTER[entry.layer]}{next(counters[entry.layer])}"
                        pubs.append(_Pub(node, entry, label))
                        graph.nodes[node.id][1].append(f"{label}: {entry.group} | {entry.scheme} | {entry.type}")
                    else:
                        subs.append((node, entry))
    subscribed: set[int] = set()
    for pub in pubs:
        connected = False
        for index, (sub_node, sub) in enumerate(subs):
            if not (_regex_connects(pub.entry, sub) if sub.is_regex else _connects(pub.entry, sub)):
                continue
            if not _reachable(pub.node, sub_node, pub.entry.layer):
                continue
            style = "dotted" if sub.is_regex else NECESSITY_STYLE[sub.necessity]
            graph.edges.append(
                Edge(pub.node, sub_node, pub.entry.layer, pub.entry.group, pub.entry.scheme, pub.entry.type, pub.label, style)
            )
            subscribed.add(index)
            connected = True
        if not connected and not pub.entry.inner:
            graph.disconnected_pubs.append(pub)
    graph.disconnected_subs = [s for i, s in enumerate(subs) if i not in subscribed]
    return graph


def _reachable(pub: _Node, sub: _Node, layer: str) -> bool:
    if layer == "interthread":
        return (pub.platform, pub.module, pub.application) == (sub.platform, sub.module, sub.application)
    if layer in ("interprocess", "intermodule"):
        return pub.platform == sub.platform
    return pub.platform != sub.platform  # intervehicle


def _html_name(name: str) -> str:
    return html.escape(name, quote=True).replace("&lt;", "<br/>&lt;", 1)


def _edge_line(edge: Edge, color: str) -> str:
    short = edge.group.rsplit(":", 1)[-1]
    tip = html.escape(f"{edge.label}: {edge.group} | {edge.scheme} | {edge.type}", quote=True)
    return (
        f'{edge.publisher.id}->{edge.subscriber.id}[fontsize=7,headlabel="{edge.label}",taillabel="{edge.label}",'
        f'xlabel=<{edge.label}[{html.escape(short)}]>,color="{color}",style={edge.style},tooltip="{tip}",'
        f'labeltooltip="{tip}",headtooltip="{tip}",penwidth=0.5,arrowhead=vee,arrowsize=0.3]\n'
    )


def to_dot(graph: Graph, options: VizOptions | None = None) -> str:
    """The graph as DOT text, clusters for platforms, modules and applications."""
    options = options or VizOptions()
    out = [f"digraph {escape_id(graph.name)} {{ ", f"\tsplines={options.splines}", "\tnewrank=true"]
    cluster = count()
    by_platform: dict[str, dict[str, dict[str, set[str]]]] = {}
    for node, _labels in graph.nodes.values():
        by_platform.setdefault(node.platform, {}).setdefault(node.module, {}).setdefault(node.application, set()).add(node.id)

    def edges_on(layer: str, publishers: set[str] | None = None) -> list[Edge]:
        """The edges of ``layer``, published by one of ``publishers`` if given."""
        return [e for e in graph.edges if e.layer == layer and (publishers is None or e.publisher.id in publishers)]

    def disconnected(node_ids: set[str], layer: str, indent: str) -> list[str]:
        lines = []
        if options.no_disconnected:
            subs = [(n, s) for n, s in graph.disconnected_subs if s.necessity == "required"]
            pubs: list[_Pub] = []
        else:
            subs = list(graph.disconnected_subs)
            pubs = graph.disconnected_pubs
        for pub in pubs:
            if pub.node.id in node_ids and pub.entry.layer == layer:
                color = LAYER_COLOR[layer]
                sink = f"{pub.node.id}_no_subscribers_{escape_id(color)}"
                lines.append(f'{indent}{sink} [label="",style=invis]')
                lines.append(f'{indent}{pub.node.id}->{sink}[fontsize=7,xlabel=<{pub.label}>,color="{color}",style=solid]')
        for node, sub in subs:
            if node.id in node_ids and sub.layer == layer:
                color = "red" if sub.necessity == "required" else LAYER_COLOR[layer]
                source = f"{node.id}_no_publishers_{escape_id(color)}"
                lines.append(f"{indent}{source} [label=<{html.escape(sub.group)}>,penwidth=0]")
                lines.append(f'{indent}{source}->{node.id}[fontsize=7,color="{color}",style={NECESSITY_STYLE[sub.necessity]}]')
        return lines

    for platform in sorted(by_platform):
        out += [f"\tsubgraph cluster_{next(cluster)} {{", f"\t\tlabel=<<b>{html.escape(platform)}</b>>",
                f'\t\tfontcolor="{VEHICLE_COLOR}"', "\t\tpenwidth=2", f'\t\tpencolor="{VEHICLE_COLOR}20"']
        platform_ids: set[str] = set()
        for module in sorted(by_platform[platform]):
            real_module = module != NO_MODULE
            if real_module:
                out += [f"\tsubgraph cluster_{next(cluster)} {{", f"\t\tlabel=<<b>{html.escape(module)}</b>>",
                        f'\t\tfontcolor="{MODULE_COLOR}"', "\t\tpenwidth=2", f'\t\tpencolor="{MODULE_COLOR}20"']
            for app in sorted(by_platform[platform][module]):
                ids = by_platform[platform][module][app]
                platform_ids |= ids
                out += [f"\t\tsubgraph cluster_{next(cluster)} {{", f"\t\t\tlabel=<<b>{html.escape(app)}</b>>",
                        f'\t\t\tfontcolor="{PROCESS_COLOR}"', "\t\t\tpenwidth=2", f'\t\t\tpencolor="{PROCESS_COLOR}20"']
                for edge in edges_on("interthread", ids):
                    out.append("\t\t\t" + _edge_line(edge, THREAD_COLOR))
                out += disconnected(ids, "interthread", "\t\t\t")
                out += [f'\t\t\t{node_id}[penwidth=2,color="{THREAD_COLOR}20"]' for node_id in sorted(ids)]
                out.append("\t\t}")
            if real_module:
                out.append("\t}")
        for layer in ("intermodule", "interprocess"):
            for edge in edges_on(layer, platform_ids):
                out.append("\t\t" + _edge_line(edge, LAYER_COLOR[layer]))
            out += disconnected(platform_ids, layer, "\t\t")
        out.append("\t}")
    all_ids = set(graph.nodes)
    for edge in edges_on("intervehicle"):
        out.append("\t" + _edge_line(edge, VEHICLE_COLOR))
    out += disconnected(all_ids, "intervehicle", "\t")
    for node_id in sorted(graph.nodes):
        node, labels = graph.nodes[node_id]
        style = "solid"
        parts = [f'<font color="{THREAD_COLOR}">{_html_name(node.thread)}</font><br/>']
        for label in labels:
            key, rest = label.split(": ", 1)
            group, scheme, type_name = rest.split(" | ")
            parts.append(
                f'<font color="{PROCESS_COLOR}" point-size="10">{key}: </font><b><font point-size="10">'
                f'{html.escape(group)}</font></b><br/><font point-size="6">{scheme}</font><br/>'
                f'<font point-size="8">{html.escape(type_name)}</font><br/>'
            )
        out.append(f"\t{node_id}\n [label=<{''.join(parts)}>,shape=box,style={style}]")
    out.append("}")
    return "\n".join(out) + "\n"
