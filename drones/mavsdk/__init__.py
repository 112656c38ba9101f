"""The MAVSDK adapter: any MAVLink vehicle (PX4, ArduPilot, aeroexec sim) behind the drone interface."""
