"""Asks the operator which way to fly, then flies there and lands (the console's question dialog)."""

import aeroexec.engine.api as api


def mission():
    api.execute_behavior("TAKE_OFF", altitude=2)
    way = api.ask_behavior("ASK_OPERATOR", question="Which way?", possible_answers=["east", "south"])
    api.execute_behavior("GO_TO_POINT", coordinates=[4, 0, 2] if way == "east" else [0, -4, 2])
    api.execute_behavior("LAND")
