"""Mission-file loaders into the tree model: BehaviorTree.CPP v4 XML, nested
YAML and Aerostack's flat ``nodes:`` YAML;
:mod:`aeroexec.trees.mission_file` chooses among them (and TML) by the file's extension.
"""
