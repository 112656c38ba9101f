"""Mission-file loaders into the tree model: BehaviorTree.CPP v4 XML, nested
YAML, Aerostack's flat ``nodes:`` YAML and QGroundControl ``.plan`` missions;
:mod:`aeroexec.trees.mission_file` chooses among them (and TML) by the file's extension.
``xml_writer`` writes the tree model back as BehaviorTree.CPP v4 XML.
"""
