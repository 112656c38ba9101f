"""Aerostack2 1.0's Python API, ``python_interface`` (the package ``as2_python_api`` was called until 2022): the
same drone interfaces and behavior modules, under the module names that version's scripts import
(``python_interface.drone_interface``, ``python_interface.modules.goto_module``...)."""

from aeroexec.engine import api as _api

_api.add_library_folder(__path__[0])
