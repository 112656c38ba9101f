"""``aeroexec run --foxglove [PORT]`` (issue 46): the recording's topics served live over the Foxglove WebSocket
protocol; a client (``websockets``) that subscribes to the drone's pose receives it while the drone flies, as CDR
that rosbags decodes into ``geometry_msgs/msg/PoseStamped``. The layout file in docs names only topics that are
served."""

from __future__ import annotations

import json
import re
import struct
import threading
from pathlib import Path

from aeroexec.cli.main import main
from aeroexec.flight import FlightSession, FlightSpec
from aeroexec.flight.recording.topics import TOPICS
from recordings import JAZZY
from websockets.sync.client import connect

ROOT = Path(__file__).parents[2]
FIGURE10 = ROOT / "missions" / "figure10.xml"
GIVE_UP = 120  # s: how long a wait for the other side's event may take before the test fails


def test_a_foxglove_client_subscribes_and_receives_poses_while_the_drone_flies(tmp_path):
    spec = FlightSpec(mission=FIGURE10, output=str(tmp_path / "run"), register=False, foxglove=0, speed=1.0)
    subscribed = threading.Event()
    outcome = {}
    with FlightSession(spec, notify=lambda text: None) as session:
        [view] = session.recording.recorder.sinks
        assert view.host == "127.0.0.1" and view.port > 0

        def first_tick() -> None:  # the pose's channel is advertised with the first sample: wait for the viewer
            session.engine.tick_callbacks.remove(first_tick)
            subscribed.wait(GIVE_UP)

        session.engine.tick_callbacks.append(first_tick)
        flying = threading.Thread(target=lambda: outcome.setdefault("flight", session.fly()))
        flying.start()
        heights = []
        try:
            with connect(view.url, subprotocols=["foxglove.sdk.v1", "foxglove.websocket.v1"],
                         open_timeout=GIVE_UP, max_size=None) as client:
                channels = {}
                while "/drone/pose" not in channels:
                    message = client.recv(timeout=GIVE_UP)
                    if isinstance(message, str) and json.loads(message)["op"] == "advertise":
                        channels.update({c["topic"]: c for c in json.loads(message)["channels"]})
                pose = channels["/drone/pose"]
                assert (pose["encoding"], pose["schemaName"], pose["schemaEncoding"]) == (
                    "cdr", "geometry_msgs/msg/PoseStamped", "ros2msg")
                client.send(json.dumps({"op": "subscribe", "subscriptions": [{"id": 7, "channelId": pose["id"]}]}))
                subscribed.set()
                while not heights or max(heights) <= 1.0:  # until the drone is seen in the air
                    message = client.recv(timeout=GIVE_UP)
                    if isinstance(message, bytes) and message[0] == 1:
                        subscription, _ = struct.unpack_from("<IQ", message, 1)
                        assert subscription == 7
                        decoded = JAZZY.deserialize_cdr(message[13:], "geometry_msgs/msg/PoseStamped")
                        heights.append(decoded.pose.position.z)
                landed = [e for e in session.engine.log.events() if e.kind == "drone_landed"]
                in_the_air = flying.is_alive() and not landed  # received while the drone flies
        finally:
            subscribed.set()
            flying.join()
    assert in_the_air and max(heights) > 1.0
    assert outcome["flight"].exit_status == 0


def test_the_foxglove_layout_shows_only_topics_a_recording_has():
    layout = json.loads((ROOT / "docs" / "foxglove_layout.json").read_text())
    served = {t.topic(type("D", (), {"name": "drone"})()) for t in TOPICS}
    named = set(re.findall(r'"(/[a-z_/]+)', json.dumps(layout["configById"])))
    assert named and named <= served, named - served
    panels = {key.split("!")[0] for key in layout["configById"]}
    assert {"3D", "Map", "Plot"} <= panels


def test_a_taken_port_is_refused_before_anything_flies(tmp_path, capsys):
    import socket

    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        code = main(["run", str(FIGURE10), "--quiet", "--output", str(tmp_path / "run"), "--foxglove", str(port)])
    assert code == 2
    err = capsys.readouterr().err
    assert f"--foxglove 127.0.0.1:{port}: " in err and "Traceback" not in err
    assert not (tmp_path / "run" / "events.jsonl").exists()
