"""The operator console in a browser (paper §2.1, supervisory control): a live map of the world and the drones,
the mission as it runs, behaviors, beliefs and events, and the operator's commands; also a read-only replay
of a finished run's event log. Served on 127.0.0.1 with a per-run token (Starlette + uvicorn, no CDN).
"""
