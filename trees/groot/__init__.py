"""Groot2's side of a tree mission, as BehaviorTree.CPP serves it: the palette of the nodes aeroexec reads
(``palette``: a ``<TreeNodesModel>``), the tree as ``WriteTreeToXML`` prints it (``tree_xml``), ``.btlog`` replay
files (``btlog``: FileLogger2) and the live publisher protocol Groot2 attaches to (``publisher``).
"""
