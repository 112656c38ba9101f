"""Aerostack (ROS 1; Levant, Sirocco): its mission modules (``executive_engine_api``, ``mission_execution_control``),
its behavior tree interpreter's YAML ``nodes:`` missions, and the catalogs of its other versions recognised and
refused. Registered with the core through entry points (:mod:`.registry`); the core imports nothing of it.
"""
