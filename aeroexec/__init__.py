"""aeroexec: an execution engine for aerial robot mission plans.

The subpackages live in the repository's top-level folders (``beliefs/``,
``engine/``, ``drones/``, ``trees/``, ...) and are mapped into this namespace
by ``pyproject.toml``; ``docs/ARCHITECTURE.md`` describes the parts and layers.
"""

__version__ = "0.4.0"
