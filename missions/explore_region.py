"""The paper's complex behavior "explore spatial region x" (Appendix A), written with simpler behaviors:

1. ask the exploration planner for the next point to explore in the region;
2. go to that point;
3. if the region is not completely explored, go to 1.

Colored objects seen on the way are remembered; the mission reports them at the end.

    aeroexec run missions/explore_region.py
"""

import aeroexec.engine.api as api

REGION = [[-2, -2, 3], [18, -2, 3], [18, 18, 3], [-2, 18, 3]]  # the north-east quarter of the field


def mission():
    api.execute_behavior("TAKE_OFF", altitude=3)
    api.activate_behavior("PAY_ATTENTION_TO_COLORS")
    visited = 0
    while True:
        point = api.ask_behavior("GENERATE_NEXT_POINT_TO_EXPLORE", region=REGION)
        if not point:  # the region is covered
            break
        if api.execute_behavior("GO_TO_POINT", coordinates=point) == api.GOAL_ACHIEVED:
            visited += 1
    api.inhibit_behavior("PAY_ATTENTION_TO_COLORS")
    found, seen = api.consult_belief("color(?O, ?C)")
    print(f"explored {visited} points; {'saw ' + seen['O'] if found else 'saw no colored object'}")
    api.execute_behavior("GO_TO_POINT", coordinates=[0, 0, 3])
    api.execute_behavior("LAND")
