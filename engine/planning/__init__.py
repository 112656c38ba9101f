"""Planners behind the planning behaviors: paths free of obstacles on an
occupancy grid (A*), the next point to explore, and occupancy mapping from the
camera (paper Appendix A, planning and recording behaviors), and the planning
worker that runs them off the engine loop.
"""
