"""Plugin modules the gateway tests write to a temp dir (real files, loaded by path as users do)."""

from __future__ import annotations

ECHO_PLUGIN = '''
"""Test plugin: MOOS IN (+ buffered B) -> Goby "from_moos"; Goby "to_moos" -> MOOS OUT (twice: upper and lower)."""
from translators.base import Translator


class EchoTranslator(Translator):
    def __init__(self, cfg):
        super().__init__(cfg)
        self.moos().add_buffer("B")
        self.moos().add_trigger("IN", self.on_in)
        self.goby().interprocess().subscribe("to_moos", str, self.on_goby)

    def on_in(self, msg):
        b = self.moos().buffer().get("B")
        self.goby().interprocess().publish("from_moos", msg.string() + "|" + (b.string() if b else "none"))

    def on_goby(self, text):
        self.moos().comms().notify("OUT", text.upper())
        self.moos().comms().notify("OUT_LOWER", text.lower())


def load(gateway):
    gateway.launch_thread(EchoTranslator)


def unload(gateway):
    gateway.join_thread(EchoTranslator)
'''

NO_LOAD_PLUGIN = '''
def start(gateway):
    pass
'''

RAISING_LOAD_PLUGIN = '''
def load(gateway):
    raise ValueError("the plugin refuses to start")
'''

IMPORT_ERROR_PLUGIN = '''
import no_such_dependency_xyz  # noqa: F401

def load(gateway):
    pass
'''

THREADS_PLUGIN = '''
"""Test plugin: MOOS WHO -> MOOS THREADS, a JSON report of the thread that handled it and every thread alive."""
import json
import threading

from translators.base import Translator


class ThreadsTranslator(Translator):
    def __init__(self, cfg):
        super().__init__(cfg)
        self.constructed_on = threading.get_ident()
        self.moos().add_trigger("WHO", self.on_who)

    def on_who(self, msg):
        self.moos().comms().notify("THREADS", json.dumps({
            "constructed_on": self.constructed_on,
            "handled_on": threading.get_ident(),
            "handler_thread": threading.current_thread().name,
            "threads": sorted(t.name for t in threading.enumerate()),
        }))


def load(gateway):
    gateway.launch_thread(ThreadsTranslator)
'''
