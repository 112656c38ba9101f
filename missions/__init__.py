"""aeroexec.missions"""
