"""Derive an application's interface from its source code: the role of goby_clang_tool's ``-gen``.

The analysis reads the Python source with ``ast`` and finds every ``publish``/``subscribe`` call made on a
portal layer (``...interprocess().publish(group, msg)``, ``...interthread().subscribe(group, Type, cb)``,
``subscribe_regex(...)``). Groups and types are resolved by evaluating the argument expressions in the
module's namespace (the module is imported, never run): group constants give their wire string, protobuf
classes their full name. A published message's type is found from how the variable was made in the same
function (``msg = DesiredCourse()``), from an annotation (``msg: DesiredCourse``), or through protobuf
fields (``data.node_status`` of an ``InterfaceData``). A call the analysis cannot resolve is an error that
names the file and line, so an interface file can never silently miss a call.

What the process runs besides its own modules is followed as goby_clang_tool follows template instantiations:
a thread class given to ``launch_thread`` (a class, or the result of a lookup annotated ``-> type[...]`` such as
an extension point's, which only imports) has its module analysed too; and every application class
(``SingleThreadApplication``/``MultiThreadApplication``) publishes its configuration on ``goby::configuration``
and answers health and terminate requests (``goby::health::*``, ``goby::terminate::*``), as Goby's application base
classes do.
"""

from __future__ import annotations

import ast
import importlib
import inspect
import logging
import typing
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType

from google.protobuf.message import Message

from launch.errors import LaunchError
from launch.interfaces.model import ApplicationInterface, PubSubEntry, ThreadInfo

log = logging.getLogger(__name__)

FIRST_PARTY = ("gateway", "translators", "frontseat", "behaviors", "launch")
# The transport itself publishes on internal groups (manager handshake and the like); Goby never lists those.
EXCLUDED_PACKAGES = ("gateway.goby.portal", "launch.interfaces", "gateway.moos")
LAYER_METHODS = {"interprocess": "interprocess", "interthread": "interthread", "intervehicle": "intervehicle"}


CONFIGURATION_GROUP = "goby::configuration"


def _base_class_calls() -> list[tuple[str, type, str]]:
    """What every application's base class subscribes and publishes besides its configuration (as in Goby's files):
    the health answer (gateway/goby/portal/health.py) and the terminate answer (terminate.py)."""
    from gateway.goby.portal.health import HEALTH_REQUEST, HEALTH_RESPONSE
    from gateway.goby.portal.protobuf.coroner_pb2 import HealthRequest, ProcessHealth
    from gateway.goby.portal.protobuf.terminate_pb2 import TerminateRequest, TerminateResponse
    from gateway.goby.portal.terminate import TERMINATE_REQUEST, TERMINATE_RESPONSE

    return [(str(HEALTH_REQUEST), HealthRequest, "subscribes"), (str(HEALTH_RESPONSE), ProcessHealth, "publishes"),
            (str(TERMINATE_REQUEST), TerminateRequest, "subscribes"),
            (str(TERMINATE_RESPONSE), TerminateResponse, "publishes")]


class AnalysisError(LaunchError):
    """A publish/subscribe call whose group, type or layer cannot be determined; names file and line."""


@dataclass(frozen=True)
class _Where:
    path: str
    line: int

    def __str__(self) -> str:
        return f"{self.path}:{self.line}"


def cxx_type_name(message_type: type) -> str:
    """Goby's interface files name types as C++ does: ``goby::middleware::frontseat::protobuf::NodeStatus``."""
    if issubclass(message_type, Message):
        return message_type.DESCRIPTOR.full_name.replace(".", "::")
    if message_type is str:
        return "std::string"
    raise TypeError(f"{message_type!r} is not a protobuf message class or str")


def _scheme_for(message_type: type) -> str:
    return "CSTR" if message_type is str else "PROTOBUF"


def _layer_of(node: ast.expr, aliases: dict[str, str]) -> str | None:
    """The portal layer an expression denotes: a chain ending in ``interprocess()``/``interthread()``/``intervehicle()``."""
    if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr in LAYER_METHODS:
        return LAYER_METHODS[node.func.attr]
    if isinstance(node, ast.Name):
        return aliases.get(node.id)
    if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and node.value.id == "self":
        return aliases.get(f"self.{node.attr}")
    return None


@dataclass(frozen=True)
class _Origin:
    """How a local name got its value: an annotation, or (an element of) a call's result."""

    annotation: ast.expr | None = None
    call: ast.Call | None = None
    index: int | None = None  # element of a tuple result


class _FunctionTypes:
    """Where local names of one function come from: annotations, constructor or function calls."""

    def __init__(self, func: ast.FunctionDef | ast.AsyncFunctionDef | None) -> None:
        self.origins: dict[str, _Origin] = {}
        if func is None:
            return
        for arg in [*func.args.posonlyargs, *func.args.args, *func.args.kwonlyargs]:
            if arg.annotation is not None:
                self.origins[arg.arg] = _Origin(annotation=arg.annotation)
        for node in ast.walk(func):
            if isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
                self.origins[node.target.id] = _Origin(annotation=node.annotation)
            elif isinstance(node, ast.Assign) and isinstance(node.value, ast.Call):
                for target in node.targets:
                    if isinstance(target, ast.Name):
                        self.origins.setdefault(target.id, _Origin(call=node.value))
                    elif isinstance(target, ast.Tuple):
                        for i, element in enumerate(target.elts):
                            if isinstance(element, ast.Name):
                                self.origins.setdefault(element.id, _Origin(call=node.value, index=i))


class _ModuleAnalyzer(ast.NodeVisitor):
    def __init__(self, module: ModuleType, source_path: Path, interface: ApplicationInterface) -> None:
        self.module = module
        self.path = source_path
        self.interface = interface
        self.launched_modules: list[str] = []  # modules of thread classes this code launches
        self.class_stack: list[ast.ClassDef] = []
        self.func_stack: list[ast.FunctionDef | ast.AsyncFunctionDef] = []
        self.class_aliases: dict[str, dict[str, str]] = {}

    # -- helpers ---------------------------------------------------------------------------------
    def _where(self, node: ast.AST) -> _Where:
        return _Where(str(self.path), getattr(node, "lineno", 0))

    def _namespace(self) -> dict[str, object]:
        """The module's globals plus the imports made inside the enclosing function."""
        namespace = dict(vars(self.module))
        for func in self.func_stack:
            for sub in ast.walk(func):
                if isinstance(sub, ast.ImportFrom) and sub.module and sub.level == 0:
                    for alias in sub.names:
                        try:
                            owner = importlib.import_module(sub.module)
                            value = getattr(owner, alias.name, None)
                            if value is None:
                                value = importlib.import_module(f"{sub.module}.{alias.name}")
                        except ImportError:
                            continue
                        namespace[alias.asname or alias.name] = value
                elif isinstance(sub, ast.Import):
                    for alias in sub.names:
                        try:
                            imported = importlib.import_module(alias.name)
                        except ImportError:
                            continue
                        namespace[alias.asname or alias.name.split(".")[0]] = (
                            imported if alias.asname else importlib.import_module(alias.name.split(".")[0])
                        )
        return namespace

    def _eval(self, expr: ast.expr, node: ast.AST, what: str) -> object:
        try:
            code = compile(ast.Expression(expr), str(self.path), "eval")
            return eval(code, self._namespace())  # noqa: S307 - evaluating names/attributes of our own modules
        except Exception as exc:  # any failure means we cannot resolve it statically
            raise AnalysisError(f"{self._where(node)}: cannot resolve the {what} `{ast.unparse(expr)}`: {exc}") from exc

    def _thread_name(self) -> str:
        if self.class_stack:
            return f"{self.module.__name__}.{self.class_stack[-1].name}"
        return f"{self.module.__name__}"

    def _aliases(self) -> dict[str, str]:
        aliases: dict[str, str] = {}
        if self.class_stack:
            aliases.update(self.class_aliases.get(self.class_stack[-1].name, {}))
        if self.func_stack:
            for node in ast.walk(self.func_stack[-1]):
                if isinstance(node, ast.Assign) and len(node.targets) == 1 and isinstance(node.targets[0], ast.Name):
                    layer = _layer_of(node.value, {})
                    if layer:
                        aliases[node.targets[0].id] = layer
        return aliases

    def _message_type(self, expr: ast.expr, node: ast.AST) -> type:
        """The class of a published message expression."""
        if isinstance(expr, ast.Constant) and isinstance(expr.value, str):
            return str
        if isinstance(expr, ast.Call):
            return self._call_result_type(expr, None, node)
        types = _FunctionTypes(self.func_stack[-1] if self.func_stack else None)
        if isinstance(expr, ast.Name):
            origin = types.origins.get(expr.id)
            if origin is not None and origin.annotation is not None:
                return self._as_type(self._eval(origin.annotation, node, "message type"), expr, node)
            if origin is not None and origin.call is not None:
                return self._call_result_type(origin.call, origin.index, node)
            raise AnalysisError(
                f"{self._where(node)}: cannot tell the type of published `{expr.id}`; build it in the same function "
                f"(`{expr.id} = Type(...)`) or annotate it (`{expr.id}: Type`)"
            )
        if isinstance(expr, ast.Attribute):
            owner = self._message_type(expr.value, node)
            if issubclass(owner, Message):
                field = owner.DESCRIPTOR.fields_by_name.get(expr.attr)
                if field is not None and field.message_type is not None:
                    return self._class_for(field.message_type.full_name, node)
            raise AnalysisError(f"{self._where(node)}: `{ast.unparse(expr)}` is not a message field")
        raise AnalysisError(f"{self._where(node)}: cannot tell the type of published `{ast.unparse(expr)}`")

    def _call_result_type(self, call: ast.Call, index: int | None, node: ast.AST) -> type:
        """The message type a call returns: a constructor, or a function's return annotation.

        A return annotation that is a TypeVar takes the type of the first argument (``def f(m: M) -> M``);
        ``tuple[A, B]`` results are indexed when the call is unpacked.
        """
        callee = self._callee(call.func, node)
        if isinstance(callee, type):
            return self._as_type(callee, call, node)
        try:
            hints = typing.get_type_hints(callee)
        except Exception as exc:
            raise AnalysisError(f"{self._where(node)}: cannot read the return type of `{ast.unparse(call.func)}`: {exc}") from exc
        result = hints.get("return")
        if index is not None and typing.get_origin(result) is tuple:
            args = typing.get_args(result)
            result = args[index] if index < len(args) else None
        if isinstance(result, typing.TypeVar) and call.args:
            return self._message_type(call.args[0], node)
        if isinstance(result, type) and (issubclass(result, Message) and result is not Message or result is str):
            return result
        raise AnalysisError(
            f"{self._where(node)}: `{ast.unparse(call.func)}` is not annotated with a specific message return type "
            f"(got {result!r}); annotate it, or use a TypeVar for 'same type as the argument'"
        )

    def _callee(self, func: ast.expr, node: ast.AST) -> object:
        """The function a call invokes; ``obj.method`` on a local of known class resolves through the class, and
        ``self.method`` through the enclosing class."""
        if isinstance(func, ast.Attribute) and isinstance(func.value, ast.Name) and func.value.id == "self":
            owner = getattr(self.module, self.class_stack[-1].name, None) if self.class_stack else None
            if isinstance(owner, type) and hasattr(owner, func.attr):
                return getattr(owner, func.attr)
        if isinstance(func, ast.Attribute) and isinstance(func.value, ast.Name):
            types = _FunctionTypes(self.func_stack[-1] if self.func_stack else None)
            origin = types.origins.get(func.value.id)
            if origin is not None and origin.annotation is not None:
                owner = self._eval(origin.annotation, node, "receiver type")
                if isinstance(owner, type) and hasattr(owner, func.attr):
                    return getattr(owner, func.attr)
        return self._eval(func, node, "callee")

    def _class_for(self, full_name: str, node: ast.AST) -> type:
        from google.protobuf import symbol_database

        try:
            return symbol_database.Default().GetSymbol(full_name)
        except KeyError as exc:
            raise AnalysisError(f"{self._where(node)}: message type {full_name} is not loaded") from exc

    def _as_type(self, value: object, expr: ast.expr, node: ast.AST) -> type:
        if isinstance(value, type) and (issubclass(value, Message) or value is str):
            return value
        raise AnalysisError(f"{self._where(node)}: `{ast.unparse(expr)}` is not a protobuf message class")

    def _group(self, expr: ast.expr, node: ast.AST) -> str:
        value = self._eval(expr, node, "group")
        text = str(value)
        if not text:
            raise AnalysisError(f"{self._where(node)}: empty group `{ast.unparse(expr)}`")
        return text

    def _literal(self, expr: ast.expr | None, default: str, node: ast.AST) -> str:
        if expr is None:
            return default
        return str(self._eval(expr, node, "regular expression"))

    @staticmethod
    def _arg(call: ast.Call, index: int, keyword: str) -> ast.expr | None:
        for kw in call.keywords:
            if kw.arg == keyword:
                return kw.value
        return call.args[index] if len(call.args) > index else None

    # -- visiting --------------------------------------------------------------------------------
    def visit_ClassDef(self, node: ast.ClassDef) -> None:
        aliases: dict[str, str] = {}
        for sub in ast.walk(node):
            if isinstance(sub, ast.Assign) and len(sub.targets) == 1:
                target = sub.targets[0]
                if isinstance(target, ast.Attribute) and isinstance(target.value, ast.Name) and target.value.id == "self":
                    layer = _layer_of(sub.value, {})
                    if layer:
                        aliases[f"self.{target.attr}"] = layer
        self.class_aliases[node.name] = aliases
        self.class_stack.append(node)
        self._announce_configuration(node)
        self.generic_visit(node)
        self.class_stack.pop()

    def _announce_configuration(self, node: ast.ClassDef) -> None:
        """An application class publishes its config type on ``goby::configuration`` (portal/application.py)."""
        from gateway.goby.portal.application import _Application

        cls = getattr(self.module, node.name, None)
        if not (isinstance(cls, type) and issubclass(cls, _Application)):
            return
        try:
            config_type = typing.get_type_hints(cls.__init__).get("cfg")
        except Exception as exc:
            raise AnalysisError(f"{self._where(node)}: cannot read the config type of {node.name}: {exc}") from exc
        if not (isinstance(config_type, type) and issubclass(config_type, Message)):
            raise AnalysisError(f"{self._where(node)}: annotate {node.name}.__init__'s cfg with its config message "
                                "type (it is published on goby::configuration)")
        if "interprocess" not in config_type.DESCRIPTOR.fields_by_name:
            return
        thread = self._thread_name()
        self._note_thread(thread)
        self.interface.add(PubSubEntry("interprocess", thread, CONFIGURATION_GROUP, "PROTOBUF",
                                       cxx_type_name(config_type), "publishes"))
        for group, message_type, direction in _base_class_calls():
            self.interface.add(PubSubEntry("interprocess", thread, group, "PROTOBUF", cxx_type_name(message_type),
                                           direction))

    def _launched_class(self, expr: ast.expr, node: ast.AST) -> type:
        """The class a ``launch_thread`` call starts: a class expression, or a local set by a class lookup."""
        if isinstance(expr, ast.Name):
            origin = _FunctionTypes(self.func_stack[-1] if self.func_stack else None).origins.get(expr.id)
            if origin is not None and origin.call is not None:
                callee = self._callee(origin.call.func, node)
                result = typing.get_type_hints(callee).get("return") if callable(callee) else None
                if typing.get_origin(result) is not type:
                    raise AnalysisError(f"{self._where(node)}: `{ast.unparse(origin.call.func)}` must be annotated "
                                        "`-> type[...]` for the analysis to follow the thread it launches")
                value = self._eval(origin.call, node, "launched thread class")
            else:
                value = self._eval(expr, node, "launched thread class")
        else:
            value = self._eval(expr, node, "launched thread class")
        if not isinstance(value, type):
            raise AnalysisError(f"{self._where(node)}: `{ast.unparse(expr)}` is not a thread class")
        return value

    def visit_FunctionDef(self, node: ast.FunctionDef) -> None:
        self.func_stack.append(node)
        self.generic_visit(node)
        self.func_stack.pop()

    visit_AsyncFunctionDef = visit_FunctionDef  # type: ignore[assignment]

    def visit_Call(self, node: ast.Call) -> None:
        self.generic_visit(node)
        func = node.func
        if isinstance(func, ast.Attribute) and func.attr == "launch_thread" and node.args:
            launched = self._launched_class(node.args[0], node)
            if launched.__module__ != self.module.__name__:
                self.launched_modules.append(launched.__module__)
            return
        if not isinstance(func, ast.Attribute) or func.attr not in ("publish", "subscribe", "subscribe_regex"):
            return
        layer = _layer_of(func.value, self._aliases())
        if layer is None:
            return
        thread = self._thread_name()
        self._note_thread(thread)
        if func.attr == "subscribe_regex":
            group_regex = self._literal(self._arg(node, 1, "group_regex"), ".*", node)
            type_regex = self._literal(self._arg(node, 2, "type_regex"), ".*", node)
            self.interface.add(PubSubEntry(layer, thread, group_regex, "ALL_SCHEMES", type_regex, "subscribes", is_regex=True))
            return
        group_expr = self._arg(node, 0, "group")
        if group_expr is None:
            raise AnalysisError(f"{self._where(node)}: {func.attr} call without a group")
        group = self._group(group_expr, node)
        if func.attr == "publish":
            msg_expr = self._arg(node, 1, "msg")
            if msg_expr is None:
                raise AnalysisError(f"{self._where(node)}: publish call without a message")
            message_type = self._message_type(msg_expr, node)
            direction = "publishes"
        else:
            type_expr = self._arg(node, 1, "msg_type")
            if type_expr is None:
                raise AnalysisError(f"{self._where(node)}: subscribe call without a message type")
            message_type = self._as_type(self._eval(type_expr, node, "message type"), type_expr, node)
            direction = "subscribes"
        # intervehicle carries DCCL only (Goby's InterVehicleForwarder/Portal are DCCL-only transporters)
        scheme = {"interthread": "CXX_OBJECT", "intervehicle": "DCCL"}.get(layer) or _scheme_for(message_type)
        self.interface.add(PubSubEntry(layer, thread, group, scheme, cxx_type_name(message_type), direction))

    def _note_thread(self, thread: str) -> None:
        if not self.class_stack or thread in self.interface.threads and self.interface.threads[thread].bases:
            return
        cls = getattr(self.module, self.class_stack[-1].name, None)
        bases = [f"{b.__module__}.{b.__qualname__}" for b in inspect.getmro(cls)[1:] if b is not object] if cls else []
        self.interface.threads[thread] = ThreadInfo(thread, known=cls is not None, bases=bases)


def _first_party_imports(tree: ast.AST) -> set[str]:
    names: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names.add(node.module)
            names.update(f"{node.module}.{alias.name}" for alias in node.names)
    return {n for n in names if n.split(".")[0] in FIRST_PARTY}


def _is_excluded(module_name: str) -> bool:
    return any(module_name == p or module_name.startswith(p + ".") for p in EXCLUDED_PACKAGES)


def analyze_modules(application: str, module_names: list[str], follow_imports: bool = False) -> ApplicationInterface:
    """Analyze ``module_names`` and, if asked, the modules they import from their own top-level package.

    Following stays inside the application's own package, as goby_clang_tool sees only the target's sources:
    a thread class that lives in another package (say, a translator the frontseat interface launches) is
    listed in that package's own interface file.
    """
    interface = ApplicationInterface(application)
    own_packages = {name.split(".")[0] for name in module_names}
    pending = list(module_names)
    seen: set[str] = set()
    while pending:
        name = pending.pop(0)
        if name in seen or _is_excluded(name) or name.endswith("_pb2"):
            continue
        seen.add(name)
        try:
            module = importlib.import_module(name)
        except ModuleNotFoundError:
            continue  # `from pkg import name` where name is not a module
        source = getattr(module, "__file__", None)
        if not source or not source.endswith(".py"):
            continue
        tree = ast.parse(Path(source).read_text(), source)
        log.debug("analyzing %s", source)
        analyzer = _ModuleAnalyzer(module, Path(source), interface)
        analyzer.visit(tree)
        pending.extend(analyzer.launched_modules)
        if follow_imports:
            pending.extend(sorted(n for n in _first_party_imports(tree) if n.split(".")[0] in own_packages))
    return interface
