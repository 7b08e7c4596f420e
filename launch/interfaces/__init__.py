"""Interface files (every app's publications and subscriptions, as Goby's YAML) and deployment graphs.

``goby-interfaces generate APP`` derives an application's interface from its source code by static analysis
(the role of goby_clang_tool's ``-gen``); ``goby-interfaces visualize DEPLOYMENT.yml`` draws a deployment as
Graphviz DOT with Goby's structure (``-viz``).
"""
