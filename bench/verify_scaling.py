"""Verification time against mission size for every format: linear means 4x the nodes takes about 4x the time.

Run ``python bench/verify_scaling.py`` (``--nodes 300`` for the smaller size N; 4N Aerostack nodes must stay
within the readers' 50,000 YAML values). Each format's mission is written with N and 4N leaves (a flat
sequence; TML also as N ``<recurrent_behavior>`` lines, the case that was quadratic) and checked as
``aeroexec verify`` does; the best of ``--repeat`` runs is printed with the ratio of the two sizes, measured
in the same run. A ratio near 4 is linear; near 16 is quadratic.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

from aeroexec.flight.missions import check_mission
from aeroexec.flight.robot import chosen_catalog


def xml(n: int) -> str:
    leaves = "".join('<GO_TO_POINT COORDINATES="1, 2, 3"/>\n' for _ in range(n))
    return (f'<root BTCPP_format="4"><BehaviorTree ID="M"><Sequence><TAKE_OFF ALTITUDE="3"/>\n{leaves}'
            "<LAND/></Sequence></BehaviorTree></root>\n")


def nested_yaml(n: int) -> str:
    leaves = "".join("      - GO_TO_POINT: {COORDINATES: [1, 2, 3]}\n" for _ in range(n))
    return f"tree:\n  Sequence:\n    children:\n      - TAKE_OFF: {{ALTITUDE: 3}}\n{leaves}      - LAND\n"


def aerostack(n: int) -> str:
    items = ["nodes:", "  - {node: 1, name: root, type: control_flow, subtype: sequence, parent: 0}",
             "  - {node: 2, name: up, type: execution, subtype: task, task: TAKE_OFF, parent: 1}"]
    items += [f"  - {{node: {i + 3}, name: go{i}, type: execution, subtype: task, task: GO_TO_POINT, "
              f"parameters: 'coordinates: [1, 2, 3]', parent: 1}}" for i in range(n)]
    items.append(f"  - {{node: {n + 3}, name: down, type: execution, subtype: task, task: LAND, parent: 1}}")
    return "\n".join(items) + "\n"


def tml_tasks(n: int) -> str:
    tasks = "".join(f'<task name="go{i}"><behavior name="GO_TO_POINT"><argument name="coordinates" '
                    f'value="1, 2, 3"/></behavior></task>\n' for i in range(n))
    return ('<mission root_task="m"><task_tree><task name="m"><task name="up"><behavior name="TAKE_OFF"/></task>\n'
            f'{tasks}<task name="down"><behavior name="LAND"/></task></task></task_tree></mission>\n')


def tml_recurrent(n: int) -> str:
    lines = "".join('<recurrent_behavior name="SELF_LOCALIZE_BY_ODOMETRY"/>\n' for _ in range(n))
    return (f'<mission root_task="m"><task_tree><task name="m">{lines}<task name="up"><behavior name="TAKE_OFF"/>'
            '</task><task name="down"><behavior name="LAND"/></task></task></task_tree></mission>\n')


def python(n: int) -> str:
    calls = "".join("    api.execute_behavior('GO_TO_POINT', coordinates=(1, 2, 3))\n" for _ in range(n))
    return (f"from aeroexec.engine import api\n\n\ndef mission():\n    api.execute_behavior('TAKE_OFF', altitude=3)\n"
            f"{calls}    api.execute_behavior('LAND')\n")


FORMATS: list[tuple[str, str, Callable[[int], str]]] = [
    ("BT.CPP XML", ".xml", xml),
    ("YAML tree", ".yaml", nested_yaml),
    ("Aerostack nodes:", ".yaml", aerostack),
    ("TML tasks", ".tml.xml", tml_tasks),
    ("TML <recurrent_behavior>", ".tml.xml", tml_recurrent),
    ("Python mission", ".py", python),
]


def best_time(path: Path, catalog, repeat: int) -> float:  # noqa: ANN001
    best = float("inf")
    for _ in range(repeat):
        start = time.perf_counter()
        checked = check_mission(path, catalog)
        best = min(best, time.perf_counter() - start)
        assert not checked.errors, checked.errors[:3]
    return best


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--nodes", type=int, default=600, help="the smaller size N (the larger is 4N)")
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    catalog = chosen_catalog(None)
    n = args.nodes
    print(f"{'format':28} {f'N={n}':>10} {f'4N={4 * n}':>10} {'ratio':>7}")
    with tempfile.TemporaryDirectory() as folder:
        for name, suffix, write in FORMATS:
            times = []
            for size in (n, 4 * n):
                path = Path(folder) / f"m{size}{suffix}"
                path.write_text(write(size))
                times.append(best_time(path, catalog, args.repeat))
            print(f"{name:28} {times[0]:9.3f}s {times[1]:9.3f}s {times[1] / times[0]:6.1f}x")


if __name__ == "__main__":
    main()
