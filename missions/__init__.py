"""Example missions, shipped as package data, that run as they are: Python missions, BehaviorTree.CPP XML and YAML
trees, a TML mission, QGroundControl plans, fleet files (``aeroexec run`` or ``aeroexec fleet`` with the path)."""
