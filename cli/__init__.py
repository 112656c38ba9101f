"""The ``aeroexec`` command: one module per sub-command (arguments in, a flight session or a check or a report out,
and what is printed), ``main.py`` dispatching them; ``views/`` the terminal views, ``reporting/`` the flight report."""
