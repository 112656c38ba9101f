"""aeroexec.cli"""
