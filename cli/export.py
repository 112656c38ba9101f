"""``aeroexec export RUN_DIR --mcap FILE``: a finished run as a recording the robotics ecosystem's tools open (an
MCAP file for Foxglove, rosbags, ``ros2 bag``): the drone's pose, velocity, global position, battery and frames
as ROS 2 messages, the behavior events, beliefs, operator commands, tree node statuses, safety rules' states and
the planned route beside them. A fleet's folder makes one file, each drone's topics under its name."""

from __future__ import annotations

import argparse
import sys


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("run_dir", metavar="RUN_DIR",
                        help="a finished run's output folder (or a fleet's: every drone in one file), or its event log")
    parser.add_argument("--mcap", metavar="FILE", required=True,
                        help="the MCAP file to write: /DRONE/pose, /DRONE/velocity, /DRONE/fix, /DRONE/battery, /tf, "
                             "/DRONE/route (ROS 2 types, CDR) and /DRONE/behavior_events, /DRONE/beliefs, "
                             "/DRONE/operator_commands, /DRONE/tree, /DRONE/safety, /DRONE/events (JSON); DRONE is "
                             "'drone' for a single run, each drone's name for a fleet")


def run(args: argparse.Namespace) -> int:
    from aeroexec.flight.recording.export import RecordingError, export_mcap

    try:
        exported = export_mcap(args.run_dir, args.mcap)
    except RecordingError as error:
        print(f"aeroexec export: {error}", file=sys.stderr)
        return 1
    except OSError as error:  # the file cannot be written
        print(f"aeroexec export: {args.mcap}: cannot write the recording: {error.strerror or error}", file=sys.stderr)
        return 1
    for note in exported.notes:
        print(f"aeroexec export: {note}", file=sys.stderr)
    total = sum(exported.counts.values())
    print(exported.path)
    print(f"{total:,} messages on {len(exported.counts)} topics for {', '.join(exported.drones)}", file=sys.stderr)
    return 0
