"""Mission-file loaders into the tree model: BehaviorTree.CPP v4 XML, nested
YAML and Aerostack's flat ``nodes:`` YAML, chosen by the file's extension.
"""
