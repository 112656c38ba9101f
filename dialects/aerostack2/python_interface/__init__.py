"""The Python API of Aerostack2 before 1.0 (the package was renamed as2_python_api in December 2022),
``python_interface``: the same drone interfaces and behavior modules, under the module names that version's scripts
import (``python_interface.drone_interface``, ``python_interface.modules.goto_module``...); its drone interfaces fly
a follow_path from the ground as that version did (:mod:`aeroexec.dialects.aerostack2.eras`)."""

from aeroexec.engine import api as _api

_api.add_library_folder(__path__[0])
