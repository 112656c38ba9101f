"""The behavior-tree runtime (paper §6.2): a verified tree built as ``py_trees`` behaviours with
BehaviorTree.CPP v4 semantics, its nodes laid out by kind as BT.CPP lays them out (``nodes``: ``controls``,
``decorators``, ``actions``, the engine's ``behavior_leaves`` and ``belief_leaves``, one registration table
``nodes.registry``), each node declaring its ports once (``manifests``, ``ports``), the blackboards, and the
mission the engine's loop ticks.
"""
