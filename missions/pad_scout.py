"""The scout of missions/pad_survey.yaml: look over the landing pads, so that its rules derive which are free
(``free_pad(self, Pad, X, Y)``, shared with the fleet), then come home and land."""

import aeroexec.engine.api as api

ALTITUDE = 4


def mission():
    api.add_rules("""
        pad(pad_a, (4, 2)).  pad(pad_b, (-4, -3)).  pad(pad_c, (2, -8)).  pad(pad_d, (-8, -2)).
        gusty(pad_d).
        unsurveyed(pad_a).  unsurveyed(pad_b).  unsurveyed(pad_c).  unsurveyed(pad_d).
        taken(?P) :- pad(?P, (?X, ?Y)), object(?O, ?), position(?O, (?A, ?B, ?C)), ?C < 1,
                     distance((?X, ?Y, 0), (?A, ?B, 0), ?D), ?D < 1.5.
        free_pad(self, ?P, ?X, ?Y) :- pad(?P, (?X, ?Y)), not(unsurveyed(?P)), not(taken(?P)), not(gusty(?P)).
    """)
    if api.execute_behavior("TAKE_OFF", altitude=ALTITUDE) != api.GOAL_ACHIEVED:
        raise RuntimeError("the scout could not take off")
    api.activate_behavior("PAY_ATTENTION_TO_SHAPES")
    for name, x, y in (("pad_a", 4, 2), ("pad_b", -4, -3), ("pad_c", 2, -8)):
        api.execute_behavior("GO_TO_POINT", coordinates=[x, y, ALTITUDE])
        api.remove_belief(f"unsurveyed({name})")
    api.inhibit_behavior("PAY_ATTENTION_TO_SHAPES")
    api.wait(3)  # the fleet link shares its beliefs once a second
    api.execute_behavior("GO_TO_POINT", coordinates=[0, -3, ALTITUDE])
    api.execute_behavior("LAND")
