"""The simulated drone and its world: kinematics on an external clock, obstacles, markers, camera."""
