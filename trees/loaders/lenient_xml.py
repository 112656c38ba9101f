"""What tinyxml2 (BehaviorTree.CPP's XML parser) reads and strict XML does not: a raw ``<`` or ``&`` inside an
attribute value (``_skipIf="value < 25"``, ``code="a && b"``).

``escape_attributes(data, file)`` returns the text with each such character written as strict XML writes it
(``&lt;``, ``&amp;``) and where it found them, as ``(file, line, message)``: the trees read as BT.CPP reads them,
with a warning that names the line and the portable spelling. Comments, CDATA sections, processing instructions and
text between elements are left alone; a well-formed file comes back unchanged. Lines are kept.
"""

from __future__ import annotations

import re

_REFERENCE = re.compile(rb"&(?:[A-Za-z_][\w.-]*|#\d+|#x[0-9A-Fa-f]+);")
_SKIP = ((b"<!--", b"-->"), (b"<![CDATA[", b"]]>"), (b"<?", b"?>"), (b"<!", b">"))


def escape_attributes(data: bytes, file: str) -> tuple[bytes, list[tuple[str, int, str]]]:
    """``data`` with raw ``<`` and ``&`` in attribute values escaped, and a warning per line where that was done."""
    if b"<" not in data or data[:2] in (b"\xff\xfe", b"\xfe\xff"):  # UTF-16 is read strictly
        return data, []
    out = bytearray()
    found: dict[int, set[str]] = {}
    index, size, quote, line = 0, len(data), 0, 1
    in_tag = False
    while index < size:
        byte = data[index]
        if quote:
            if byte == quote:
                quote = 0
            elif byte == 0x3C:  # <
                found.setdefault(line, set()).add("<")
                out += b"&lt;"
                index += 1
                continue
            elif byte == 0x26 and not _REFERENCE.match(data, index):  # & that starts no reference
                found.setdefault(line, set()).add("&")
                out += b"&amp;"
                index += 1
                continue
        elif in_tag:
            if byte in (0x22, 0x27):  # " '
                quote = byte
            elif byte == 0x3E:  # >
                in_tag = False
        elif byte == 0x3C:
            skipped = next((end for start, end in _SKIP if data.startswith(start, index)), None)
            if skipped is not None:
                stop = data.find(skipped, index + 2)
                stop = size if stop < 0 else stop + len(skipped)
                out += data[index:stop]
                line += data.count(b"\n", index, stop)
                index = stop
                continue
            in_tag = True
        out.append(byte)
        line += byte == 0x0A
        index += 1
    warnings = [(file, line, _message(sorted(chars))) for line, chars in sorted(found.items())]
    return (bytes(out) if warnings else data), warnings


def _message(chars: list[str]) -> str:
    written = " and ".join(f"a raw '{c}'" for c in chars)
    portable = " and ".join({"<": "&lt;", "&": "&amp; (&amp;&amp; for &&)"}[c] for c in chars)
    return (f"an attribute holds {written}, which is not well-formed XML: read as BehaviorTree.CPP (tinyxml2) "
            f"reads it; write {portable} so that Groot2 and every XML tool read it too")
