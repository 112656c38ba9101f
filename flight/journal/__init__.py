"""The flight journal: one SQLite database per run (``journal.sqlite`` in its output folder, WAL mode) written as
the run flies — events, node transitions, belief changes, operator commands, behavior activations and outcomes,
telemetry, a Python mission's calls, a tree's state and where the mission stopped — and what a resumed run
(``aeroexec run --resume RUN_DIR``) goes on from.

``schema.py`` (the tables), ``writer.py`` (:class:`JournalWriter`, on the engine's loop), ``store.py`` (the
database as it is written: commits on the loop, checkpoints on a thread), ``looks.py`` (a polling mission's calls
in runs), ``reader.py`` (:class:`Journal`: questions over it, and the event log's records rebuilt from it),
``agreement.py`` (:func:`disagreements`: where a journal and its event log differ), ``resume_point.py`` (where an
interrupted run goes on from), ``identity.py`` (the run, folder and files a journal belongs to, checked before a
resume), ``rejoin.py`` (the drone put back where the mission left it), ``resumption.py`` (a flight set up from a
resume point), ``opening.py`` (:func:`open_journal`: a new journal, or a resumed run's).

Each name is imported from its module when first used (``aeroexec.lazy``).
"""

from aeroexec.lazy import lazy_names

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)

__all__ = ["Journal", "JournalError", "JournalWriter", "NAME", "RejoinFailed", "ResumePoint", "Resumption",
           "disagreements", "is_journal", "open_journal", "read_records", "resume_spec"]
__getattr__ = lazy_names(__name__, {"disagreements": "agreement", "Journal": "reader", "is_journal": "reader",
                                    "read_records": "reader", "ResumePoint": "resume_point",
                                    "resume_spec": "resume_point", "RejoinFailed": "resumption",
                                    "Resumption": "resumption", "open_journal": "opening", "JournalError": "schema",
                                    "NAME": "schema", "JournalWriter": "writer"})

if TYPE_CHECKING:
    from aeroexec.flight.journal.agreement import disagreements
    from aeroexec.flight.journal.opening import open_journal
    from aeroexec.flight.journal.reader import Journal, is_journal, read_records
    from aeroexec.flight.journal.resume_point import ResumePoint, resume_spec
    from aeroexec.flight.journal.resumption import RejoinFailed, Resumption
    from aeroexec.flight.journal.schema import NAME, JournalError
    from aeroexec.flight.journal.writer import JournalWriter
