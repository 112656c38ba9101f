"""The built-in nodes' manifests: one per node name, taken by its class, and read by verification without py_trees."""

from __future__ import annotations

import subprocess
import sys

from aeroexec.trees.runtime.manifests import CONTROLS, DECORATORS, LOOPING, MANIFESTS
from aeroexec.trees.runtime.nodes.registry import BUILT_IN


def test_every_registered_node_takes_the_manifest_of_its_name():
    assert set(BUILT_IN) == set(MANIFESTS)
    assert [name for name, cls in BUILT_IN.items() if cls.manifest != MANIFESTS[name]] == []
    assert {"Sequence", "Parallel", "Switch3", "TryCatch"} <= CONTROLS and "SubTree" not in DECORATORS
    assert {"Repeat", "LoopInt", "ReactiveSequence", "WhileDoElse"} <= LOOPING and "Sequence" not in LOOPING


def test_verifying_a_tree_imports_neither_py_trees_nor_the_node_classes(tmp_path):
    """`aeroexec verify` of a tree reads the manifests: the runtime (py_trees, ~20 ms of start-up) is left out."""
    code = ("import sys; from pathlib import Path; from aeroexec.engine.catalog import default_catalog\n"
            "from aeroexec.flight.missions import check_mission\n"
            "checked = check_mission(Path(sys.argv[1]), default_catalog())\n"
            "loaded = sorted(m for m in sys.modules if m.startswith(('py_trees', 'aeroexec.trees.runtime.nodes')))\n"
            "print(len(checked.errors), loaded)")
    mission = tmp_path / "loops.xml"
    mission.write_text('<root BTCPP_format="4" main_tree_to_execute="M"><BehaviorTree ID="M"><Sequence>'
                       '<Repeat num_cycles="2"><Script code="x := 1"/></Repeat>'
                       '<LoopInt queue="1;2"><AlwaysSuccess/></LoopInt>'
                       '<Precondition if="x == 1" else="FAILURE"><AlwaysSuccess/></Precondition>'
                       '</Sequence></BehaviorTree></root>')
    result = subprocess.run([sys.executable, "-c", code, str(mission)], capture_output=True, text=True, check=True)
    assert result.stdout.split() == ["0", "[]"]
