"""The Goby3 course's examples over the trail messages, each runnable with ``python -m`` (docs/dccl.md "Units").

``health_publisher`` / ``health_subscriber``: the lecture's "Time in Goby" pair (interprocess1 with a timestamped
HealthStatus).
"""
