"""What ``aeroexec run`` and ``aeroexec fleet`` set a flight up with: the mission file checked, the robot kind,
the remote surfaces (web console, Groot2) and whole-line output."""
