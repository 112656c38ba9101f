"""Aerostack2's mission interpreter: a plan of behavior calls (``{"target", "plan": [{behavior, method, args}]}``)
run one item after another on the drone's engine."""
