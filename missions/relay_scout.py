"""The scout of the two-drone relay (missions/relay.yaml): fly out to the marker field, look, broadcast
"area clear" to the fleet, come home and land."""

import aeroexec.engine.api as api


def mission():
    api.execute_behavior("TAKE_OFF", altitude=3)
    api.execute_behavior("GO_TO_POINT", coordinates=[5, -3, 3])
    api.execute_behavior("BROADCAST_MESSAGE", message="area clear")
    api.execute_behavior("GO_TO_POINT", coordinates=[0, -3, 3])
    api.execute_behavior("LAND")
