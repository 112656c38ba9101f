"""Choose where to land through rules: a pad is a landing pad when nothing seen on the ground stands on it and
it is not gusty; the drone looks over the pads, asks the derived predicate which one to use, says why, and
lands there.

    aeroexec run missions/land_by_rules.py
"""

import aeroexec.engine.api as api

ALTITUDE = 4


def mission():
    api.add_rules("""
        % candidate pads, (east, north) in meters; pad_d is known to be gusty
        pad(pad_a, (4, 2)).  pad(pad_b, (-4, -3)).  pad(pad_c, (2, -8)).  pad(pad_d, (-8, -2)).
        gusty(pad_d).
        % taken: something seen on the ground stands within 1.5 m of the pad
        taken(?P) :- pad(?P, (?X, ?Y)), object(?O, ?), position(?O, (?A, ?B, ?C)), ?C < 1,
                     distance((?X, ?Y, 0), (?A, ?B, 0), ?D), ?D < 1.5.
        landing_pad(?P, ?X, ?Y) :- pad(?P, (?X, ?Y)), not(taken(?P)), not(gusty(?P)).
    """)
    if api.execute_behavior("TAKE_OFF", altitude=ALTITUDE) != api.GOAL_ACHIEVED:
        raise RuntimeError("the drone could not take off")
    api.activate_behavior("PAY_ATTENTION_TO_SHAPES")
    for x, y in ((2, -8), (4, 2), (-4, -3)):  # look at each pad from above
        api.execute_behavior("GO_TO_POINT", coordinates=[x, y, ALTITUDE])
    api.inhibit_behavior("PAY_ATTENTION_TO_SHAPES")
    found, pad = api.consult_belief("landing_pad(?P, ?X, ?Y)")
    if not found:
        print(api.why_not("landing_pad(?P, ?X, ?Y)"))
        api.execute_behavior("GO_TO_POINT", coordinates=[0, 0, ALTITUDE])
        api.execute_behavior("LAND")
        raise RuntimeError("no pad is free: landed at home")
    name = pad["P"]
    print(f"landing on {name}, because:")
    print(api.why(f"landing_pad({name}, ?X, ?Y)"))
    for taken in ("pad_a", "pad_b"):
        print(api.why(f"taken({taken})").splitlines()[0])
    api.execute_behavior("GO_TO_POINT", coordinates=[pad["X"], pad["Y"], ALTITUDE])
    api.execute_behavior("LAND")
