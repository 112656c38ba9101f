"""Python missions (paper §6.1): the bridge that lets a mission thread call
the engine, and the static check of a mission's source before flight
(behavior names, arguments, belief expressions, WRONG_SEQUENCE). What a foreign
dialect adds (its APIs under the names missions import, its checks) comes
through the tables of :mod:`.standins` and :mod:`.dialect_checks`.
"""
