"""The paper's complex behavior "go to point y" (Appendix A), written with simpler behaviors:

1. from where the robot is, ask the path planner for a path free of obstacles to y;
2. follow the path;
3. if something goes wrong on the way, plan again from where the robot is (at most three times).

    aeroexec run missions/go_to_point_y.py
"""

import aeroexec.engine.api as api

Y = [12, 12, 2]  # behind the tower, seen from home


def go_to_point(y, attempts=3):
    for _ in range(attempts):
        path = api.ask_behavior("GENERATE_PATH_FREE_OF_OBSTACLES", destination=y)
        if not path:
            return api.FAILED_PRECONDITIONS
        result = api.execute_behavior("FOLLOW_PATH", path=path)
        if result == api.GOAL_ACHIEVED:
            return result
    return result


def mission():
    api.execute_behavior("TAKE_OFF")
    result = go_to_point(Y)
    if result != api.GOAL_ACHIEVED:
        raise RuntimeError(f"could not reach {Y}: {result}")
    api.execute_behavior("GO_TO_POINT", coordinates=[0, 0, 2])
    api.execute_behavior("LAND")
