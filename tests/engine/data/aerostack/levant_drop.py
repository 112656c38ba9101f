# A Levant mission using DROP_OBJECT, which the Levant catalog describes but no implementation serves,
# and GO_TO_POINT without the point the implementation needs.
import executive_engine_api as api


def runMission():
    api.executeBehavior('TAKE_OFF')
    api.executeBehavior('GO_TO_POINT')
    api.executeBehavior('DROP_OBJECT')
    api.executeBehavior('LAND')
