"""Refused: TAKE_OFF's altitude is at most 50 m, and a point has three coordinates."""

from aeroexec.engine import api as drone


def mission():
    drone.executeBehavior("TAKE_OFF", altitude=800)
    drone.executeBehavior("GO_TO_POINT", coordinates=(4, 2))
    drone.executeBehavior("LAND")
