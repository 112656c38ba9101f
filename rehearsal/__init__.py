"""Rehearsal: a mission flown many times in the simulator with variations, on every core or a Dask cluster, and
the HTML report of the campaign (``aeroexec rehearse``).

Each name is imported from its module when first used (``aeroexec.lazy``).
"""

from aeroexec.lazy import lazy_names

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)

__all__ = ["RunResult", "Variation", "fly", "fly_dask", "fly_local", "seeds", "summary", "write_report"]
__getattr__ = lazy_names(__name__, {"RunResult": "campaign", "Variation": "campaign", "fly": "campaign",
                                    "fly_dask": "campaign", "fly_local": "campaign", "seeds": "campaign",
                                    "summary": "report", "write_report": "report"})

if TYPE_CHECKING:
    from aeroexec.rehearsal.campaign import RunResult, Variation, fly, fly_dask, fly_local, seeds
    from aeroexec.rehearsal.report import summary, write_report
