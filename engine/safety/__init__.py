"""Runtime assurance: the operator's safety rules watched every tick (monitors), the contingencies they take, the
predicates computed from the vehicle model (``battery_to_home``...), and the checks a rule allows before flight."""

from aeroexec.drones.vehicle import VehicleModel
from aeroexec.engine.safety.monitor import SafetyMonitor
from aeroexec.engine.safety.predicates import SafetyPredicates

__all__ = ["SafetyMonitor", "SafetyPredicates", "VehicleModel"]
