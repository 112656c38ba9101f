"""Mission-file loaders into the tree model: BehaviorTree.CPP v4 XML, nested YAML, Aerostack's flat ``nodes:``
YAML and Aerostack2's interpreter plans (``aerostack2_nodes`` maps Aerostack2's BT nodes onto the catalog);
:mod:`aeroexec.trees.mission_file` chooses among them (and TML and MAVLink item missions) by the file's extension.
``xml_writer`` writes the tree model back as BehaviorTree.CPP v4 XML.
"""
