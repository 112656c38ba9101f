"""Execution control (paper §4.1, §4.2, §4.4, §5.2): the behavior coordinator
(Algorithms 4-5), behavior processes and their lifecycle, the resource manager
with capability processes, activation conditions, failure explanations, and
the belief updaters that write the drone's telemetry as beliefs.
"""
