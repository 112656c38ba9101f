"""The lander of missions/pad_survey.yaml: the same rules as the scout, but it has surveyed no pad, so it
derives no free pad itself; it waits for one the scout derived (``free_pad(scout, ...)``, heard over the fleet
link), flies there and lands."""

import aeroexec.engine.api as api

ALTITUDE = 3
PATIENCE = 300  # s to wait for the scout's survey


def mission():
    api.add_rules("""
        pad(pad_a, (4, 2)).  pad(pad_b, (-4, -3)).  pad(pad_c, (2, -8)).  pad(pad_d, (-8, -2)).
        gusty(pad_d).
        unsurveyed(pad_a).  unsurveyed(pad_b).  unsurveyed(pad_c).  unsurveyed(pad_d).
        taken(?P) :- pad(?P, (?X, ?Y)), object(?O, ?), position(?O, (?A, ?B, ?C)), ?C < 1,
                     distance((?X, ?Y, 0), (?A, ?B, 0), ?D), ?D < 1.5.
        free_pad(self, ?P, ?X, ?Y) :- pad(?P, (?X, ?Y)), not(unsurveyed(?P)), not(taken(?P)), not(gusty(?P)).
    """)
    waited = 0.0
    while not api.true_belief("free_pad(?D, ?P, ?X, ?Y), ?D != self"):
        if waited >= PATIENCE:
            raise RuntimeError(f"no free pad heard of in {PATIENCE} s")
        api.wait(0.5)
        waited += 0.5
    _, pad = api.consult_belief("free_pad(?D, ?P, ?X, ?Y), ?D != self")
    print(f"landing on {pad['P']}, found free by {pad['D']}")
    api.execute_behavior("TAKE_OFF", altitude=ALTITUDE)
    api.execute_behavior("GO_TO_POINT", coordinates=[pad["X"], pad["Y"], ALTITUDE])
    api.execute_behavior("LAND")
