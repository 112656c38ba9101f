# A Levant mission in the form of the Aerostack wiki's "Python Language" page and its complete example:
# memorise home, look for an object while flying toward it (polling the belief memory), mark it, go home, land.
import executive_engine_api as api


def runMission():
    print("Starting mission...")
    api.activateBehavior('SELF_LOCALIZE_BY_ODOMETRY')
    result = api.executeBehavior('TAKE_OFF')
    print("TAKE_OFF: " + str(result))
    success, unification = api.consultBelief('position(self, (?X, ?Y, ?Z))')
    home = [unification['X'], unification['Y'], 2]
    ack, colors = api.activateBehavior('PAY_ATTENTION_TO_COLORS')
    ack, flight = api.activateBehavior('GO_TO_POINT', coordinates=[-2, -8, 2])
    while not api.trueBelief('color(?OBJ, yellow), visible(?OBJ)'):
        pass
    api.inhibitBehavior(flight)
    found, seen = api.consultBelief('color(?OBJ, yellow), position(?OBJ, (?X, ?Y, ?Z))')
    api.addBelief('picked_up(' + seen['OBJ'] + ')')
    api.addBelief('found_at(yellow, 1)')
    api.inhibitBehavior(colors)
    api.executeBehavior('GO_TO_POINT', coordinates=home)
    api.removeBelief('found_at(yellow, ?)')
    api.inhibitBehavior('SELF_LOCALIZE_BY_ODOMETRY')
    api.executeBehavior('LAND')
    print("Finish mission...")
