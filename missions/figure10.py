"""The paper's Figure 10 mission in today's Python: take off, look for visual markers, fly to a point
and back to where the drone was after take-off, stop looking, land.

    aeroexec run missions/figure10.py
"""

import aeroexec.engine.api as api


def runMission():
    api.executeBehavior("TAKE_OFF")

    api.activateBehavior("PAY_ATTENTION_TO_VISUAL_MARKERS")

    success, unification = api.consultBelief("position(self, (?x, ?y, ?z))")
    if not success:
        raise RuntimeError("position unknown")
    x, y, z = unification["x"], unification["y"], unification["z"]

    api.executeBehavior("GO_TO_POINT", point=[2, 5, 1.3])
    api.executeBehavior("GO_TO_POINT", point=[x, y, z])

    api.inhibitBehavior("PAY_ATTENTION_TO_VISUAL_MARKERS")

    api.executeBehavior("LAND")
