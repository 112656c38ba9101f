"""Refused: LANDING is not a behavior."""

from aeroexec.engine.api import executeBehavior


def runMission():
    executeBehavior("TAKE_OFF")
    executeBehavior("LANDING")
