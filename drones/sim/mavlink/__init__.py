"""The simulated drone over MAVLink, as a PX4 multicopter would speak it
(heartbeat, telemetry streams, commands, offboard, missions, parameters), so
MAVSDK and QGroundControl fly and watch it (``aeroexec sim``).
"""
