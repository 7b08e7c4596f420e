"""Skip markers that several test areas share."""

from __future__ import annotations

import pytest

from gateway.goby.intervehicle.testing import loopback_multicast_works

needs_loopback_multicast = pytest.mark.skipif(not loopback_multicast_works(),
                                              reason="multicast on 127.0.0.1 is not available here")
"""For tests of links on the UDP multicast driver, which needs a datagram sent to a group on 127.0.0.1 to come back."""
