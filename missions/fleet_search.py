"""One drone of the fleet search (missions/fleet_search.yaml): explore the strip south of its own home until
marker 3 is known (by its own camera or from another drone over the fleet link); the drone that sees it
broadcasts it; every drone returns home and lands.

    aeroexec fleet missions/fleet_search.yaml --plain
"""

import aeroexec.engine.api as api

ALTITUDE = 4
WAIT_FOR_NEWS = 120  # s: a drone that covered its strip waits this long to hear of the marker


def mission():
    _, home = api.consult_belief("position(self, (?X, ?Y, ?Z))")
    x, y = round(home["?X"], 1), round(home["?Y"], 1)
    strip = [[x - 3, -18, ALTITUDE], [x + 3, -18, ALTITUDE], [x + 3, -11, ALTITUDE], [x - 3, -11, ALTITUDE]]
    if api.execute_behavior("TAKE_OFF", altitude=ALTITUDE) != api.GOAL_ACHIEVED:
        raise RuntimeError("the drone could not take off")
    api.activate_behavior("PAY_ATTENTION_TO_VISUAL_MARKERS")
    while not api.true_belief("code(?M, 3)"):
        point = api.ask_behavior("GENERATE_NEXT_POINT_TO_EXPLORE", region=strip)
        if not point:
            break
        api.execute_behavior("GO_TO_POINT", coordinates=point)
    waited = 0
    while not api.true_belief("code(?M, 3)") and waited < WAIT_FOR_NEWS:
        api.wait(1)
        waited += 1
    api.inhibit_behavior("PAY_ATTENTION_TO_VISUAL_MARKERS")
    known = api.true_belief("code(?M, 3)")  # now: what another drone said expires once it landed and went quiet
    seen, marker = api.consult_belief("code(?M, 3), position(?M, (?X, ?Y, ?Z))")  # where: only the finder knows
    if seen and not api.true_belief("message(?D, ?Text)"):  # nobody said it yet
        api.execute_behavior("BROADCAST_MESSAGE",
                             message=f"marker 3 found at ({marker['X']:.0f}, {marker['Y']:.0f})")
    api.execute_behavior("GO_TO_POINT", coordinates=[x, y, ALTITUDE])
    api.execute_behavior("LAND")
    if not known:
        raise RuntimeError("marker 3 is known to nobody in the fleet")
