"""Supervisory control (paper §2.1) inside the engine: the supervisor that runs the operator's commands (pause,
resume, abort, inhibit, answer) on the engine's thread, operator channels, and the default output folder. The run's
files and control socket are the flight's (:mod:`aeroexec.flight`).
"""

#: The changes of the running mission an operator may ask for (:mod:`.changes` checks and makes them): named here,
#: so the supervisor knows its commands without importing that module, which a flight needs only once one is asked.
CHANGES = ("skip", "jump", "insert", "modify", "delete", "replace", "load")
