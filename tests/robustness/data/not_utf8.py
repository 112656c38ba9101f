from aeroexec.engine import api


def mission():
    api.execute_behavior("LAND")  # ÿ
