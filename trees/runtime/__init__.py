"""The behavior-tree runtime (paper §6.2): a verified tree built as ``py_trees`` behaviours with
BehaviorTree.CPP v4 semantics, laid out by node kind as BT.CPP lays it out (``controls``, ``decorators``,
``actions``; the engine's ``behavior_leaves`` and ``belief_leaves``), each node declaring its ports once
(``ports``), one registration table (``registry``), the blackboards, and the mission the engine's loop ticks.
"""
