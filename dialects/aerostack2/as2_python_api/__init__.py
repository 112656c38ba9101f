"""Aerostack2's Python API (``as2_python_api``) over aeroexec: a script written for Aerostack2 runs unchanged with
``aeroexec run script.py``, on the simulated drone or a MAVSDK vehicle.

Each ``DroneInterface`` binds to one drone by its namespace; its behavior modules (takeoff, go_to, follow_path,
land...) are catalog requests (:mod:`aeroexec.dialects.aerostack2.behaviors` says which), with Aerostack2's
argument conventions and return values: True when the behavior succeeded (or, with ``wait=False``, was
accepted), False when it was refused or failed.
"""

from aeroexec.engine import api as _api

_api.add_library_folder(__path__[0])
