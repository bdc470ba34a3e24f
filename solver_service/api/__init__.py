"""The REST service: FastAPI app (``app``), settings, compute pool, jobs and Hops components.

Imported lazily: ``rockmech serve`` and the compute processes pay only for what they use.
"""
