"""aeroexec.trees"""
