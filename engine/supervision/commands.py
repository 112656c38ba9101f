"""The names of the changes of the running mission an operator may ask for (``aeroexec ctl skip|jump|insert|...``):
the supervisor knows its commands by them without importing :mod:`.changes`, which checks and makes a change and
which a flight needs only once one is asked."""

CHANGES = ("skip", "jump", "insert", "modify", "delete", "replace", "load")
