"""The simulation campaign (``aeroexec campaign``): whole flights drawn from a seed each — a mission (random
trees, Python missions, plans), the operator's commands at random simulated times, faults (link drops, kill -9
then --resume, SIGTERM, SIGHUP, a full or slow disk), rules and safety rules — flown in the simulator on its clock
and judged after each by the invariants every run must keep (``invariants.py``); a failing case is replayed from
its seed with one command and shrunk.

Each name is imported from its module when first used (``aeroexec.lazy``).
"""

from aeroexec.lazy import lazy_names

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)

__all__ = ["Action", "Case", "CaseResult", "Fault", "Figures", "GATED", "INVARIANTS", "MEMORY_BOUND", "STEP_BOUND",
           "Violation", "check", "draw", "figures", "judge", "replay_command", "run_campaign", "run_case", "shrink",
           "timed_campaign"]
__getattr__ = lazy_names(__name__, {"Action": "cases", "Case": "cases", "Fault": "cases", "GATED": "cases",
                                    "draw": "cases", "INVARIANTS": "invariants", "MEMORY_BOUND": "invariants",
                                    "STEP_BOUND": "invariants", "Violation": "invariants", "check": "invariants",
                                    "CaseResult": "running", "Figures": "running", "figures": "running",
                                    "judge": "running", "replay_command": "running", "run_campaign": "running",
                                    "run_case": "running", "shrink": "running", "timed_campaign": "running"})

if TYPE_CHECKING:
    from aeroexec.rehearsal.simulation.cases import GATED, Action, Case, Fault, draw
    from aeroexec.rehearsal.simulation.invariants import INVARIANTS, MEMORY_BOUND, STEP_BOUND, Violation, check
    from aeroexec.rehearsal.simulation.running import (
        CaseResult,
        Figures,
        figures,
        judge,
        replay_command,
        run_campaign,
        run_case,
        shrink,
        timed_campaign,
    )
