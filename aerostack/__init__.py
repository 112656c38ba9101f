"""The mission APIs of Aerostack (ROS 1: Levant's ``executive_engine_api``, Sirocco's ``mission_execution_control``)
and Aerostack2 (ROS 2: ``as2_python_api``, the constants of ``as2_msgs``, a minimal ``rclpy``), served by aeroexec.

They are installed here only, as ``aeroexec.aerostack.<name>``: nothing of aeroexec takes the top-level names
``rclpy``, ``as2_python_api``... in an environment (ROS 2's own ``rclpy`` stays the one every other program gets).
A mission aeroexec loads imports them under the names it was written with: its imports are mapped here
(:mod:`aeroexec.engine.missions.standins`).
"""
