"""goby-liaison: the web page of a platform (Goby3's goby_liaison as a user sees it, plus a live map).

Modules, bottom up: ``errors``; ``message_types`` (naming protobuf types, importing their modules);
``settings`` (the config, checked); ``decode`` (payload -> text); ``scope_model`` (rows, history, rates,
coalescing); ``form_schema`` and ``form_values`` (the commander's form from a descriptor with DCCL bounds, and the
values a browser sends back); ``commander_model`` (sent commands, acks, expiry); ``map_model`` (vehicles, trails,
overlays); ``portal_side`` (the application's portal thread); ``fanout`` (per-browser bounded queues);
``server`` (aiohttp routes and WebSockets); ``static/`` (the page: plain HTML/JS/CSS).  See docs/liaison.md.
"""
