"""The simulation campaign (``aeroexec campaign``): whole flights drawn from a seed each — a mission (random
trees, Python missions, plans), the operator's commands at random simulated times, faults (link drops, kill -9
then --resume, SIGTERM, SIGHUP, a full or slow disk), rules and safety rules — flown in the simulator on its clock
and judged after each by the invariants every run must keep (``invariants.py``); a failing case is replayed from
its seed with one command and shrunk."""

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

__all__ = ["GATED", "INVARIANTS", "MEMORY_BOUND", "STEP_BOUND", "Action", "Case", "CaseResult", "Fault", "Figures",
           "Violation", "check", "draw", "figures", "judge", "replay_command", "run_campaign", "run_case", "shrink",
           "timed_campaign"]
