"""The foreign dialects: missions written for other systems, flown by aeroexec (docs/ARCHITECTURE.md, "where to add
a dialect").

- :mod:`.aerostack`: Aerostack (ROS 1; Levant, Sirocco): its mission modules, its ``nodes:`` missions, its catalogs;
- :mod:`.aerostack2`: Aerostack2 (ROS 2): its Python API, behavior modules, interpreter plans and tree nodes;
- :mod:`.tml`: TML missions (Aerostack's task-based mission language);
- :mod:`.ros`: the ROS modules a mission of either Aerostack imports and aeroexec does not provide.

Each registers with the core as another package would, through pyproject.toml's entry points (the mission formats'
table, the stand-ins' and the checks' tables, the readers' groups); the core (engine, trees, beliefs, grammar, drones,
flight, fleet) imports none of them: an import-linter contract. The mission APIs are installed here only, as
``aeroexec.dialects.<dialect>.<name>``: nothing of aeroexec takes the top-level names ``rclpy``,
``as2_python_api``... in an environment (ROS 2's own ``rclpy`` stays the one every other program gets). A mission
aeroexec loads imports them under the names it was written with (:mod:`aeroexec.engine.missions.standins`).
"""
