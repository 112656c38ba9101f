"""Helpers of the console and Groot2 tests: free loopback ports and a small tree mission."""

import socket

TREE = """<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Sequence name="seq">
      <TAKE_OFF name="up"/>
      <SubTree ID="Leg" name="leg"/>
      <LAND name="down"/>
    </Sequence>
  </BehaviorTree>
  <BehaviorTree ID="Leg">
    <Fallback name="either">
      <AlwaysFailure name="nope"/>
      <AlwaysSuccess name="fine"/>
    </Fallback>
  </BehaviorTree>
</root>
"""


def free_port(pairs: int = 1) -> int:
    """A loopback port p free now, with p + 1 .. p + pairs - 1 free too (Groot2 uses p and p + 1)."""
    for _ in range(50):
        with socket.socket() as s:
            s.bind(("127.0.0.1", 0))
            port = s.getsockname()[1]
        if port + pairs > 65535:
            continue
        try:
            taken = []
            for p in range(port, port + pairs):
                t = socket.socket()
                t.bind(("127.0.0.1", p))
                taken.append(t)
            for t in taken:
                t.close()
            return port
        except OSError:
            for t in taken:
                t.close()
    raise RuntimeError("no free loopback ports")


