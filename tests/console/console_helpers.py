"""Helpers of the console and Groot2 tests: free loopback ports, a small tree mission, and what a browser shows."""

import socket
from pathlib import Path

from aeroexec.fleet.transport import free_port as free_tcp_port

GEOMETRY = (Path(__file__).with_name("page_geometry.js")).read_text()

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
        port = free_tcp_port()  # below the ephemeral range, where a browser's connection cannot take it
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




def viewport(driver, width: int, height: int) -> None:
    """The page's viewport exactly ``width`` x ``height`` CSS pixels (not the window's outer size)."""
    driver.execute_cdp_cmd("Emulation.setDeviceMetricsOverride",
                           {"width": width, "height": height, "deviceScaleFactor": 1, "mobile": False})


def geometry(driver, panel: str | None = None) -> dict:
    """The page's texts as shown: how many, the pairs that overlap, where ``panel`` (an element id) lies."""
    return driver.execute_script(GEOMETRY, panel)
