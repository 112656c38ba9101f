"""The simulated drone over MAVLink, as a PX4 multicopter or an ArduCopter would speak it
(heartbeat, telemetry streams, commands, offboard, missions, parameters), so
MAVSDK and QGroundControl fly and watch it (``aeroexec sim --autopilot px4|ardupilot``).
"""
