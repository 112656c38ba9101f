"""Supervisory control (paper §2.1) inside the engine: the supervisor that runs the operator's commands (pause,
resume, abort, inhibit, answer) on the engine's thread, operator channels, and the default output folder. The run's
files and control socket are the flight's (:mod:`aeroexec.flight`).
"""
