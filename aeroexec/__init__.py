"""aeroexec: an execution engine for aerial robot mission plans.

The subpackages live in the repository's top-level folders (``beliefs/``,
``engine/``, ``drones/``, ``trees/``, ...) and are mapped into this namespace
by ``pyproject.toml``; see ``shared/DESIGN.md`` for the layers.
"""

__version__ = "0.1.0"
