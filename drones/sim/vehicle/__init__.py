"""The simulated vehicle: the multicopter's physical state and flight phases, its control laws, battery and contacts.

:class:`~aeroexec.drones.sim.vehicle.multicopter.Multicopter` is what :class:`~aeroexec.drones.sim.SimulatedDrone`
flies, one fixed substep at a time.
"""
