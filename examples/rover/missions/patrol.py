"""The rover leaves its dock, patrols the yard looking for markers, says what it saw and docks again.

    aeroexec run examples/rover/missions/patrol.py --robot rover
"""

import aeroexec.engine.api as api

STOPS = [(-2, -6), (2, 4), (-4, 6)]


def mission():
    api.activate_behavior("PAY_ATTENTION_TO_VISUAL_MARKERS")
    for stop in STOPS:
        if api.execute_behavior("DRIVE_TO_POINT", coordinates=stop) != "GOAL_ACHIEVED":
            break
    api.execute_behavior("TURN", heading=90)
    found, seen = api.consult_belief("code(?M, ?C)")
    api.execute_behavior("SAY", sentence=f"I saw marker {seen['?C']}" if found else "I saw no marker")
    api.execute_behavior("DOCK")
