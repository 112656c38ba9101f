# A Levant mission for the Levant catalog above: take off, two points, a turn, land.
import executive_engine_api as api


def runMission():
    api.activateBehavior('SELF_LOCALIZE_BY_ODOMETRY')
    api.executeBehavior('TAKE_OFF')
    api.executeBehavior('GO_TO_POINT', coordinates=[3, 0, 2])
    api.executeBehavior('ROTATE', angle=90)
    api.executeBehavior('GO_TO_POINT', coordinates=[3, 3, 2])
    api.executeBehavior('LAND')
