# A Levant mission that waits for an object to be seen but never flies nor looks:
# the world does not change, so the polling loop could only end at the time limit.
import executive_engine_api as api


def runMission():
    while not api.trueBelief('visible(object_1)'):
        pass
