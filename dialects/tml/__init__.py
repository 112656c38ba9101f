"""TML missions (Aerostack's task-based mission language, Levant dialect):
read with lines, verified, compiled into the tree model and run with their
event handlers on the tree runtime.
"""
