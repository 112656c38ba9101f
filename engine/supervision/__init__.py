"""Supervisory control (paper §2.1): the operator's commands (pause, resume,
abort, inhibit, answer), the control server, operator channels, messages
between drones, the flight log and its summary, and the run's output folder.
"""
