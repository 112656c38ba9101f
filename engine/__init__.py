"""aeroexec.engine"""
