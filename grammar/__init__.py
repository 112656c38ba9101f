"""The grammar of the belief language (`beliefs.lark`), shipped as package data."""
