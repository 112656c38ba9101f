"""Rehearsal: a mission flown many times in the simulator with variations, on every core or a Dask cluster, and
the HTML report of the campaign (``aeroexec rehearse``)."""

from aeroexec.rehearsal.campaign import RunResult, Variation, fly, fly_dask, fly_local, seeds
from aeroexec.rehearsal.report import summary, write_report

__all__ = ["RunResult", "Variation", "fly", "fly_dask", "fly_local", "seeds", "summary", "write_report"]
