"""Fleets: one engine per drone, linked over Eclipse Zenoh (telemetry, events, shared beliefs, broadcasts,
operator commands), several drones in one process or one per process and machine."""
