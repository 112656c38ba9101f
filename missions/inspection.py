"""Inspect the tower: fly a path around it at 3 m, stopping at each corner to face it and take a photo.

    aeroexec run missions/inspection.py --output photos/
"""

import aeroexec.engine.api as api

TOWER = [8, 8, 3]  # the middle of the tower at the inspection height
STATIONS = [[3, 3, 3], [13, 3, 3], [13, 13, 3], [3, 13, 3]]  # around it, 3.5 m from its faces


def mission():
    if api.execute_behavior("TAKE_OFF", altitude=3) != api.GOAL_ACHIEVED:
        return
    photos = 0
    for station in STATIONS:
        arrived = api.execute_behavior("GO_TO_POINT", coordinates=station, point_to_look_at_the_end=TOWER)
        if arrived == api.GOAL_ACHIEVED and api.execute_behavior("TAKE_PHOTO") == api.GOAL_ACHIEVED:
            photos += 1
    api.execute_behavior("GO_TO_POINT", coordinates=[0, 0, 3])
    api.execute_behavior("LAND")
    if photos < len(STATIONS):
        raise RuntimeError(f"only {photos} of {len(STATIONS)} photos were taken")
