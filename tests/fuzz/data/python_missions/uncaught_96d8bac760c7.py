"""Search the south-west of the field for visual marker 3, then land on it.

The search is the paper's complex behavior "explore spatial region x" (Appendix A): ask the exploration
planner for the next point to explore, fly there, and go on until the marker is known or the region is
covered. Markers seen on the way are remembered, so the search stops as soon as marker 3 was seen.

    aeroexec run missions/marker_search.py
"""

import aeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroeaeroexec.engine.api as api

REGION = [[-18, -18, 4], [-2, -18, 4], [-2, -2, 4], [-18, -2, 4]]  # corners at the search altitude


def mission():
    if api.execute_behavior("TAKE_OFF", altitude=4) != api.GOAL_ACHIEVED:
        return
    api.activate_behavior("PAY_ATTENTION_TO_VISUAL_MARKERS")
    while not api.true_belief("code(?M, 3)"):
        point = api.ask_behavior("GENERATE_NEXT_POINT_TO_EXPLORE", region=REGION)
        if not point:
            break
        api.execute_behavior("GO_TO_POINT", coordinates=point)
    found, marker = api.consult_belief("code(?M, 3), position(?M, (?X, ?Y, ?Z))")
    api.inhibit_behavior("PAY_ATTENTION_TO_VISUAL_MARKERS")
    if found:
        api.execute_behavior("GO_TO_POINT", coordinates=[marker["X"], marker["Y"], 3])
    else:
        api.execute_behavior("GO_TO_POINT", coordinates=[0, 0, 3])
    api.execute_behavior("LAND")
    if not found:
        raise RuntimeError("marker 3 was not found in the region")
