"""The behavior-tree runtime (paper §6.2): a verified tree built as ``py_trees`` behaviours with
BehaviorTree.CPP v4 semantics (control nodes, decorators, script and blackboard nodes, the engine's leaves),
its blackboards, and the mission that the engine's loop ticks.
"""
