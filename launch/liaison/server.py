"""The web side of goby-liaison: aiohttp on its own thread and event loop, pages and one WebSocket per page.

Threads: :class:`WebServer` runs an asyncio loop on the thread ``liaison-web``.  The portal thread never waits
for it: the portal side writes into the models (``ScopeModel.ingest``, ``MapModel.ingest_*``: a lock held for a
dict update) and reports command outcomes with :meth:`WebServer.call` (``loop.call_soon_threadsafe``).  The web
thread hands commands to the portal thread with the ``publish`` callable it was given (the portal thread's
``call_soon``).  Every ``1/update_freq`` s the ticker reads the models (coalescing whatever arrived) and offers
one update per view to each page's bounded queue (``fanout.Browser``).
"""

from __future__ import annotations

import asyncio
import logging
import threading
import time
from collections.abc import Awaitable, Callable
from importlib import resources
from pathlib import Path
from typing import Any

from aiohttp import WSMsgType, web

from launch.liaison.commander_model import CommanderModel, CommandType, SentCommand, Target
from launch.liaison.errors import CommandRefused, LiaisonError
from launch.liaison.fanout import MATCH_BUDGET_S, VIEWS, Browser
from launch.liaison.form_values import build_command
from launch.liaison.http_guard import SECURITY_HEADERS, HostGuard
from launch.liaison.map_model import POLYGON_RADIUS_M, POLYGON_SIDES, USV_COMMAND_TYPE, MapModel
from launch.liaison.name_filter import compile_filter
from launch.liaison.page_messages import PageMessageError, encode, float_field, int_field, parse, str_field
from launch.liaison.replay import ReplayCache, ReplayError, ReplayLog, list_logs, resolve
from launch.liaison.scope_model import ScopeModel
from launch.liaison.settings import LiaisonSettings
from util.ratelimit import RateLimitedLog

log = logging.getLogger(__name__)

STATIC_DIR = Path(str(resources.files("launch.liaison") / "static"))
MAX_WS_MESSAGE = 256 * 1024  # bytes a page may send in one WebSocket message
HISTORY_ITEMS_SENT = 100
SEND_RATE_LIMIT = 20  # commands a page may send per second
MAX_COMMENT_CHARS = 1000
MAX_FILTER_CHARS = 256
MAX_REPLAY_NAME_CHARS = 1024
MAX_REPLAY_TRAIL_S = 86_400.0  # seconds of trail a replay frame may ask for
MAX_LOG_TIME_S = 1e11  # a replay time (s since the epoch) beyond this is refused
#: Publishes a command on the portal thread: (type, target, message, entry id) -> None; never blocks.
Publish = Callable[[CommandType, Target, Any, int], None]


_bad_input = RateLimitedLog(log, period_s=10.0)


def _json(obj: Any) -> str:
    """JSON for the pages; a non-finite number (which a model should have refused) becomes null, logged."""
    text, replaced = encode(obj)
    if replaced:
        _bad_input.warning("non-finite", "a non-finite number reached the page's JSON: sent as null")
    return text


class WebServer:
    """Serves the pages of one liaison; ``start()`` binds (LiaisonError if it cannot), ``stop()`` is idempotent."""

    def __init__(self, settings: LiaisonSettings, scope: ScopeModel, commander: CommanderModel, map_model: MapModel,
                 publish: Publish, clock_now: Callable[[], float]) -> None:
        self.settings = settings
        self.scope = scope
        self.commander = commander
        self.map = map_model
        self._publish = publish
        self._now = clock_now
        self.browsers: set[Browser] = set()
        self.port: int | None = None
        self._loop: asyncio.AbstractEventLoop | None = None
        self._thread: threading.Thread | None = None
        self._ready = threading.Event()
        self._error: BaseException | None = None
        self._stop: asyncio.Event | None = None
        self._notify_rules = [(compile_filter(g, "group"), compile_filter(t, "type")) for g, t in settings.notify]
        self.guard = HostGuard(settings.http_address, settings.allowed_hosts)
        self.refused_requests = 0  # HTTP/WebSocket requests refused for their Host or Origin
        self._notified: dict[int, int] = {}  # row id -> count when last notified
        self._replay_cache = ReplayCache(settings.replay_max_samples)
        self._replays: dict[Browser, ReplayLog] = {}  # the log each page replays
        self._replay_loading: set[Browser] = set()
        self.ticks = 0

    # ------------------------------------------------------------------------------------- lifecycle
    def start(self, timeout_s: float = 10.0) -> None:
        """Start the web thread and bind; raises LiaisonError naming the address when the bind fails."""
        self._thread = threading.Thread(target=self._run, name="liaison-web", daemon=True)
        self._thread.start()
        if not self._ready.wait(timeout_s):
            raise LiaisonError(f"the web server did not start within {timeout_s:g} s")
        if self._error is not None:
            self._thread.join()
            where = f"{self.settings.http_address}:{self.settings.http_port}"
            raise LiaisonError(f"cannot serve http on {where} (http_address, http_port): {self._error}")

    def stop(self) -> None:
        if self._thread is None:
            return
        if self._loop is not None and self._stop is not None:
            try:
                self._loop.call_soon_threadsafe(self._stop.set)
            except RuntimeError:
                pass  # the loop has already closed
        self._thread.join(15.0)
        if self._thread.is_alive():
            log.error("the web thread did not stop within 15 s")
        self._thread = None

    def call(self, fn: Callable[..., Any], *args: Any) -> None:
        """Run ``fn(*args)`` on the web thread; callable from any thread, never blocks, dropped once stopped."""
        loop = self._loop
        if loop is None or loop.is_closed():
            return
        try:
            loop.call_soon_threadsafe(fn, *args)
        except RuntimeError:
            pass  # stopping

    @property
    def urls(self) -> dict[str, str]:
        host = self.settings.http_address
        shown = "127.0.0.1" if host in ("", "0.0.0.0", "::") else host
        base = f"http://{shown}:{self.port}"
        return {"home": f"{base}/", "scope": f"{base}/?_=/scope", "commander": f"{base}/?_=/commander",
                "map": f"{base}/?_=/map"}

    def _run(self) -> None:
        loop = asyncio.new_event_loop()
        self._loop = loop
        try:
            loop.run_until_complete(self._serve())
        except BaseException as exc:  # noqa: BLE001 - reported to start() or logged
            if not self._ready.is_set():
                self._error = exc
                self._ready.set()
            else:
                log.exception("the web server failed")
        finally:
            loop.run_until_complete(loop.shutdown_asyncgens())
            loop.run_until_complete(loop.shutdown_default_executor())  # aiohttp reads static files on it
            loop.close()

    async def _serve(self) -> None:
        self._stop = asyncio.Event()
        app = web.Application(client_max_size=MAX_WS_MESSAGE, middlewares=[self._guard_middleware])
        app.on_response_prepare.append(_add_security_headers)
        app.router.add_get("/", self._page)
        for view in ("scope", "commander", "map"):
            app.router.add_get(f"/{view}", self._page)
        app.router.add_get("/ws", self._websocket)
        app.router.add_get("/api/urls", self._api_urls)
        app.router.add_get("/favicon.ico", self._favicon)
        app.router.add_get("/map/background", self._background)
        app.router.add_static("/static/", STATIC_DIR, show_index=False)
        runner = web.AppRunner(app, handle_signals=False, access_log=None, shutdown_timeout=1.0)
        await runner.setup()
        site = web.TCPSite(runner, self.settings.http_address or None, self.settings.http_port,
                           reuse_address=True)
        try:
            await site.start()
        except OSError:
            await runner.cleanup()
            raise
        server = getattr(site, "_server", None)
        sockets = getattr(server, "sockets", None) or []
        self.port = sockets[0].getsockname()[1] if sockets else self.settings.http_port
        self._ready.set()
        log.info("serving http on port %d for host names %s (and the address a connection arrives on)", self.port,
                 self.guard.describe())
        ticker = asyncio.ensure_future(self._ticker())
        try:
            await self._stop.wait()
        finally:
            ticker.cancel()
            for browser in list(self.browsers):
                await browser.ws.close(code=1001, message=b"goby-liaison is stopping")
            await runner.cleanup()

    # ------------------------------------------------------------------------------------------ pages
    async def _page(self, request: web.Request) -> web.StreamResponse:
        return web.FileResponse(STATIC_DIR / "index.html", headers={"Cache-Control": "no-cache"})

    async def _favicon(self, request: web.Request) -> web.StreamResponse:
        return web.FileResponse(STATIC_DIR / "favicon.svg", headers={"Content-Type": "image/svg+xml"})

    async def _background(self, request: web.Request) -> web.StreamResponse:
        """The configured background image of the map (the only file served besides the page's own)."""
        if self.settings.background is None:
            raise web.HTTPNotFound(text="no background image is configured ([goby_moos_py.liaison.protobuf.web] "
                                        "map.background)")
        return web.FileResponse(self.settings.background.path, headers={"Cache-Control": "no-cache"})

    async def _api_urls(self, request: web.Request) -> web.Response:
        return web.json_response(self.urls)

    @web.middleware
    async def _guard_middleware(self, request: web.Request,
                                handler: Callable[[web.Request], Awaitable[web.StreamResponse]]) -> web.StreamResponse:
        """Every request: refuse a Host this server is not served under (DNS rebinding) with 421, and an Origin
        of another site with 403 (WebSockets ignore the same-origin policy)."""
        sockname = request.transport.get_extra_info("sockname") if request.transport is not None else None
        local = str(sockname[0]) if sockname else None
        host = request.headers.get("Host")
        if not self.guard.host_allowed(host, local):
            self.refused_requests += 1
            _bad_input.warning(("host", request.remote), "refused a request from %s for Host %r (not one of %s; "
                               "[goby_moos_py.liaison.protobuf.web] allowed_host)", request.remote, host,
                               self.guard.describe())
            return web.Response(status=421, text=f"this server does not serve host {host!r}: browse to it by one of "
                                f"{self.guard.describe()}, or add the name to [goby_moos_py.liaison.protobuf.web] "
                                "allowed_host")
        origin = request.headers.get("Origin")
        if origin is not None and not self.guard.origin_allowed(origin, local):
            self.refused_requests += 1
            _bad_input.warning(("origin", request.remote), "refused a request from %s with Origin %r", request.remote,
                               origin)
            return web.Response(status=403, text=f"origin {origin} may not use this page")
        return await handler(request)

    # -------------------------------------------------------------------------------------- websocket
    async def _websocket(self, request: web.Request) -> web.StreamResponse:
        if len(self.browsers) >= self.settings.max_clients:
            return web.Response(status=503, text=f"too many pages open ({self.settings.max_clients}, "
                                                 "[goby_moos_py.liaison.protobuf.web] max_clients): close one")
        ws = web.WebSocketResponse(max_msg_size=MAX_WS_MESSAGE, compress=False, heartbeat=20.0)
        await ws.prepare(request)
        browser = Browser(ws, request.remote or "?", self.settings.client_queue)
        browser.paused = self.settings.start_paused
        browser.set_filters(self.settings.group_filter, self.settings.type_filter)
        self.browsers.add(browser)
        sender = asyncio.ensure_future(browser.send_loop())
        sent_times: list[float] = []
        try:
            browser.reply(_json(self._hello()))
            async for message in ws:
                if message.type == WSMsgType.TEXT:
                    self._handle(browser, message.data, sent_times)
                elif message.type == WSMsgType.BINARY:
                    self._reply(browser, "error", error="binary messages are not understood: send JSON text")
                elif message.type == WSMsgType.ERROR:
                    log.info("browser %s: %s", browser.address, ws.exception())
                await browser.replies_drained()  # a page that sends but does not read is no longer read
        finally:
            self.browsers.discard(browser)
            self._replays.pop(browser, None)
            sender.cancel()
        return ws

    def _hello(self) -> dict[str, Any]:
        s = self.settings
        return {"op": "hello", "title": s.title, "views": s.views, "update_freq": s.update_freq,
                "start_paused": s.start_paused, "filters": {"group": s.group_filter, "type": s.type_filter},
                "max_history": s.max_history, "history_groups": s.history_groups}

    def _reply(self, browser: Browser, op: str, **fields: Any) -> None:
        """The answer to one page message: on the reply queue, which is never dropped."""
        browser.reply(_json({"op": op, **fields}))

    def _handle(self, browser: Browser, text: str, sent_times: list[float]) -> None:
        """One message from a page: every message gets an answer, a bad one an ``error`` naming the cause."""
        try:
            request = parse(text)
        except PageMessageError as exc:
            self._reply(browser, "error", error=str(exc))
            return
        op = request["op"]
        handler = {
            "subscribe": self._on_subscribe, "filter": self._on_filter, "pause": self._on_pause,
            "resume": self._on_resume, "expand": self._on_expand, "collapse": self._on_collapse,
            "send": lambda b, r: self._on_send(b, r, sent_times),
            "replay_list": self._on_replay_list, "replay_open": self._on_replay_open,
            "replay_seek": self._on_replay_seek, "replay_close": self._on_replay_close,
        }.get(op)
        if handler is None:
            self._reply(browser, "error", error=f"unknown op {op!r}")
            return
        try:
            handler(browser, request)
        except (KeyError, TypeError, ValueError, ArithmeticError) as exc:
            self._reply(browser, "error", op_failed=op, error=f"bad {op} request: {exc}")
        except Exception as exc:  # noqa: BLE001 - a bug must cost one reply, not the connection
            _bad_input.error(("handler", op), "page message %r failed: %s: %s", op, type(exc).__name__, exc)
            self._reply(browser, "error", op_failed=op, error=f"{op} failed on the server: {type(exc).__name__}")

    def _on_subscribe(self, browser: Browser, request: dict[str, Any]) -> None:
        views = request.get("views")
        if not isinstance(views, list) or not all(isinstance(v, str) for v in views):
            raise ValueError('"views" must be a list of view names')
        unknown = set(views) - VIEWS
        if unknown:
            raise ValueError(f"unknown view(s) {', '.join(sorted(unknown))} (known: {', '.join(sorted(VIEWS))})")
        browser.views = set(views)
        self._reply(browser, "subscribed", views=sorted(browser.views))
        for view in browser.views:
            self._send_full(browser, view)

    def _on_filter(self, browser: Browser, request: dict[str, Any]) -> None:
        group = str_field(request, "group", ".*", MAX_FILTER_CHARS)
        type_ = str_field(request, "type", ".*", MAX_FILTER_CHARS)
        browser.set_filters(group, type_)  # ValueError names the bad expression
        self._reply(browser, "filter", group=group, type=type_)
        self._send_full(browser, "scope")

    def _on_pause(self, browser: Browser, request: dict[str, Any]) -> None:
        browser.paused = True
        self._reply(browser, "paused", paused=True)

    def _on_resume(self, browser: Browser, request: dict[str, Any]) -> None:
        browser.paused = False
        self._reply(browser, "paused", paused=False)
        self._send_full(browser, "scope")

    def _on_expand(self, browser: Browser, request: dict[str, Any]) -> None:
        row_id = int_field(request, "id")
        items = self.scope.history(row_id, HISTORY_ITEMS_SENT)
        if items is None:
            raise ValueError(f"no scope row {row_id}")
        browser.expanded.add(row_id)
        self._reply(browser, "history", id=row_id, items=items)

    def _on_collapse(self, browser: Browser, request: dict[str, Any]) -> None:
        browser.expanded.discard(int_field(request, "id"))
        self._reply(browser, "collapsed", id=request["id"])

    # ------------------------------------------------------------------------------------------ replay
    def _on_replay_list(self, browser: Browser, request: dict[str, Any]) -> None:
        folders = self.settings.replay_dirs
        self._reply(browser, "replay_list", logs=list_logs(folders), folders=[str(f) for f in folders])

    def _on_replay_open(self, browser: Browser, request: dict[str, Any]) -> None:
        name = str_field(request, "name", "", MAX_REPLAY_NAME_CHARS)
        if browser in self._replay_loading:
            raise ValueError("a log is being opened already: wait for it")
        try:
            path = resolve(self.settings.replay_dirs, name)
        except ReplayError as exc:
            self._reply(browser, "replay_error", error=str(exc))
            return
        self._replay_loading.add(browser)
        asyncio.ensure_future(self._open_replay(browser, path, name))

    async def _open_replay(self, browser: Browser, path: Path, name: str) -> None:
        """Load a log on an executor thread (a large one must not stall the pages), then tell the page."""
        try:
            replay = await asyncio.get_running_loop().run_in_executor(None, self._replay_cache.load, path, name)
        except ReplayError as exc:
            self._reply(browser, "replay_error", error=str(exc))
            return
        except Exception as exc:  # noqa: BLE001 - a bug must cost one reply, not the server
            log.exception("replay of %s failed", name)
            self._reply(browser, "replay_error", error=f"{name}: {type(exc).__name__}: {exc}")
            return
        finally:
            self._replay_loading.discard(browser)
        if browser in self.browsers:
            self._replays[browser] = replay
            self._reply(browser, "replay_opened", **replay.summary())

    def _on_replay_seek(self, browser: Browser, request: dict[str, Any]) -> None:
        replay = self._replays.get(browser)
        if replay is None:
            raise ValueError("no log is open: send replay_open first")
        when = float_field(request, "t", -MAX_LOG_TIME_S, MAX_LOG_TIME_S)
        trail_s = float_field(request, "trail_s", 0.0, MAX_REPLAY_TRAIL_S) if "trail_s" in request else 600.0
        self._reply(browser, "replay_frame", **replay.frame(when, trail_s))

    def _on_replay_close(self, browser: Browser, request: dict[str, Any]) -> None:
        self._replays.pop(browser, None)
        self._reply(browser, "replay_closed")

    def _map_command(self) -> dict[str, Any] | None:
        """What the map's command tool sends: the commander's USVCommand type, its targets and DCCL bounds."""
        kind = self.commander.types.get(USV_COMMAND_TYPE)
        if kind is None or not kind.targets:
            return None
        return {"type": kind.name, "targets": [{"index": t.index, "label": t.label} for t in kind.targets],
                "sides": list(POLYGON_SIDES), "radius": list(POLYGON_RADIUS_M)}

    def _on_send(self, browser: Browser, request: dict[str, Any], sent_times: list[float]) -> None:
        now = time.monotonic()
        sent_times[:] = [t for t in sent_times if now - t < 1.0]
        if len(sent_times) >= SEND_RATE_LIMIT:
            self._reply(browser, "refused", field="", error=f"more than {SEND_RATE_LIMIT} commands a second")
            return
        try:
            comment = str_field(request, "comment", "", MAX_COMMENT_CHARS)
            kind, target, msg = self._check_command(request)
        except PageMessageError as exc:
            self._reply(browser, "refused", field="comment", error=str(exc))
            return
        except CommandRefused as exc:
            self._reply(browser, "refused", field=exc.field, error=str(exc))
            return
        sent_times.append(now)
        entry = self.commander.record(kind, target, msg, browser.address, comment, self._now())
        self._reply(browser, "accepted", id=entry.id, text=entry.text, target=entry.target)
        self._publish(kind, target, msg, entry.id)
        self._broadcast_sent([entry])

    def _check_command(self, request: dict[str, Any]) -> tuple[CommandType, Target, Any]:
        name = request.get("type")
        kind = self.commander.types.get(name) if isinstance(name, str) else None
        if kind is None:
            raise CommandRefused(f"type {name!r} is not in the configured list "
                                 f"({', '.join(sorted(self.commander.types)) or 'none'})", "type")
        index = request.get("target")
        if not isinstance(index, int) or isinstance(index, bool) or not 0 <= index < len(kind.targets):
            allowed = "; ".join(f"{t.index}: {t.label}" for t in kind.targets) or "none configured"
            raise CommandRefused(f"target {index!r} is not a configured publish_to of {name} ({allowed})", "target")
        msg = build_command(kind.cls, request.get("values", {}), self._now)
        return kind, kind.targets[index], msg

    # -------------------------------------------------------------------- outcomes (scheduled by portal)
    def command_published(self, entry_id: int, error: str | None) -> None:
        """The portal thread published a command (or failed). Web thread."""
        entry = self.commander.published(entry_id, error)
        if entry is not None:
            self._broadcast_sent([entry])

    def command_acknowledged(self, entry_id: int, text: str) -> None:
        """The layer acknowledged a command (intervehicle). Web thread."""
        entry = self.commander.acknowledged(entry_id, text)
        if entry is not None:
            self._broadcast_sent([entry])

    def command_expired(self, entry_id: int, text: str) -> None:
        """The layer gave up on a command (intervehicle). Web thread."""
        entry = self.commander.expired(entry_id, text)
        if entry is not None:
            self._broadcast_sent([entry])

    def interprocess_ack(self, type_name: str, value: Any, text: str, final: bool, refused: bool) -> None:
        """An ack message of a configured ``interprocess_ack`` rule arrived. Web thread."""
        entry = self.commander.interprocess_ack(type_name, value, text, final, refused)
        if entry is not None:
            self._broadcast_sent([entry])

    # ----------------------------------------------------------------------------------------- fan-out
    def _broadcast_sent(self, entries: list[SentCommand]) -> None:
        text = _json({"op": "sent", "entries": [e.view() for e in entries], "full": False})
        for browser in self.browsers:
            for view in ("commander", "map"):  # the map shows the last command's state beside the vehicle
                if view in browser.views:
                    browser.offer(text, view)

    def _send_full(self, browser: Browser, view: str, deadline: float | None = None) -> None:
        """A whole view; the scope waits for a later tick when matching its filters is over budget."""
        if view == "scope":
            if not browser.paused:
                rows = browser.visible(self.scope.views(), deadline)
                if rows is None:  # matching took its time budget: the ticks go on until it is done
                    browser.needs_resync.add("scope")
                    return
                browser.offer(_json({"op": "scope", "rows": rows, "full": True}), "scope")
        elif view == "commander":
            browser.offer(_json({"op": "commands", "types": self.commander.catalogue()}), "commander")
            browser.offer(_json({"op": "sent", "entries": [e.view() for e in self.commander.history],
                                 "full": True}), "commander")
        elif view == "map":
            browser.offer(_json({"op": "map", "full": True, **self.map.snapshot(), "command": self._map_command(),
                                 "replay": bool(self.settings.replay_dirs)}), "map")
            last = [self.commander.history[-1]] if self.commander.history else []
            browser.offer(_json({"op": "sent", "entries": [e.view() for e in last], "full": True}), "map")
        browser.needs_resync.discard(view)

    async def _ticker(self) -> None:
        period = 1.0 / self.settings.update_freq
        next_at = time.monotonic()
        while True:
            next_at += period
            await asyncio.sleep(max(0.0, next_at - time.monotonic()))
            if time.monotonic() - next_at > period:
                next_at = time.monotonic()  # fell behind: skip, do not burst
            try:
                self.tick()
            except Exception:  # noqa: BLE001 - a bug in one tick must not stop the page
                log.exception("liaison tick failed")

    def tick(self) -> None:
        """Read the models and offer each page what changed. Web thread."""
        self.ticks += 1
        now = time.monotonic()
        rows = self.scope.tick(now)
        map_update = self.map.tick()
        expired = self.commander.expire_due(now)
        if expired:
            self._broadcast_sent(expired)
        notices = self._notifications(rows)
        by_filter: dict[tuple[str, str], str] = {}
        changed_ids = {int(r["id"]) for r in rows}
        map_text = _json({"op": "map", "full": False, **map_update}) if map_update else None
        browsers = list(self.browsers)
        turn = self.ticks % len(browsers) if browsers else 0
        deadline = time.perf_counter() + MATCH_BUDGET_S  # for matching filters, all pages together
        for browser in browsers[turn:] + browsers[:turn]:  # who goes first (and gets the match budget) rotates
            for view in list(browser.needs_resync):
                if browser.has_room():
                    self._send_full(browser, view, deadline)
            if "scope" in browser.views and rows and not browser.paused and "scope" not in browser.needs_resync:
                self._offer_scope(browser, rows, changed_ids, by_filter, deadline)
            if map_text and "map" in browser.views and "map" not in browser.needs_resync:
                browser.offer(map_text, "map")
            if notices and "commander" in browser.views:
                browser.offer(_json({"op": "notify", "items": notices}), "commander")

    def _offer_scope(self, browser: Browser, rows: list[dict[str, Any]], changed_ids: set[int],
                     by_filter: dict[tuple[str, str], str], deadline: float) -> None:
        """The rows of this tick that pass the page's filters (one JSON text per distinct filter)."""
        key = browser.filter_key
        text = by_filter.get(key)
        if text is None:
            shown = browser.visible(rows, deadline)
            if shown is None:  # out of match budget this tick: a full resync follows
                browser.needs_resync.add("scope")
                return
            text = by_filter[key] = _json({"op": "scope", "rows": shown, "full": False}) if shown else ""
        if text:
            browser.offer(text, "scope")
        for row_id in browser.expanded & changed_ids:
            items = self.scope.history(row_id, HISTORY_ITEMS_SENT)
            if items is not None:
                browser.offer(_json({"op": "history", "id": row_id, "items": items}), "scope")

    def _notifications(self, rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
        if not self._notify_rules:
            return []
        notices = []
        for row in rows:
            if self._notified.get(row["id"]) == row["count"]:
                continue  # re-sent for its rate only
            if any(g.fullmatch(row["group"]) and t.fullmatch(row["type"]) for g, t in self._notify_rules):
                self._notified[row["id"]] = row["count"]
                notices.append({"group": row["group"], "type": row["type"], "time": row["time"],
                                "value": row["value"]})
        return notices


async def _add_security_headers(request: web.Request, response: web.StreamResponse) -> None:
    """Every response: a CSP without inline code, no framing, no sniffing, no referrer."""
    response.headers.update(SECURITY_HEADERS)
