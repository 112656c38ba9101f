"""aeroexec: an execution engine for aerial robot mission plans.

The subpackages live in the repository's top-level folders (``beliefs/``,
``engine/``, ``drones/``, ``trees/``, ...) and are mapped into this namespace
by ``pyproject.toml``; ``docs/ARCHITECTURE.md`` describes the parts and layers.
"""

from aeroexec import _moved

__version__ = "0.2.0"

_moved.install()
