"""The tree's nodes by kind, as BehaviorTree.CPP lays them out: ``controls`` (sequences, fallbacks), ``parallels``,
``branches`` (IfThenElse, WhileDoElse, SwitchN, TryCatch), ``decorators``, ``actions`` (BT.CPP's built-in leaves),
the engine's leaves (``behavior_leaves``, ``belief_leaves``), pre- and post-conditions (``node_conditions``) and
the one registration table (``registry``: XML name -> class).
"""
