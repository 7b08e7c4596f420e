"""MOOS side (``gateway.moos``), Goby side (``gateway.goby``) and the gateway process that joins them
(``gateway.moos_gateway``)."""
