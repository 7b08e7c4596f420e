"""MOOS side (``gateway.moos``), Goby side (``gateway.portal``) and the gateway process that joins them."""
