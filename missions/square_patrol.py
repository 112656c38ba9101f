"""Patrol a square twice at 3 m, watching for visual markers, and report what was seen; come home early
if the battery runs low.

    aeroexec run missions/square_patrol.py
"""

from aeroexec.engine import api

CORNERS = [(-4, -6, 3), (4, -6, 3), (4, 2, 3), (-4, 2, 3)]


def mission():
    if api.execute_behavior("TAKE_OFF", altitude=3) != api.GOAL_ACHIEVED:
        return
    api.activate_behavior("PAY_ATTENTION_TO_VISUAL_MARKERS")
    for lap in range(2):
        for corner in CORNERS:
            result = api.execute_behavior("GO_TO_POINT", coordinates=corner)
            if result != api.GOAL_ACHIEVED:
                print(f"lap {lap + 1}: GO_TO_POINT {corner} ended with {result}")
        if api.true_belief("charge(battery, ?p), ?p < 30"):
            break
    found, marker = api.consult_belief("object(?m, marker), code(?m, ?c)")
    print(f"first marker seen: {marker['?c']}" if found else "no marker seen")
    api.inhibit_behavior("PAY_ATTENTION_TO_VISUAL_MARKERS")
    api.execute_behavior("GO_TO_POINT", coordinates=(0, 0, 3))
    api.execute_behavior("LAND")
