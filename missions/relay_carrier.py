"""The carrier of the two-drone relay (missions/relay.yaml): wait on the ground for another drone's
"area clear" (``message(?D, "area clear")``), then fly there, come back and land."""

import aeroexec.engine.api as api

PATIENCE = 300  # s to wait for the message


def mission():
    waited = 0
    while not api.true_belief('message(?D, "area clear")'):
        if waited >= PATIENCE:
            raise RuntimeError(f"nobody said the area is clear in {PATIENCE} s")
        api.wait(0.5)
        waited += 0.5
    api.execute_behavior("TAKE_OFF", altitude=2)
    api.execute_behavior("GO_TO_POINT", coordinates=[5, 3, 2])
    api.execute_behavior("GO_TO_POINT", coordinates=[0, 3, 2])
    api.execute_behavior("LAND")
