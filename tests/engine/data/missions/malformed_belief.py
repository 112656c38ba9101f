"""Refused: a belief expression with a missing parenthesis and one with an unknown predicate."""

import aeroexec.engine.api as api


def mission():
    api.execute_behavior("TAKE_OFF")
    if api.true_belief("charge(battery, ?c), ?c < 30"):
        api.execute_behavior("LAND")
        return
    found, where = api.consultBelief("object(?x, marker), position(?x, ?p")
    if api.trueBelief("objet(?x, marker)"):
        api.add_belief("visible(marker_1)")
    api.execute_behavior("LAND")
