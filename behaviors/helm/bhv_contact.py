"""IvPContactBehavior (pHelmIvP 19.8.1): the common part of behaviours about one named contact.

Each iteration :meth:`ContactBehavior.update_platform_info` reads ownship's ``NAV_*`` and the contact's
``<CONTACT>_NAV_X/_Y/_HEADING/_SPEED/_UTC`` from the info buffer (written from NODE_REPORTs by
:class:`behaviors.helm.contacts.ContactTable`), and, with ``extrapolate``, moves the contact along its heading to
the helm's time with :class:`behaviors.helm.contacts.LinearExtrapolator`.
"""

from __future__ import annotations

import math
from typing import Any

from .behavior import Behavior, parse_bool, parse_float
from .contacts import LinearExtrapolator
from .errors import ParamError

_NOT_SUPPORTED = ("complete_after_retired", "match_contact_group", "ignore_contact_group", "match_group",
                  "ignore_group", "match_type", "ignore_type", "bearing_line_config", "bearing_lines")


class ContactBehavior(Behavior):
    """Ownship (``osx, osy, osh, osv``) and contact (``cnx, cny, cnh, cnv, cnutc``) state, updated each iteration."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.contact = ""
        self.extrapolate = True
        self.on_no_contact_ok = True
        self.time_on_leg = 60.0
        self.extrapolator = LinearExtrapolator(15.0, 30.0)
        self.osx = self.osy = self.osh = self.osv = 0.0
        self.cnx = self.cny = self.cnh = self.cnv = self.cnutc = 0.0
        self.contact_range = 0.0

    def set_specific_param(self, param: str, value: str) -> bool:
        """The contact parameters; subclasses call this first, then handle their own."""
        if param in ("contact", "them"):
            if not value:
                raise ParamError("contact must name a vehicle")
            self.contact = value.upper()
        elif param == "extrapolate":
            self.extrapolate = parse_bool(value, param)
        elif param == "decay":
            start, sep, end = value.partition(",")
            if not sep:
                raise ParamError(f"decay must be START,END, not '{value}'")
            first, last = parse_float(start.strip(), "decay start"), parse_float(end.strip(), "decay end")
            if first < 0 or first > last:
                raise ParamError(f"decay must be START,END with 0 <= START <= END, not '{value}'")
            self.extrapolator.set_decay(first, last)
        elif param == "decay_end":  # deprecated; in 19.8.1 it never reaches the extrapolator, so no effect
            parse_float(value, param)
        elif param == "on_no_contact_ok":
            self.on_no_contact_ok = parse_bool(value, param)
        elif param == "time_on_leg":
            self.time_on_leg = parse_float(value, param, low=0.0)
        elif param in _NOT_SUPPORTED:
            raise ParamError(f"{param} is not supported by this helm")
        else:
            return False
        return True

    def check_config(self) -> None:
        super().check_config()
        if not self.contact:
            raise ParamError("contact is not set")

    def update_platform_info(self) -> bool:
        """Ownship and contact state for this iteration; False (after a BHV_ERROR or BHV_WARNING) if incomplete.

        A missing contact posts BHV_ERROR, which halts the helm this iteration, when ``on_no_contact_ok`` is false,
        and BHV_WARNING otherwise; either way there is no function.
        """
        own = [self.info.get_double(v) for v in ("NAV_X", "NAV_Y", "NAV_HEADING", "NAV_SPEED")]
        if any(v is None for v in own):
            self.post_error("ownship x,y,heading, or speed info not found.")
            return False
        self.osx, self.osy, heading, self.osv = own  # type: ignore[assignment]
        self.osh = heading % 360.0  # type: ignore[operator]
        names = [f"{self.contact}_NAV_{suffix}" for suffix in ("X", "Y", "HEADING", "SPEED", "UTC")]
        theirs = [self.info.get_double(name) for name in names]
        if any(v is None for v in theirs):
            message = f"{self.contact} x/y/heading/speed info not found"
            if self.on_no_contact_ok:
                self.post_warning(message)
            else:
                self.post_error(message)
            return False
        self.cnx, self.cny, self.cnh, self.cnv, self.cnutc = theirs  # type: ignore[assignment]
        if self.extrapolate:
            self.extrapolator.set_position(self.cnx, self.cny, self.cnv, self.cnh, self.cnutc)
            x, y, ok = self.extrapolator.position(self.now)
            if ok:
                self.cnx, self.cny = x, y
            else:
                self.post_warning(f"Incomplete Linear Extrapolation: {self.extrapolator.failure_reason}")
        self.contact_range = math.hypot(self.osx - self.cnx, self.osy - self.cny)
        return True
