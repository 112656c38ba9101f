"""A mission with a misspelt behavior, a wrong argument and a malformed belief expression: refused."""

import aeroexec.engine.api as api


def mission():
    api.execute_behavior("TAKE_OFF", altitude=3)
    api.execute_behavior("GO_TO_PONT", coordinates=[2, 5, 1.3])
    api.execute_behavior("GO_TO_POINT", coordinates=[2, 5, 1.3], speeed=2)
    success, unification = api.consult_belief("position(self, (?x, ?y, ?z)")
    api.execute_behavior("LAND")
