"""aeroexec.drones"""
