"""Attribute values read as tinyxml2 (BehaviorTree.CPP 4.10's XML parser; the same tinyxml2 as in 4.8) reads them,
where strict XML reads them otherwise or not at all: a raw ``<`` or ``&`` (``_skipIf="value < 25"``,
``code="a && b"``), an undefined entity (``&y;`` stays the text ``&y;``), a raw newline or tab (kept, where strict
XML makes a space), and tinyxml2's in-place quirk: a ``&`` that starts no entity, after one it replaced, repeats
the byte of the original text at its place (``&amp;&b`` reads ``&ab``; its ``StrPair::GetStr``).

``escape_attributes(data, file)`` returns the text with each such value written as strict XML writes what tinyxml2
read (``&lt;``, ``&amp;``, ``&#10;``) and where it found a raw ``<``, ``&`` or an undefined entity, as ``(file,
line, message)``: a warning that names the line and the portable spelling (raw whitespace is no warning). Comments,
CDATA sections, processing instructions and text between elements are left alone; a file whose attribute values
need no rewriting comes back unchanged. Lines are kept (a value's raw newline is written after it).
"""

from __future__ import annotations

import re

_REFERENCE = re.compile(rb"&(?:[A-Za-z_][\w.-]*|#\d+|#x[0-9A-Fa-f]+);")
_ENTITIES = ((b"quot", 0x22), (b"amp", 0x26), (b"apos", 0x27), (b"lt", 0x3C), (b"gt", 0x3E))
_CHARACTER = re.compile(rb"&#(?:([0-9]+)|[xX]([0-9A-Fa-f]+));")
_STRICT = {0x26: b"&amp;", 0x3C: b"&lt;", 0x0A: b"&#10;", 0x0D: b"&#13;", 0x09: b"&#9;"}


def tinyxml2_value(raw: bytes) -> tuple[bytes, set[str]]:
    """An attribute's raw text as tinyxml2 reads it (``StrPair::GetStr``: newlines normalized, entities replaced in
    place), and what in it strict XML does not read so: ``<``, ``&`` (no reference) or ``&name;`` (undefined)."""
    buffer = bytearray(raw) + b"\0\0"
    end, p, q = len(raw), 0, 0
    found: set[str] = set()
    while p < end:
        byte = buffer[p]
        if byte in (0x0D, 0x0A):  # CR LF, LF CR, CR or LF: one LF
            p += 2 if buffer[p + 1] == (0x0A if byte == 0x0D else 0x0D) else 1
            buffer[q] = 0x0A
            q += 1
        elif byte == 0x26 and buffer[p + 1] == 0x23:  # &#...;
            match = _CHARACTER.match(bytes(buffer[p:end]))
            code = int(match[1], 10) if match and match[1] else int(match[2], 16) if match else -1
            if 0 < code < 0x110000:
                text = chr(code).encode("utf-8", "surrogatepass")
                buffer[q:q + len(text)] = text
                q, p = q + len(text), p + len(match[0])  # type: ignore[index]
            else:
                found.add("&")
                buffer[q] = byte
                p, q = p + 1, q + 1
        elif byte == 0x26:
            entity = next(((name, value) for name, value in _ENTITIES
                           if buffer.startswith(name, p + 1) and buffer[p + 1 + len(name)] == 0x3B), None)
            if entity is not None:
                buffer[q] = entity[1]
                q, p = q + 1, p + len(entity[0]) + 2
            else:  # tinyxml2 moves on without copying: the byte at q stays what it was
                found.add("&name;" if _REFERENCE.match(bytes(buffer[p:end])) else "&")
                p, q = p + 1, q + 1
        else:
            if byte == 0x3C:
                found.add("<")
            buffer[q] = byte
            p, q = p + 1, q + 1
    return bytes(buffer[:q]), found


def _strict(value: bytes, quote: int) -> bytes:
    """``value`` written as strict XML reads it back, inside ``quote``."""
    return b"".join(b"&quot;" if byte == quote == 0x22 else b"&apos;" if byte == quote == 0x27
                    else _STRICT.get(byte, bytes((byte,))) for byte in value)
_SKIP = ((b"<!--", b"-->"), (b"<![CDATA[", b"]]>"), (b"<?", b"?>"), (b"<!", b">"))


def escape_attributes(data: bytes, file: str) -> tuple[bytes, list[tuple[str, int, str]]]:
    """``data`` with raw ``<`` and ``&`` in attribute values escaped, and a warning per line where that was done."""
    if b"<" not in data or data[:2] in (b"\xff\xfe", b"\xfe\xff"):  # UTF-16 is read strictly
        return data, []
    out = bytearray()
    found: dict[int, set[str]] = {}
    index, size, quote, line = 0, len(data), 0, 1
    in_tag = False
    changed = False
    while index < size:
        byte = data[index]
        if quote:
            close = data.find(bytes((quote,)), index)
            if close < 0:  # no closing quote: the parser says where
                out += data[index:]
                break
            raw = data[index:close]
            value, odd = tinyxml2_value(raw)
            written = _strict(value, quote)
            newlines = raw.count(b"\n") + raw.count(b"\r") - raw.count(b"\r\n")
            if written != raw:
                changed = True
            if odd:
                found.setdefault(line, set()).update(odd)
            out += written + bytes((quote,)) + b"\n" * newlines
            line += raw.count(b"\n")
            index, quote = close + 1, 0
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
    return (bytes(out) if changed else data), warnings


def _message(chars: list[str]) -> str:
    written = " and ".join("an undefined entity (read as its text)" if c == "&name;" else f"a raw '{c}'"
                           for c in chars)
    portable = " and ".join({"<": "&lt;", "&": "&amp; (&amp;&amp; for &&)", "&name;": "&amp;name;"}[c]
                            for c in chars)
    return (f"an attribute holds {written}, which is not well-formed XML: read as BehaviorTree.CPP (tinyxml2) "
            f"reads it; write {portable} so that Groot2 and every XML tool read it too")
