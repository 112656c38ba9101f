"""Runtime assurance: the operator's safety rules watched every tick (monitors), the contingencies they take, the
vehicle model behind ``battery_to_home``, and the checks a rule allows before flight."""

from aeroexec.engine.safety.monitor import SafetyMonitor
from aeroexec.engine.safety.vehicle import SafetyPredicates, VehicleModel

__all__ = ["SafetyMonitor", "SafetyPredicates", "VehicleModel"]
