# A Sirocco mission in the form of the Aerostack wiki's "Python API" page: tasks through
# mission_execution_control, a recurrent task started and stopped by name, beliefs queried.
import mission_execution_control as mxc


def mission():
    print("Starting mission...")
    finished, result = mxc.executeTask('TAKE_OFF')
    if not finished:
        return
    mxc.startTask('PAY_ATTENTION_TO_VISUAL_MARKERS')
    mxc.executeTask('FOLLOW_PATH', path=[[0, 4, 2], [4, 4, 2], [4, 0, 2]])
    mxc.executeTask('ROTATE', relative_angle=90)
    success, unification = mxc.queryBelief('position(self, (?X, ?Y, ?Z))')
    mxc.addBelief('patrolled(sector_1, ' + str(round(unification['X'])) + ')', True)
    if mxc.trueBelief('battery_level(self, LOW)'):
        print("Low battery")
    mxc.stopTask('PAY_ATTENTION_TO_VISUAL_MARKERS')
    mxc.executeTask('LAND')
    print("Finish mission")
