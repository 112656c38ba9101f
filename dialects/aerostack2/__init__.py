"""Aerostack2 (ROS 2): its Python API (``as2_python_api``, with ``as2_msgs``' constants and a minimal ``rclpy``),
its behavior modules as catalog requests (:mod:`.behaviors`), its scripts' drone interfaces in the static check
(:mod:`.drone_objects`), its mission interpreter's plans (:mod:`.plans`) and its behavior-tree nodes
(:mod:`.tree_nodes`). Registered with the core through entry points (:mod:`.registry`); the core imports nothing
of it.
"""
