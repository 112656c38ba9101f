"""The grammars, shipped as package data: the belief language (`beliefs.lark`) and BehaviorTree.CPP's scripts
(`script.lark`)."""
