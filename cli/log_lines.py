"""The ``aeroexec`` command's log lines: one line each, a traceback only with ``-v`` (a module of its own, imported
once the command line is parsed: ``aeroexec --help`` does not import :mod:`logging`)."""

from __future__ import annotations

import logging


class OneLineFormatter(logging.Formatter):
    """Log lines without tracebacks (unless ``-v``): a failure inside a background task is one line with its reason."""

    def __init__(self, fmt: str, tracebacks: bool = False) -> None:
        super().__init__(fmt)
        self.tracebacks = tracebacks

    def format(self, record: logging.LogRecord) -> str:
        if self.tracebacks or not record.exc_info or record.exc_info[1] is None:
            return super().format(record)
        error = record.exc_info[1]
        saved = record.exc_info, record.exc_text
        record.exc_info, record.exc_text = None, None
        try:
            line = super().format(record)
        finally:
            record.exc_info, record.exc_text = saved
        detail = " ".join(str(error).split())[:200]
        return f"{line} ({type(error).__name__}{': ' + detail if detail else ''}; -v shows the traceback)"
