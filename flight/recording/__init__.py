"""Recordings of flights for the robotics ecosystem's tools: a run's records as MCAP (ROS 2 messages in CDR with
rosbag2's ``ros2msg`` definitions, aeroexec's own records as JSON), from a finished run's folder or while flying.

``ros_messages.py`` (the ROS 2 types and their definitions as rosbag2 writes them), ``topics.py`` (the topic table:
which records go where, as which message), ``recorder.py`` (records in, encoded messages out to sinks),
``mcap_file.py`` (the MCAP sink), ``export.py`` (a finished run's folder recorded). Needs the ``ros`` extra.
"""
