"""aeroexec.catalogs"""
