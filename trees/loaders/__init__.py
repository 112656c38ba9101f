"""Mission-file loaders into the tree model: BehaviorTree.CPP v4 XML and nested YAML (the foreign dialects' readers,
Aerostack's ``nodes:`` YAML, Aerostack2's plans and nodes, TML, are in ``aeroexec.dialects``, reached through entry
points); :mod:`aeroexec.trees.mission_file` chooses among the formats (and MAVLink item missions) by the file's
extension. ``xml_writer`` writes the tree model back as BehaviorTree.CPP v4 XML.
"""
